"""Trust a broker's local CA by its fingerprint: fetch it once from the TLS handshake, keep it.

The join token carries the SHA-256 of the CA certificate, not the certificate. The
first connection takes the chain the broker shows (without trusting it yet), finds the
certificate with that fingerprint and saves it; every connection, the first included,
then verifies the broker's certificate against it as usual (chain and host name). A
broker whose chain lacks that CA is refused before any password is sent.
"""

from __future__ import annotations

import hashlib
import socket
import ssl
from pathlib import Path

from feelmysign.connection.settings import BrokerSettings
from feelmysign.errors import BrokerConnectionError

HANDSHAKE_TIMEOUT_S = 10.0


def pinned_ca_file(settings: BrokerSettings, fingerprint: str, cache_dir: Path) -> Path:
    """The CA certificate (PEM) with ``fingerprint``, from ``cache_dir`` or the broker's chain."""
    path = cache_dir / f"ca-{fingerprint[:16]}.pem"
    if path.is_file() and _fingerprint(ssl.PEM_cert_to_DER_cert(path.read_text())) == fingerprint:
        return path
    for der in _unverified_chain(settings):
        if _fingerprint(der) == fingerprint:
            cache_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
            path.write_text(ssl.DER_cert_to_PEM_cert(der))
            return path
    raise BrokerConnectionError(
        "wrong-certificate",
        f"The broker at {settings.url} does not show the certificate authority of the join "
        f"token (SHA-256 {fingerprint[:16]}...): it is not the broker that made the token, or "
        "its certificates were made anew. Nothing was sent; ask for a new token "
        "('feelmysign broker add-sleeve ID' on the broker's machine).",
        url=settings.url,
    )


def _fingerprint(der: bytes) -> str:
    return hashlib.sha256(der).hexdigest()


def _unverified_chain(settings: BrokerSettings) -> list[bytes]:
    """The certificates the broker shows in its TLS handshake, not checked in any way."""
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
    context.check_hostname = False
    context.verify_mode = ssl.CERT_NONE
    try:
        with (
            socket.create_connection((settings.host, settings.port), HANDSHAKE_TIMEOUT_S) as raw,
            context.wrap_socket(raw, server_hostname=settings.host) as tls,
        ):
            # Public from Python 3.13 on as get_unverified_chain(); present since 3.10.
            chain = tls._sslobj.get_unverified_chain()  # type: ignore[attr-defined]
            return [cert.public_bytes(ssl._ssl.ENCODING_DER) for cert in chain or []]  # type: ignore[attr-defined]
    except (OSError, ssl.SSLError) as error:
        raise BrokerConnectionError(
            "unreachable",
            f"Cannot reach the TLS listener at {settings.url} ({error}): check the address in "
            "the join token, the network, and that the broker runs with --lan.",
            url=settings.url,
        ) from None
