"""Why a connection to a broker failed, as a reason code and a sentence a person can act on."""

from __future__ import annotations

import socket
import ssl
from typing import TYPE_CHECKING

from feelmysign.connection.settings import SENDER_USERNAME_PREFIX, BrokerSettings

if TYPE_CHECKING:  # paho is imported where a client is made, not by 'feelmysign --help'
    from paho.mqtt.reasoncodes import ReasonCode

# MQTT 5 CONNACK reason codes that mean "these credentials": Bad user name or
# password, Not authorized.
LOGIN_REFUSED = (134, 135)
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
    if isinstance(failure, ssl.SSLCertVerificationError):
        return _certificate_message(settings, failure)
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


def _certificate_message(settings: BrokerSettings, failure: ssl.SSLCertVerificationError) -> str:
    """Why the broker's certificate was not accepted (OpenSSL's verify message), and what to
    do: an expired certificate and one for another host are the broker's to fix, not a reason
    to leave TLS."""
    url = settings.url
    why = failure.verify_message or failure.reason or str(failure)
    start = f"The TLS handshake with {url} failed: the broker's certificate was refused ({why})"
    if "expired" in why or "not yet valid" in why:
        return (
            f"{start}. Renew the certificate on the broker (for Let's Encrypt: certbot renew, "
            "then reload Mosquitto), and check that this machine's clock is right "
            "('timedatectl' must say 'System clock synchronized: yes')."
        )
    if "mismatch" in why:
        return (
            f"{start}: it is not made out for {settings.host!r}. Give --broker the host name "
            "the certificate names (for a 'feelmysign broker --lan' broker, the address its "
            "join tokens carry)."
        )
    if settings.ca_file is not None:
        return (
            f"{start}: the CA given with --ca ({settings.ca_file}) did not sign it. Give the "
            "ca.pem of that broker (or of the CA that signed its certificate)."
        )
    return (
        f"{start}: this machine does not trust it. For a 'feelmysign broker --lan' broker, send "
        "with the token of 'feelmysign broker add-sender' (--join TOKEN), or copy its ca.pem "
        "here and give --ca FILE."
    )


def _login_refused_message(settings: BrokerSettings, code: ReasonCode) -> str:
    if code.value not in LOGIN_REFUSED:
        return f"The broker at {settings.url} refused the connection ({code}, code {code.value})."
    who = f"user {settings.username!r}" if settings.username else "an anonymous login"
    if settings.username and settings.username.startswith(SENDER_USERNAME_PREFIX):
        # A sender with an account of its own: the wearer's page may have blocked it.
        name = settings.username.removeprefix(SENDER_USERNAME_PREFIX)
        return (
            f"The broker at {settings.url} refused sender {name!r} ({code}): not authorised. "
            "The wearer blocked this sender on the wearer's page (or its account was removed); "
            "ask the wearer to unblock it, or ask for a new join token."
        )
    return (
        f"The broker at {settings.url} refused {who} ({code}): check the user name and "
        "password, or pass the credentials.json of that broker with --credentials FILE "
        "('feelmysign broker' writes it in its state directory)."
    )
