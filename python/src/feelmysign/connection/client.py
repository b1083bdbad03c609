"""The one MQTT client factory: every program of feelmysign (sleeve, sender, tools,
benchmarks) connects through ``new_client`` or ``connect_client``, so they share the
transport, TLS and protocol choices.
"""

from __future__ import annotations

import ssl
import time
from typing import Any

import paho.mqtt.client as mqtt
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion
from paho.mqtt.reasoncodes import ReasonCode

from feelmysign.connection.failures import connect_failure_message, failure_reason
from feelmysign.connection.settings import BrokerSettings
from feelmysign.errors import BrokerConnectionError

DEFAULT_TIMEOUT_S = 10.0  # a broker on the same continent answers in well under a second
KEEPALIVE_S = 30  # a dead connection is noticed within 1.5 x this


def new_client(
    settings: BrokerSettings,
    *,
    client_id: str = "",
    persistent_session: bool = False,
    protocol: MQTTProtocolVersion = mqtt.MQTTv311,
) -> mqtt.Client:
    """A paho-mqtt 2 client set up for ``settings``; not yet connected.

    A persistent session (fixed client id, clean session off) lets the broker
    keep QoS 1 messages for a sleeve that is away, and its subscriptions.
    Persistent sessions are an MQTT 3.1.1 notion here (``clean_session``).
    """
    if protocol == mqtt.MQTTv5:
        client = mqtt.Client(
            CallbackAPIVersion.VERSION2,
            client_id=client_id,
            protocol=mqtt.MQTTv5,
            transport=settings.transport,
        )
    else:
        client = mqtt.Client(
            CallbackAPIVersion.VERSION2,
            client_id=client_id,
            clean_session=not persistent_session,
            protocol=protocol,
            transport=settings.transport,
        )
        client.max_queued_messages_set(0)  # queue without limit while away: never drop a stroke
    if settings.transport == "websockets":
        client.ws_set_options(path=settings.path)
    if settings.tls:
        client.tls_set(cert_reqs=ssl.CERT_REQUIRED)
    if settings.username is not None:
        client.username_pw_set(settings.username, settings.password)
    return client


def connect_client(
    settings: BrokerSettings, client_id: str, *, timeout_s: float = DEFAULT_TIMEOUT_S
) -> mqtt.Client:
    """An MQTT 5 client (clean start), logged in, its network loop running on a thread.

    MQTT 5, because only its acknowledgements say when a publish is refused.
    Returns once the broker accepted the login; BrokerConnectionError saying what
    to do otherwise. The caller disconnects it and stops its loop.
    """
    client = new_client(settings, client_id=client_id, protocol=mqtt.MQTTv5)
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
            failure_reason(error), connect_failure_message(settings, error), url=settings.url
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
                failure_reason(failure),
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
