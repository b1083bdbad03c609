"""Why a connection to a broker failed, as a reason code and a sentence a person can act on."""

from __future__ import annotations

import socket
import ssl
from typing import TYPE_CHECKING

from feelmysign.connection.settings import BrokerSettings

if TYPE_CHECKING:  # paho is imported where a client is made, not by 'feelmysign --help'
    from paho.mqtt.reasoncodes import ReasonCode

# MQTT 5 CONNACK reason codes that mean "these credentials": Bad user name or
# password, Not authorized.
_LOGIN_REFUSED = (134, 135)
_START_HINT = "start one with 'feelmysign broker' or 'make up', or give the right --broker URL"


def failure_reason(error: BaseException) -> str:
    if isinstance(error, ConnectionRefusedError):
        return "refused"
    if isinstance(error, TimeoutError):
        return "timeout"
    if isinstance(error, ConnectionResetError):
        return "closed"
    return "unreachable"


def connect_failure_message(settings: BrokerSettings, failure: BaseException | ReasonCode) -> str:
    """Why connecting to ``settings`` failed and what to do, for an error or a CONNACK code."""
    import paho.mqtt.client as mqtt
    from paho.mqtt.reasoncodes import ReasonCode

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
    if isinstance(failure, ssl.SSLCertVerificationError) and settings.ca_file is None:
        return (
            f"The TLS handshake with {url} failed ({failure.reason or failure}): this machine "
            "does not trust the broker's certificate. For a 'feelmysign broker --lan' broker, "
            "send with the token of 'feelmysign broker add-sender' (--join TOKEN), or copy its "
            "ca.pem here and give --ca FILE."
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


def _login_refused_message(settings: BrokerSettings, code: ReasonCode) -> str:
    if code.value not in _LOGIN_REFUSED:
        return f"The broker at {settings.url} refused the connection ({code}, code {code.value})."
    who = f"user {settings.username!r}" if settings.username else "an anonymous login"
    return (
        f"The broker at {settings.url} refused {who} ({code}): check the user name and "
        "password, or pass the credentials.json of that broker with --credentials FILE "
        "('feelmysign broker' writes it in its state directory)."
    )
