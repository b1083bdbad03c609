"""A broker's certificate refused: the sender says why (expired, made out for another host,
signed by another CA) and what to do, never to leave TLS. A real TLS handshake with a server
holding such a certificate."""

from __future__ import annotations

import contextlib
import datetime
import hashlib
import ipaddress
import os
import socket
import ssl
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID

from feelmysign.cli import main
from feelmysign.connection.join_token import JoinToken


def _name(text: str) -> x509.Name:
    return x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, text)])


def _certificates(folder: Path, host: str, *, expired: bool = False) -> tuple[Path, Path, Path]:
    """A CA, and a server certificate for ``host`` it signed: (ca.pem, server.pem, server.key)."""
    now = datetime.datetime.now(datetime.UTC)
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca = (
        x509.CertificateBuilder()
        .subject_name(_name("test CA"))
        .issuer_name(_name("test CA"))
        .public_key(ca_key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(days=30))
        .not_valid_after(now + datetime.timedelta(days=30))
        .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
        .sign(ca_key, hashes.SHA256())
    )
    key = ec.generate_private_key(ec.SECP256R1())
    ends = now - datetime.timedelta(days=1) if expired else now + datetime.timedelta(days=30)
    server = (
        x509.CertificateBuilder()
        .subject_name(_name(host))
        .issuer_name(ca.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(days=20))
        .not_valid_after(ends)
        .add_extension(
            x509.SubjectAlternativeName([x509.IPAddress(ipaddress.ip_address(host))]),
            critical=False,
        )
        .sign(ca_key, hashes.SHA256())
    )
    folder.mkdir(parents=True, exist_ok=True)
    paths = folder / "ca.pem", folder / "server.pem", folder / "server.key"
    paths[0].write_bytes(ca.public_bytes(serialization.Encoding.PEM))
    paths[1].write_bytes(server.public_bytes(serialization.Encoding.PEM))
    paths[2].write_bytes(
        key.private_bytes(
            serialization.Encoding.PEM,
            serialization.PrivateFormat.PKCS8,
            serialization.NoEncryption(),
        )
    )
    return paths


@contextmanager
def _tls_server(cert: Path, key: Path) -> Iterator[int]:
    """A TLS listener on 127.0.0.1 that offers ``cert`` to whoever connects; its port."""
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    context.load_cert_chain(cert, key)
    listener = socket.create_server(("127.0.0.1", 0))
    stop = threading.Event()

    def serve() -> None:
        listener.settimeout(0.2)
        while not stop.is_set():
            try:
                connection, _ = listener.accept()
            except TimeoutError:
                continue
            # The client refuses the certificate: what the test is about.
            with connection, contextlib.suppress(ssl.SSLError, OSError):
                context.wrap_socket(connection, server_side=True).close()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield listener.getsockname()[1]
    finally:
        stop.set()
        thread.join(timeout=5)
        listener.close()


@pytest.mark.parametrize(
    ("host", "expired", "other_ca", "says"),
    [
        ("127.0.0.1", True, False, "certificate has expired"),
        ("192.0.2.7", False, False, "it is not made out for '127.0.0.1'"),
        ("127.0.0.1", False, True, "did not sign it"),
    ],
)
def test_a_refused_certificate_says_why_and_never_to_leave_tls(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    host: str,
    expired: bool,
    other_ca: bool,
    says: str,
) -> None:
    ca, cert, key = _certificates(tmp_path / "broker", host, expired=expired)
    if other_ca:
        ca = _certificates(tmp_path / "other", "127.0.0.1")[0]
    with _tls_server(cert, key) as port:
        argv = ["send", "--broker", f"mqtts://127.0.0.1:{port}", "--ca", str(ca), "0,0,1,0,300"]
        assert main([*argv, "--timeout-s", "10"]) == 1
    err = capsys.readouterr().err
    assert "the broker's certificate was refused" in err and says in err, err
    assert "mqtt://" not in err.replace(f"mqtts://127.0.0.1:{port}", "") and "Traceback" not in err


def test_a_ca_file_with_no_certificate_in_it_is_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, cert, key = _certificates(tmp_path / "broker", "127.0.0.1")
    with _tls_server(cert, key) as port:
        argv = ["send", "--broker", f"mqtts://127.0.0.1:{port}", "--ca", str(key), "0,0,1,0,300"]
        assert main(argv) == 1  # the key given for the CA: no certificate in it
    err = capsys.readouterr().err
    assert f"The CA file {key} holds no certificate" in err and "ca.pem" in err, err
    assert "bug" not in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("host", "expired", "says"),
    [
        ("127.0.0.1", True, "certificate has expired"),
        ("192.0.2.7", False, "it is not made out for '127.0.0.1'"),
    ],
)
def test_the_sleeve_says_why_the_certificate_was_refused_not_that_nothing_answers(
    tmp_path: Path, host: str, expired: bool, says: str
) -> None:
    """The sleeve's own line for a refused certificate says the TLS problem and what to do,
    as the senders do; it goes on retrying (the certificate may be renewed)."""
    ca, cert, key = _certificates(tmp_path / "broker", host, expired=expired)
    # The sleeve joins with a token pinning that CA, kept where a first join keeps it.
    fingerprint = hashlib.sha256(ssl.PEM_cert_to_DER_cert(ca.read_text())).hexdigest()
    trusted = tmp_path / "state" / "feelmysign" / "trusted"
    trusted.mkdir(parents=True)
    (trusted / f"ca-{fingerprint[:16]}.pem").write_text(ca.read_text())
    log = tmp_path / "sleeve.log"
    with _tls_server(cert, key) as port, log.open("w") as stderr:
        token = JoinToken(f"mqtts://127.0.0.1:{port}", "s1", "sleeve", "pw", fingerprint)
        sleeve = subprocess.Popen(
            [sys.executable, "-m", "feelmysign", "sleeve", "--backend", "sim"],
            stdout=subprocess.DEVNULL,
            stderr=stderr,
            env={
                **{k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")},
                "XDG_STATE_HOME": str(tmp_path / "state"),
                "FEELMYSIGN_JOIN": token.encode(),
            },
        )
        try:
            deadline = time.monotonic() + 60
            while "cannot connect to the broker" not in log.read_text():
                assert sleeve.poll() is None, log.read_text()
                assert time.monotonic() < deadline, log.read_text()
                time.sleep(0.1)
        finally:
            sleeve.terminate()
            sleeve.wait(timeout=60)
    said = log.read_text()
    assert "the broker's certificate was refused" in said and says in said, said
    assert "nothing answers" not in said, said
