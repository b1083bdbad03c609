"""A certificate of the user's own (--tls-cert, --tls-key) that every client would refuse, or
that the listener could not use, is refused at start with what to do; one for other names is
said. Real certificates, made here with cryptography."""

from __future__ import annotations

import datetime
import ipaddress
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID

from feelmysign.broker.tls import user_certificate
from feelmysign.errors import BrokerError

NOW = datetime.datetime.now(datetime.UTC)
DAY = datetime.timedelta(days=1)


def _write(
    tmp_path: Path,
    names: Sequence[x509.GeneralName],
    *,
    before: datetime.datetime = NOW - DAY,
    after: datetime.datetime = NOW + 90 * DAY,
    other_key: bool = False,
) -> tuple[Path, Path]:
    key = ec.generate_private_key(ec.SECP256R1())
    cert = (
        x509.CertificateBuilder()
        .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "feelmysign test")]))
        .issuer_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "test CA")]))
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(before)
        .not_valid_after(after)
        .add_extension(x509.SubjectAlternativeName(names), critical=False)
        .sign(key, hashes.SHA256())
    )
    given = ec.generate_private_key(ec.SECP256R1()) if other_key else key
    cert_path, key_path = tmp_path / "fullchain.pem", tmp_path / "privkey.pem"
    cert_path.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    key_path.write_bytes(
        given.private_bytes(
            serialization.Encoding.PEM,
            serialization.PrivateFormat.PKCS8,
            serialization.NoEncryption(),
        )
    )
    return cert_path, key_path


PI = [x509.DNSName("pi.example.org")]


def test_an_expired_certificate_is_refused_with_its_date(tmp_path: Path) -> None:
    cert, key = _write(tmp_path, PI, before=NOW - 400 * DAY, after=NOW - 3 * DAY)
    with pytest.raises(BrokerError) as raised:
        user_certificate(cert, key, ["pi.example.org"])
    message = str(raised.value)
    assert f"expired on {(NOW - 3 * DAY):%Y-%m-%d}" in message, message
    assert "Renew it" in message and "clock" in message, message


def test_a_certificate_not_yet_valid_is_refused_with_the_clock(tmp_path: Path) -> None:
    cert, key = _write(tmp_path, PI, before=NOW + 2 * DAY)
    with pytest.raises(BrokerError) as raised:
        user_certificate(cert, key, ["pi.example.org"])
    assert "valid only from" in str(raised.value) and "timedatectl" in str(raised.value)


def test_a_key_of_another_certificate_is_refused(tmp_path: Path) -> None:
    cert, key = _write(tmp_path, PI, other_key=True)
    with pytest.raises(BrokerError) as raised:
        user_certificate(cert, key, ["pi.example.org"])
    assert "is not the private key of the certificate" in str(raised.value)


@pytest.mark.parametrize(
    ("names", "hosts", "warned"),
    [
        (PI, ["pi.example.org"], False),
        (PI, ["PI.example.org."], False),
        ([x509.DNSName("*.example.org")], ["pi.example.org"], False),
        ([x509.DNSName("*.example.org")], ["a.pi.example.org"], True),
        (PI, ["10.0.0.5", "pi.example.org"], False),  # a further name the clients use
        (PI, ["10.0.0.5"], True),
        ([x509.IPAddress(ipaddress.ip_address("10.0.0.5"))], ["10.0.0.5"], False),
        (PI, ["0.0.0.0"], False),  # listening everywhere: no name to check
    ],
)
def test_a_certificate_for_other_names_is_said(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    names: Sequence[x509.GeneralName],
    hosts: list[str],
    warned: bool,
) -> None:
    cert, key = _write(tmp_path, names)
    files = user_certificate(cert, key, hosts)
    assert files.cert == cert.absolute() and files.ca is None
    said = capsys.readouterr().err
    assert ("Warning:" in said) is warned, said
    if warned:
        assert f"not {' or '.join(hosts)}" in said and "Give --host" in said, said


def test_up_with_an_expired_certificate_stops_at_once_in_one_line(tmp_path: Path) -> None:
    cert, key = _write(tmp_path, PI, before=NOW - 400 * DAY, after=NOW - 3 * DAY)
    command = [sys.executable, "-m", "feelmysign", "up", "--host", "127.0.0.1"]
    command += ["--state-dir", str(tmp_path / "state"), "--port", "0", "--ws-port", "0"]
    command += ["--http-port", "0", "--tls-port", "0", "--tls-cert", str(cert)]
    command += ["--tls-key", str(key)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode not in (0, 70), done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    errors = [line for line in done.stderr.splitlines() if line.startswith("Error:")]
    assert len(errors) == 1 and "expired on" in errors[0], done.stderr
    assert "feelmysign is up" not in done.stdout, done.stdout
