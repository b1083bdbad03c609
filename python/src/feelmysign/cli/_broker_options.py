"""Broker options shared by the commands that talk to a broker (``send``, ``sleeve``).

    --broker URL          mqtt://HOST:PORT, mqtts:// (TLS), ws:// or wss:// (WebSockets)
    --id ID               the sleeve's id (default sleeve1)
    --username U --password P, or --credentials FILE (the credentials.json of 'feelmysign broker')

Each setting is taken from, in order: its option, its ``FEELMYSIGN_*`` environment
variable, the credentials file, the default. The credentials file gives the
account of the ``role`` (the sender's or the sleeve's), the MQTT URL and the
sleeve id. When no broker, user or credentials file is given at all, the local
broker's file (``feelmysign broker``'s default state directory) is used if it
exists, so that ``feelmysign send --shape circle`` just works next to it; it is
never sent to a broker named by --broker, so its passwords stay local.

``connect_client`` opens an MQTT 5 connection and waits for the broker's
answer, turning every way it can fail into a BrokerConnectionError a person can
act on (MQTT 5, because only its acknowledgements say when a publish is refused).
"""

from __future__ import annotations

import argparse
import os
import socket
import ssl
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal
from urllib.parse import urlsplit

import paho.mqtt.client as mqtt
from paho.mqtt.enums import CallbackAPIVersion
from paho.mqtt.reasoncodes import ReasonCode

from feelmysign._broker_error import BrokerError
from feelmysign._credentials import Credentials, check_sleeve_id, load_credentials
from feelmysign.broker import DEFAULT_MQTT_PORT, DEFAULT_SLEEVE_ID, default_state_dir
from feelmysign.connection import SCHEMES
from feelmysign.connection import BrokerSettings as ConnectionSettings

Role = Literal["sender", "sleeve"]

BROKER_ENV = "FEELMYSIGN_BROKER"
SLEEVE_ID_ENV = "FEELMYSIGN_SLEEVE_ID"
USERNAME_ENV = "FEELMYSIGN_USERNAME"
PASSWORD_ENV = "FEELMYSIGN_PASSWORD"
CREDENTIALS_ENV = "FEELMYSIGN_CREDENTIALS"
DEFAULT_BROKER_URL = f"mqtt://127.0.0.1:{DEFAULT_MQTT_PORT}"  # where 'feelmysign broker' listens
DEFAULT_TIMEOUT_S = 10.0  # a broker on the same continent answers in well under a second
KEEPALIVE_S = 30  # a dead connection is noticed within 1.5 x this
# MQTT 5 CONNACK reason codes that mean "these credentials": Bad user name or
# password, Not authorized.
_LOGIN_REFUSED = (134, 135)
_START_HINT = "start one with 'feelmysign broker' or 'make up', or give the right --broker URL"


class BrokerConnectionError(BrokerError):
    """A broker that cannot be reached, refuses the login, or refuses or drops a message.

    ``reason`` (as for BrokerError) is one of ``bad-url``, ``bad-option``,
    ``refused`` (nothing listens), ``unreachable`` (name, route, TLS),
    ``login-refused``, ``timeout``, ``closed`` (the connection dropped) and
    ``publish-refused``; ``url`` is the broker's URL when known.
    """

    def __init__(self, reason: str, message: str, *, url: str | None = None) -> None:
        super().__init__(reason, message)
        self.url = url


@dataclass(frozen=True)
class BrokerSettings(ConnectionSettings):
    """Where the broker is, how to log in (``feelmysign.connection``), and which sleeve.

    A ``connection.BrokerSettings``, so ``connection.new_client`` takes it as is.
    """

    sleeve_id: str = DEFAULT_SLEEVE_ID

    @property
    def strokes_topic(self) -> str:
        return f"feelmysign/{self.sleeve_id}/strokes"


def add_broker_options(parser: argparse.ArgumentParser, *, role: Role) -> None:
    """Add --broker, --id, --username, --password and --credentials for ``role``."""
    group = parser.add_argument_group(
        "broker",
        "Where the MQTT broker is and how to log in. Each setting comes from its option, "
        "else its environment variable, else --credentials, else the default.",
    )
    group.add_argument(
        "--broker",
        metavar="URL",
        help=f"broker URL: mqtt://HOST:PORT, mqtts:// (TLS), ws:// or wss:// (WebSockets) "
        f"(default: ${BROKER_ENV}, else the credentials file's mqtt_url, else "
        f"{DEFAULT_BROKER_URL})",
    )
    which = "the sleeve to send to" if role == "sender" else "this sleeve's id"
    group.add_argument(
        "--id",
        dest="sleeve_id",
        metavar="ID",
        help=f"{which}: 1-64 letters, digits, '_' or '-' (default: ${SLEEVE_ID_ENV}, else "
        f"the credentials file's sleeve id, else {DEFAULT_SLEEVE_ID})",
    )
    group.add_argument("--username", metavar="U", help=f"MQTT user name (default: ${USERNAME_ENV})")
    group.add_argument(
        "--password",
        metavar="P",
        help=f"MQTT password (default: ${PASSWORD_ENV}; prefer it or --credentials: "
        "other users can see command lines)",
    )
    group.add_argument(
        "--credentials",
        metavar="FILE",
        help=f"the credentials.json written by 'feelmysign broker', for the {role} account, "
        f"the URL and the sleeve id (default: ${CREDENTIALS_ENV}, else "
        f"{local_credentials_path()} when it exists and nothing else is given)",
    )


def local_credentials_path() -> Path:
    """The credentials file of a ``feelmysign broker`` run with its default state directory."""
    return default_state_dir() / "credentials.json"


def broker_settings_from_args(args: argparse.Namespace, role: Role) -> BrokerSettings:
    """The settings the options and environment ask for; BrokerError saying what is wrong."""
    env = os.environ
    url = args.broker or env.get(BROKER_ENV) or None
    username = args.username or env.get(USERNAME_ENV) or None
    password = args.password or env.get(PASSWORD_ENV) or None
    credentials = _credentials(args.credentials or env.get(CREDENTIALS_ENV), url, username)
    if username is None and password is not None:
        raise BrokerConnectionError(
            "bad-option",
            f"A password was given (--password or ${PASSWORD_ENV}) without a user name: "
            f"give --username too (or ${USERNAME_ENV}).",
        )
    if username is not None and password is None:
        raise BrokerConnectionError(
            "bad-option",
            f"User {username!r} was given without a password: give --password too "
            f"(or ${PASSWORD_ENV}), or use --credentials FILE.",
        )
    if username is None and credentials is not None:
        account = credentials.sender if role == "sender" else credentials.sleeve
        username, password = account.username, account.password
    if url is None:
        url = credentials.mqtt_url if credentials is not None else DEFAULT_BROKER_URL
    sleeve_id = args.sleeve_id or env.get(SLEEVE_ID_ENV) or None
    if sleeve_id is None:
        sleeve_id = credentials.sleeve_id if credentials is not None else DEFAULT_SLEEVE_ID
    return parse_broker_url(
        url, username=username, password=password, sleeve_id=check_sleeve_id(sleeve_id)
    )


def _credentials(path: str | None, url: str | None, username: str | None) -> Credentials | None:
    if path:
        return load_credentials(path)
    local = local_credentials_path()
    if url is None and username is None and local.is_file():
        return load_credentials(local)
    return None


def parse_broker_url(
    url: str,
    *,
    username: str | None = None,
    password: str | None = None,
    sleeve_id: str = DEFAULT_SLEEVE_ID,
) -> BrokerSettings:
    """Settings for ``url``; BrokerConnectionError ``bad-url`` naming what is wrong with it."""
    text = url.strip()
    if "://" not in text:
        return _bad_url(url, "has no scheme", f"write it as mqtt://{text or '127.0.0.1:1883'}")
    parts = urlsplit(text)
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


# --- connecting -----------------------------------------------------------------------------


def connect_client(
    settings: ConnectionSettings, client_id: str, *, timeout_s: float = DEFAULT_TIMEOUT_S
) -> mqtt.Client:
    """An MQTT 5 client (clean start), logged in, its network loop running on a thread.

    Returns once the broker accepted the login; BrokerConnectionError saying what
    to do otherwise. The caller disconnects it and stops its loop.
    """
    client = _new_v5_client(settings, client_id)
    client.connect_timeout = timeout_s
    answers: list[ReasonCode] = []

    def on_connect(
        _client: mqtt.Client, _userdata: Any, _flags: Any, code: ReasonCode, _props: Any
    ) -> None:
        answers.append(code)

    client.on_connect = on_connect
    try:
        client.connect(settings.host, settings.port, keepalive=KEEPALIVE_S)
    except (OSError, mqtt.WebsocketConnectionError) as error:
        raise BrokerConnectionError(
            _failure_reason(error), connect_failure_message(settings, error), url=settings.url
        ) from None
    # Driven by hand until the CONNACK: a network thread would retry a refused login.
    deadline_s = time.monotonic() + timeout_s
    while not answers:
        remaining_s = deadline_s - time.monotonic()
        if remaining_s <= 0 or client.loop(timeout=min(remaining_s, 1.0)) != mqtt.MQTT_ERR_SUCCESS:
            if answers:
                break
            client.disconnect()
            failure = TimeoutError() if remaining_s <= 0 else ConnectionResetError()
            raise BrokerConnectionError(
                _failure_reason(failure),
                connect_failure_message(settings, failure),
                url=settings.url,
            )
    client.on_connect = None
    if answers[0].is_failure:
        client.disconnect()
        raise BrokerConnectionError(
            "login-refused", connect_failure_message(settings, answers[0]), url=settings.url
        )
    client.loop_start()
    return client


def _new_v5_client(settings: ConnectionSettings, client_id: str) -> mqtt.Client:
    client = mqtt.Client(
        CallbackAPIVersion.VERSION2,
        client_id=client_id,
        protocol=mqtt.MQTTv5,
        transport=settings.transport,
    )
    if settings.transport == "websockets":
        client.ws_set_options(path=settings.path)
    if settings.tls:
        client.tls_set(cert_reqs=ssl.CERT_REQUIRED)
    if settings.username is not None:
        client.username_pw_set(settings.username, settings.password)
    return client


def _failure_reason(error: BaseException) -> str:
    if isinstance(error, ConnectionRefusedError):
        return "refused"
    if isinstance(error, TimeoutError):
        return "timeout"
    if isinstance(error, ConnectionResetError):
        return "closed"
    return "unreachable"


def connect_failure_message(
    settings: ConnectionSettings, failure: BaseException | ReasonCode
) -> str:
    """Why connecting to ``settings`` failed and what to do, for an error or a CONNACK code."""
    url = settings.url
    if isinstance(failure, ReasonCode):
        return _login_refused_message(settings, failure)
    if isinstance(failure, ConnectionRefusedError):
        return f"Nothing accepts connections at {url} (connection refused): {_START_HINT}."
    if isinstance(failure, socket.gaierror):
        return (
            f"Cannot find the host {settings.host!r} of {url} ({failure.strerror}): check the "
            "host name in --broker (or $FEELMYSIGN_BROKER)."
        )
    if isinstance(failure, TimeoutError):
        return (
            f"No answer from {url}: check the host and port, the network and any firewall; "
            f"or {_START_HINT}."
        )
    if isinstance(failure, ssl.SSLError):
        return (
            f"The TLS handshake with {url} failed ({failure.reason or failure}): mqtts:// and "
            "wss:// need a TLS listener with a certificate this machine trusts; use mqtt:// or "
            "ws:// for a listener without TLS (such as the local broker's)."
        )
    if isinstance(failure, ConnectionResetError | mqtt.WebsocketConnectionError):
        kind = "WebSocket" if settings.transport == "websockets" else "TCP"
        return (
            f"{url} closed the connection before answering the login: is that port an MQTT "
            f"broker's {kind} listener? (The local broker's ports are in its credentials.json.)"
        )
    detail = getattr(failure, "strerror", None) or str(failure) or type(failure).__name__
    return f"Cannot connect to {url} ({detail}): check --broker, or {_START_HINT}."


def _login_refused_message(settings: ConnectionSettings, code: ReasonCode) -> str:
    if code.value not in _LOGIN_REFUSED:
        return f"The broker at {settings.url} refused the connection ({code}, code {code.value})."
    who = f"user {settings.username!r}" if settings.username else "an anonymous login"
    return (
        f"The broker at {settings.url} refused {who} ({code}): check the user name and "
        "password, or pass the credentials.json of that broker with --credentials FILE "
        "('feelmysign broker' writes it in its state directory)."
    )
