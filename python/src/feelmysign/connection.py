"""Where the broker is and how to log in: one settings object and one client factory.

Every program of feelmysign (sleeve, sender, tools, benchmarks) connects
through ``new_client``, so they share the transport, TLS and protocol choices.
"""

from __future__ import annotations

import ssl
from dataclasses import dataclass
from typing import Literal
from urllib.parse import urlsplit

import paho.mqtt.client as mqtt
from paho.mqtt.enums import CallbackAPIVersion

from feelmysign.errors import FeelMySignError

SCHEMES: dict[str, tuple[Literal["tcp", "websockets"], bool, int]] = {
    "mqtt": ("tcp", False, 1883),
    "mqtts": ("tcp", True, 8883),
    "ws": ("websockets", False, 9001),
    "wss": ("websockets", True, 443),
}
EXAMPLE_URL = "mqtt://127.0.0.1:1883"


@dataclass(frozen=True)
class BrokerSettings:
    host: str
    port: int
    transport: Literal["tcp", "websockets"] = "tcp"
    tls: bool = False
    path: str = "/"
    username: str | None = None
    password: str | None = None

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


def parse_broker_url(
    url: str, *, username: str | None = None, password: str | None = None
) -> BrokerSettings:
    """Settings from ``mqtt://host:port``, ``mqtts://``, ``ws://host:port/path`` or ``wss://``."""
    try:
        parts = urlsplit(url.strip())
        port = parts.port
    except ValueError as error:
        raise FeelMySignError(
            f"broker URL {url!r} is not valid ({error}); e.g. {EXAMPLE_URL}"
        ) from error
    if parts.scheme not in SCHEMES or not parts.hostname:
        raise FeelMySignError(
            f"broker URL {url!r} is not valid: it needs a scheme ({', '.join(SCHEMES)}) and a "
            f"host, e.g. {EXAMPLE_URL}"
        )
    transport, tls, default_port = SCHEMES[parts.scheme]
    return BrokerSettings(
        host=parts.hostname,
        port=port or default_port,
        transport=transport,
        tls=tls,
        path=parts.path or "/",
        username=username if username is not None else parts.username,
        password=password if password is not None else parts.password,
    )


def new_client(
    settings: BrokerSettings, *, client_id: str = "", persistent_session: bool = False
) -> mqtt.Client:
    """A paho-mqtt 2 client (MQTT 3.1.1) set up for ``settings``; not yet connected.

    A persistent session (fixed client id, clean session off) lets the broker
    keep QoS 1 messages for a sleeve that is away, and its subscriptions.
    """
    client = mqtt.Client(
        CallbackAPIVersion.VERSION2,
        client_id=client_id,
        clean_session=not persistent_session,
        protocol=mqtt.MQTTv311,
        transport=settings.transport,
    )
    if settings.transport == "websockets":
        client.ws_set_options(path=settings.path)
    if settings.tls:
        client.tls_set(cert_reqs=ssl.CERT_REQUIRED)
    if settings.username is not None:
        client.username_pw_set(settings.username, settings.password)
    client.max_queued_messages_set(0)  # queue without limit while away: never drop a stroke
    return client
