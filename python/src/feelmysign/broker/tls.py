"""TLS off loopback: a local certificate authority and a server certificate, or the user's own.

The first ``feelmysign up --lan`` writes, in ``STATE_DIR/tls/``::

    ca.pem  ca.key        the local CA (10 years), its key never leaves this machine
    server.pem server.key the broker's and the page's certificate, signed by the CA,
                          for every host name and address the LAN reaches us by;
                          ``server.pem`` holds the CA after the leaf, so a client
                          that pins the CA's fingerprint can find it in the handshake

Both keys are ECDSA P-256: small (a join token stays one line) and fast on a Pi.
The server certificate is issued again when the names change or it nears its end;
the CA is kept, so sleeves that pinned it keep working.
"""

from __future__ import annotations

import datetime
import hashlib
import ipaddress
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

from feelmysign.broker.credentials import write_private_file
from feelmysign.errors import BrokerError
from feelmysign.input_files import MAX_PEM_BYTES, read_bytes

CA_VALIDITY_DAYS = 3650
# Apple's and Chromium's limit for a certificate a user accepts by hand.
SERVER_VALIDITY_DAYS = 397
# Issue the server certificate again when it has less than this left.
RENEW_BEFORE_DAYS = 30
# Clocks on a Pi without a real-time clock can be behind at boot.
BACKDATE = datetime.timedelta(days=1)
CA_NAME = "feelmysign local CA"
SERVER_USAGES = (ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH)


DEFAULT_MQTTS_PORT = 8883  # IANA's MQTT-over-TLS port


@dataclass(frozen=True)
class LanOptions:
    """Serve off loopback: the address to bind, the TLS port, and the certificate to show.

    ``names`` are further host names the certificate covers (e.g. ``pi.local``). Without
    ``cert``/``key``, the local CA in the state directory issues one.
    """

    host: str
    port: int = DEFAULT_MQTTS_PORT
    cert: Path | None = None
    key: Path | None = None
    names: tuple[str, ...] = ()

    def tls_files(self, tls_dir: Path) -> TlsFiles:
        if (self.cert is None) != (self.key is None):
            raise BrokerError("bad-option", "Give --tls-cert and --tls-key together.")
        if self.cert is not None and self.key is not None:
            return user_certificate(self.cert, self.key, [self.host, *self.names])
        return ensure_local_ca(tls_dir, [self.host, *self.names])


@dataclass(frozen=True)
class TlsFiles:
    """What a TLS listener needs, and the fingerprint clients pin (None: publicly trusted)."""

    cert: Path
    key: Path
    ca: Path | None
    ca_fingerprint: str | None


def fingerprint(der: bytes) -> str:
    """SHA-256 of a DER certificate, as lowercase hex (the form join tokens carry)."""
    return hashlib.sha256(der).hexdigest()


def pem_fingerprint(pem: bytes) -> str:
    return fingerprint(x509.load_pem_x509_certificate(pem).public_bytes(serialization.Encoding.DER))


def ensure_local_ca(tls_dir: Path, hosts: list[str]) -> TlsFiles:
    """The local CA and a server certificate for ``hosts``, created or renewed as needed."""
    tls_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
    ca_pem, ca_key_pem = tls_dir / "ca.pem", tls_dir / "ca.key"
    if not (ca_pem.is_file() and ca_key_pem.is_file()):
        _write_new_ca(ca_pem, ca_key_pem)
    ca_cert = x509.load_pem_x509_certificate(ca_pem.read_bytes())
    ca_key = serialization.load_pem_private_key(ca_key_pem.read_bytes(), password=None)
    if not isinstance(ca_key, ec.EllipticCurvePrivateKey):
        raise BrokerError("tls", f"{ca_key_pem} is not an EC key; delete {tls_dir} to start over.")
    server_pem, server_key = tls_dir / "server.pem", tls_dir / "server.key"
    if not _server_cert_fits(server_pem, server_key, ca_cert, hosts):
        _write_server_cert(server_pem, server_key, ca_cert, ca_key, hosts)
    return TlsFiles(
        cert=server_pem,
        key=server_key,
        ca=ca_pem,
        ca_fingerprint=fingerprint(ca_cert.public_bytes(serialization.Encoding.DER)),
    )


def user_certificate(cert: Path, key: Path, hosts: Sequence[str] = ()) -> TlsFiles:
    """The user's own certificate (e.g. Let's Encrypt's fullchain.pem and privkey.pem).

    Refused (BrokerError ``bad-option``) when every client would refuse it or the listener
    could not use it: expired or not yet valid, or ``key`` not its private key. One that names
    none of ``hosts`` (the address up listens on and prints, and further names) is said on
    stderr: clients that use a name it holds still connect (a port forwarded under a DNS name)."""
    pem: dict[str, bytes] = {}
    for path, option in ((cert, "--tls-cert"), (key, "--tls-key")):
        try:
            pem[option] = read_bytes(path, max_bytes=MAX_PEM_BYTES)
        except FileNotFoundError:
            raise BrokerError("bad-option", f"{option} {path}: no such file.") from None
        except OSError as error:
            raise BrokerError(
                "bad-option", f"{option} {path} cannot be read: {error.strerror or error}."
            ) from None
    try:
        leaf = x509.load_pem_x509_certificates(pem["--tls-cert"])[0]
        private = serialization.load_pem_private_key(pem["--tls-key"], password=None)
    except (ValueError, TypeError) as error:
        raise BrokerError(
            "bad-option",
            f"--tls-cert {cert} / --tls-key {key} is not a PEM certificate and an unencrypted "
            f"PEM private key ({error}).",
        ) from None
    _check_user_certificate(leaf, private, cert, key, hosts)
    return TlsFiles(cert=cert.absolute(), key=key.absolute(), ca=None, ca_fingerprint=None)


def _check_user_certificate(
    leaf: x509.Certificate, private: object, cert: Path, key: Path, hosts: Sequence[str]
) -> None:
    now = _now()
    if leaf.not_valid_after_utc < now:
        raise BrokerError(
            "bad-option",
            f"--tls-cert {cert} expired on {leaf.not_valid_after_utc:%Y-%m-%d %H:%M} UTC: every "
            "phone, page and sleeve would refuse it. Renew it (certbot renew), or leave out "
            "--tls-cert and --tls-key to use the local CA's; if it should still be valid, "
            f"check this machine's clock (it says {now:%Y-%m-%d %H:%M} UTC).",
        )
    if leaf.not_valid_before_utc > now:
        raise BrokerError(
            "bad-option",
            f"--tls-cert {cert} is valid only from {leaf.not_valid_before_utc:%Y-%m-%d %H:%M} "
            f"UTC, and this machine's clock says {now:%Y-%m-%d %H:%M} UTC: set the clock "
            "('timedatectl' must say 'System clock synchronized: yes'), or wait.",
        )
    public = getattr(private, "public_key", None)
    if public is None or public().public_bytes(
        serialization.Encoding.DER, serialization.PublicFormat.SubjectPublicKeyInfo
    ) != leaf.public_key().public_bytes(
        serialization.Encoding.DER, serialization.PublicFormat.SubjectPublicKeyInfo
    ):
        raise BrokerError(
            "bad-option",
            f"--tls-key {key} is not the private key of the certificate in --tls-cert {cert}: "
            "give the key made with it (Let's Encrypt: privkey.pem beside fullchain.pem).",
        )
    names = _certificate_names(leaf)
    wanted = [host for host in hosts if host not in WILDCARD_ADDRESSES]
    if wanted and not any(_names_host(names, host) for host in wanted):
        print(
            f"Warning: --tls-cert {cert} is for {', '.join(names) or 'no host name'}, not "
            f"{' or '.join(wanted)}: a client that connects by {wanted[0]} (the addresses "
            "printed below) will refuse it. Give --host a name the certificate holds, or a "
            f"certificate for {wanted[0]}.",
            file=sys.stderr,
            flush=True,
        )


# Addresses to listen on that no client connects by.
WILDCARD_ADDRESSES = frozenset({"0.0.0.0", "::"})


def _certificate_names(cert: x509.Certificate) -> list[str]:
    """The host names and addresses a certificate is for: its subject alternative names (the
    common name only without them, as clients do)."""
    try:
        alternatives = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    except x509.ExtensionNotFound:
        common = cert.subject.get_attributes_for_oid(NameOID.COMMON_NAME)
        return [str(attribute.value) for attribute in common]
    names: list[str] = list(alternatives.get_values_for_type(x509.DNSName))
    names += [str(address) for address in alternatives.get_values_for_type(x509.IPAddress)]
    return names


def _names_host(names: list[str], host: str) -> bool:
    """Whether a client connecting by ``host`` finds it among ``names`` (RFC 6125: an address
    only as an address, a wildcard for one leftmost label)."""
    try:
        address = ipaddress.ip_address(host)
    except ValueError:
        address = None
    for name in names:
        if address is not None:
            try:
                if ipaddress.ip_address(name) == address:
                    return True
            except ValueError:
                continue
            continue
        wanted, given = host.lower().rstrip("."), name.lower().rstrip(".")
        if given == wanted:
            return True
        if given.startswith("*.") and "." in wanted and wanted.split(".", 1)[1] == given[2:]:
            return True
    return False


def _now() -> datetime.datetime:
    return datetime.datetime.now(datetime.UTC)


def _write_new_ca(ca_pem: Path, ca_key_pem: Path) -> None:
    key = ec.generate_private_key(ec.SECP256R1())
    name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, CA_NAME)])
    now = _now()
    cert = (
        x509.CertificateBuilder()
        .subject_name(name)
        .issuer_name(name)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - BACKDATE)
        .not_valid_after(now + datetime.timedelta(days=CA_VALIDITY_DAYS))
        .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
        .add_extension(
            x509.KeyUsage(
                digital_signature=False,
                content_commitment=False,
                key_encipherment=False,
                data_encipherment=False,
                key_agreement=False,
                key_cert_sign=True,
                crl_sign=True,
                encipher_only=False,
                decipher_only=False,
            ),
            critical=True,
        )
        .add_extension(x509.SubjectKeyIdentifier.from_public_key(key.public_key()), critical=False)
        .sign(key, hashes.SHA256())
    )
    write_private_file(ca_key_pem, _key_pem(key))
    write_private_file(ca_pem, cert.public_bytes(serialization.Encoding.PEM).decode())


def _server_cert_fits(
    server_pem: Path, server_key: Path, ca_cert: x509.Certificate, hosts: list[str]
) -> bool:
    if not (server_pem.is_file() and server_key.is_file()):
        return False
    try:
        cert = x509.load_pem_x509_certificates(server_pem.read_bytes())[0]
        names = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
        usages = cert.extensions.get_extension_for_class(x509.ExtendedKeyUsage).value
    except (ValueError, x509.ExtensionNotFound):
        return False
    wanted = set(_general_names(hosts))
    left = cert.not_valid_after_utc - _now()
    return (
        cert.issuer == ca_cert.subject
        and wanted <= set(names)
        and set(SERVER_USAGES) <= set(usages)
        and left > datetime.timedelta(days=RENEW_BEFORE_DAYS)
    )


def _write_server_cert(
    server_pem: Path,
    server_key: Path,
    ca_cert: x509.Certificate,
    ca_key: ec.EllipticCurvePrivateKey,
    hosts: list[str],
) -> None:
    key = ec.generate_private_key(ec.SECP256R1())
    now = _now()
    cert = (
        x509.CertificateBuilder()
        .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, hosts[0])]))
        .issuer_name(ca_cert.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - BACKDATE)
        .not_valid_after(now + datetime.timedelta(days=SERVER_VALIDITY_DAYS))
        .add_extension(x509.SubjectAlternativeName(_general_names(hosts)), critical=False)
        .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
        # Client use too: the servers of a NATS cluster present it to each other on their
        # routes, both ways (deploy/nats/node.conf).
        .add_extension(x509.ExtendedKeyUsage(SERVER_USAGES), critical=False)
        .add_extension(
            x509.AuthorityKeyIdentifier.from_issuer_public_key(ca_key.public_key()),
            critical=False,
        )
        .sign(ca_key, hashes.SHA256())
    )
    chain = cert.public_bytes(serialization.Encoding.PEM) + ca_cert.public_bytes(
        serialization.Encoding.PEM
    )
    write_private_file(server_key, _key_pem(key))
    write_private_file(server_pem, chain.decode())


def _general_names(hosts: list[str]) -> list[x509.GeneralName]:
    names: list[x509.GeneralName] = []
    for host in dict.fromkeys(hosts):  # unique, in order
        try:
            names.append(x509.IPAddress(ipaddress.ip_address(host)))
        except ValueError:
            names.append(x509.DNSName(host))
    return names


def _key_pem(key: ec.EllipticCurvePrivateKey) -> str:
    return key.private_bytes(
        serialization.Encoding.PEM,
        serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption(),
    ).decode()
