"""Where the broker is, how to log in and which sleeve: one settings object and its URL parser.

``BrokerSettings`` is the one broker identity of feelmysign: a broker URL (transport,
host, port, path), its TLS (on, and the CA to verify with), the login on it and the
sleeve. ``parse_broker_url`` is the only place a broker URL is read; the broker's
``credentials.json`` gives settings for either of its logins with ``Credentials.settings``.
"""

from __future__ import annotations

import ipaddress
from dataclasses import dataclass, replace
from typing import Literal
from urllib.parse import urlsplit

from feelmysign.errors import BrokerConnectionError
from feelmysign.topics import strokes_topic

# Here, not in the broker package: the broker's files read URLs with parse_broker_url.
DEFAULT_MQTT_PORT = 1883  # IANA's MQTT port
DEFAULT_SLEEVE_ID = "sleeve1"
# The user names of the senders with an account of their own (broker add-sender --name),
# which the wearer may block.
SENDER_USERNAME_PREFIX = "sender-"
Transport = Literal["tcp", "websockets"]
# scheme -> (transport, TLS on, default port)
SCHEMES: dict[str, tuple[Transport, bool, int]] = {
    "mqtt": ("tcp", False, 1883),
    "mqtts": ("tcp", True, 8883),
    "ws": ("websockets", False, 9001),
    "wss": ("websockets", True, 443),
}
DEFAULT_BROKER_URL = f"mqtt://127.0.0.1:{DEFAULT_MQTT_PORT}"  # where 'feelmysign broker' listens
USERNAME_ENV = "FEELMYSIGN_USERNAME"
PASSWORD_ENV = "FEELMYSIGN_PASSWORD"


@dataclass(frozen=True)
class BrokerSettings:
    """One broker endpoint, the login on it, and the sleeve the program sends to or plays as."""

    host: str
    port: int
    transport: Transport = "tcp"
    tls: bool = False
    path: str = "/"
    username: str | None = None
    password: str | None = None
    sleeve_id: str = DEFAULT_SLEEVE_ID
    # The CA certificate (PEM) to verify the broker with; None: the system's trusted CAs.
    ca_file: str | None = None
    # Further servers of the same cluster (host, port), tried in turn when one fails.
    fallbacks: tuple[tuple[str, int], ...] = ()

    def endpoints(self) -> list[BrokerSettings]:
        """These settings once per server: the first, then each fallback."""
        return [self] + [replace(self, host=h, port=p, fallbacks=()) for h, p in self.fallbacks]

    @property
    def urls(self) -> str:
        """Every server's URL, comma separated (as --broker takes them)."""
        return ",".join(endpoint.url for endpoint in self.endpoints())

    @property
    def on_loopback(self) -> bool:
        """The broker is on this machine: the only place a password may go in clear text."""
        if self.host == "localhost":
            return True
        try:
            return ipaddress.ip_address(self.host).is_loopback
        except ValueError:
            return False

    @property
    def url(self) -> str:
        scheme = {
            ("tcp", False): "mqtt",
            ("tcp", True): "mqtts",
            ("websockets", False): "ws",
            ("websockets", True): "wss",
        }[(self.transport, self.tls)]
        suffix = self.path if self.transport == "websockets" and self.path != "/" else ""
        return f"{scheme}://{self.host}:{self.port}{suffix}"

    @property
    def strokes_topic(self) -> str:
        return strokes_topic(self.sleeve_id)


def parse_broker_url(
    url: str,
    *,
    username: str | None = None,
    password: str | None = None,
    sleeve_id: str = DEFAULT_SLEEVE_ID,
) -> BrokerSettings:
    """Settings for ``url``; BrokerConnectionError ``bad-url`` naming what is wrong with it.

    Several URLs separated by commas are the servers of one cluster: the client fails
    over between them. They must share the scheme (and the path, for WebSockets).
    """
    if "," in url:
        return _parse_cluster(url, username=username, password=password, sleeve_id=sleeve_id)
    text = url.strip()
    if "://" not in text:
        return _bad_url(url, "has no scheme", f"write it as mqtt://{text or '127.0.0.1:1883'}")
    try:
        parts = urlsplit(text)
    except ValueError as error:  # an unclosed '[' of an IPv6 address, for one
        return _bad_url(
            url, f"cannot be read ({error})", "e.g. mqtt://127.0.0.1:1883 or mqtt://[::1]:1883"
        )
    scheme = parts.scheme.lower()
    if scheme not in SCHEMES:
        return _bad_url(url, f"uses the scheme {parts.scheme!r}", _scheme_hint(scheme))
    if parts.username is not None or parts.password is not None:
        return _bad_url(
            url,
            "contains a user name or password",
            f"leave them out and use --username/--password, ${USERNAME_ENV}/${PASSWORD_ENV} or "
            "--credentials (a URL shows up in process lists and logs)",
        )
    if not parts.hostname:
        return _bad_url(url, "has no host name", "e.g. mqtt://127.0.0.1:1883")
    try:
        port = parts.port
    except ValueError:
        shown = parts.netloc.rpartition(":")[2]
        return _bad_url(url, f"has the port {shown!r}", "use a whole number from 1 to 65535")
    if port == 0:
        return _bad_url(url, "has the port 0", "use a whole number from 1 to 65535")
    transport, tls, default_port = SCHEMES[scheme]
    if parts.query or parts.fragment or (transport == "tcp" and parts.path not in ("", "/")):
        return _bad_url(
            url,
            "has a path, query or fragment",
            "an mqtt:// or mqtts:// URL is only scheme://HOST:PORT; ws:// may have a path",
        )
    return BrokerSettings(
        host=parts.hostname,
        port=port or default_port,
        transport=transport,
        tls=tls,
        path=parts.path or "/",
        username=username,
        password=password,
        sleeve_id=sleeve_id,
    )


def _parse_cluster(
    urls: str, *, username: str | None, password: str | None, sleeve_id: str
) -> BrokerSettings:
    parts = [
        parse_broker_url(u, username=username, password=password, sleeve_id=sleeve_id)
        for u in urls.split(",")
        if u.strip()
    ]
    first = parts[0]
    for other in parts[1:]:
        if (other.transport, other.tls, other.path) != (first.transport, first.tls, first.path):
            _bad_url(
                urls,
                "mixes schemes or paths",
                "the servers of one cluster are reached the same way, e.g. "
                "mqtt://a:1883,mqtt://b:1883",
            )
    return replace(first, fallbacks=tuple((p.host, p.port) for p in parts[1:]))


def _scheme_hint(scheme: str) -> str:
    instead = {"tcp": "mqtt", "ssl": "mqtts", "tls": "mqtts", "http": "ws", "https": "wss"}
    known = "mqtt:// (TCP), mqtts:// (TLS), ws:// or wss:// (WebSockets)"
    if scheme in instead:
        return f"write {instead[scheme]}:// instead; the schemes are {known}"
    return f"use {known}, e.g. {DEFAULT_BROKER_URL}"


def _bad_url(url: str, problem: str, hint: str) -> BrokerSettings:
    raise BrokerConnectionError(
        "bad-url", f"The broker URL {url!r} {problem}: {hint}.", url=url or None
    )
