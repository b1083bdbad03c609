"""The one MQTT client factory: every program of feelmysign (sleeve, sender, tools,
benchmarks) connects through ``new_client`` or ``connect_client``, so they share the
transport, TLS and protocol choices; ``probe_login`` asks whether a broker is ready.
"""

from __future__ import annotations

import contextlib
import random
import socket
import ssl
import sys
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from feelmysign.connection.failures import connect_failure_message, failure_reason
from feelmysign.connection.settings import BrokerSettings
from feelmysign.errors import BrokerConnectionError

if TYPE_CHECKING:  # paho is imported where a client is made, not by 'feelmysign --help'
    import paho.mqtt.client as mqtt
    from paho.mqtt.enums import MQTTProtocolVersion
    from paho.mqtt.reasoncodes import ReasonCode

DEFAULT_TIMEOUT_S = 10.0  # a broker on the same continent answers in well under a second
# MQTT 5's CONNACK "Unsupported protocol version": a 3.1.1-only broker (NATS, older ones).
UNSUPPORTED_PROTOCOL_VERSION = 132
KEEPALIVE_S = 30  # a dead connection is noticed within 1.5 x this
# Between reconnection attempts: a few seconds at most, so a sleeve is back soon after its
# broker, drawn at random each time so that many clients do not return all at once.
RECONNECT_MIN_S = 0.5
RECONNECT_MAX_S = 3.0
# A readiness probe: a broker starting up on this machine answers within milliseconds.
PROBE_POLL_S = 0.02
PROBE_KEEPALIVE_S = 10
CONNACK_POLL_S = 1.0


def _to_stderr(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def new_client(
    settings: BrokerSettings,
    *,
    client_id: str = "",
    persistent_session: bool = False,
    protocol: MQTTProtocolVersion | None = None,
) -> mqtt.Client:
    """A paho-mqtt 2 client set up for ``settings``; not yet connected.

    A persistent session (fixed client id, clean session off) lets the broker
    keep QoS 1 messages for a sleeve that is away, and its subscriptions.
    Persistent sessions are an MQTT 3.1.1 notion here (``clean_session``).
    A password is never sent in clear text off loopback: BrokerConnectionError
    ``plain-text`` says to use mqtts:// or wss:// instead. ``protocol`` is MQTT 3.1.1
    unless given.
    """
    import paho.mqtt.client as mqtt
    from paho.mqtt.enums import CallbackAPIVersion

    check_no_plain_text_password(settings)
    if protocol is None:
        protocol = mqtt.MQTTv311
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
        try:
            client.tls_set(ca_certs=settings.ca_file, cert_reqs=ssl.CERT_REQUIRED)
        except ssl.SSLError as error:  # a file that is there but holds no certificate
            raise BrokerConnectionError(
                "bad-option",
                f"The CA file {settings.ca_file} holds no certificate OpenSSL can read "
                f"({error.reason or error}): give the broker's ca.pem (a PEM file that begins "
                "'-----BEGIN CERTIFICATE-----'), not its key or another file.",
                url=settings.url,
            ) from None
    if settings.username is not None:
        client.username_pw_set(settings.username, settings.password)
    client.on_socket_open = send_at_once
    jitter_reconnects(client)
    if settings.fallbacks:
        _fail_over(client, settings)
    return client


def send_at_once(client: mqtt.Client, userdata: object, sock: object) -> None:
    """Every packet leaves when written (TCP_NODELAY, as the broker sends its own).

    With Nagle's algorithm a small packet waits until the broker has acknowledged the one
    before it, and the broker holds that acknowledgement up to 40 ms when it has nothing to
    send back: a sleeve's ``cancelled`` event, written just after its PUBACK of the cancel,
    reached the page 40 ms late. paho calls this as each connection's socket opens; under
    a WebSocket its wrapper holds the socket.
    """
    tcp: Any = getattr(sock, "_socket", sock)
    # Not a TCP socket (a Unix socket, a test's stand-in): no Nagle there, nothing to set.
    with contextlib.suppress(AttributeError, OSError):
        tcp.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


def jitter_reconnects(
    client: mqtt.Client,
    *,
    min_s: float = RECONNECT_MIN_S,
    max_s: float = RECONNECT_MAX_S,
    uniform: Callable[[float, float], float] = random.uniform,
) -> None:
    """Wait a random ``min_s``..``max_s`` seconds before each of paho's automatic reconnects.

    Paho's own backoff doubles up to a fixed maximum and has no jitter; drawing the next
    wait before every attempt (``on_pre_connect``) gives a capped wait with jitter.
    """

    def draw_next_wait(client: mqtt.Client, _userdata: object) -> None:
        wait_s = uniform(min_s, max_s)
        # Typed int, but paho waits any number of seconds (it compares clock readings).
        client.reconnect_delay_set(wait_s, wait_s)  # type: ignore[arg-type]

    client.on_pre_connect = draw_next_wait
    draw_next_wait(client, None)


def _fail_over(client: mqtt.Client, settings: BrokerSettings) -> None:
    """Before every (re)connection attempt, move to the next server of the cluster.

    paho calls ``on_pre_connect`` before each attempt, the automatic reconnections of
    its network thread included, before it opens the socket. Its ``host``/``port``
    setters refuse while connecting, so the fields they set are written directly
    (paho 2.x reads them when it opens the socket). The first attempt goes to the
    first server.
    """
    servers = [(settings.host, settings.port), *settings.fallbacks]
    attempts = [0]
    before = client.on_pre_connect  # the jittered reconnect wait: kept

    def next_server(client: mqtt.Client, userdata: Any) -> None:
        if before is not None:
            before(client, userdata)
        client._host, client._port = servers[attempts[0] % len(servers)]
        attempts[0] += 1

    client.on_pre_connect = next_server


def check_no_plain_text_password(settings: BrokerSettings) -> None:
    if settings.tls or settings.password is None or settings.on_loopback:
        return
    secure = "mqtts" if settings.transport == "tcp" else "wss"
    raise BrokerConnectionError(
        "plain-text",
        f"Refusing to send the password for {settings.username!r} in clear text to "
        f"{settings.url}, which is not this machine: use {secure}:// (TLS), e.g. the URL "
        "'feelmysign up --lan' prints, or a join token from 'feelmysign broker add-sleeve'.",
        url=settings.url,
    )


def connect_client(
    settings: BrokerSettings,
    client_id: str,
    *,
    timeout_s: float = DEFAULT_TIMEOUT_S,
    note: Callable[[str], None] = _to_stderr,
    persistent_session: bool = False,
) -> mqtt.Client:
    """A client (clean start), logged in, its network loop running on a thread.

    ``persistent_session``: MQTT 3.1.1 with clean session off instead (see ``new_client``):
    the broker keeps the client's subscriptions and its QoS 1 messages while it is away, a
    broker restarted from its saved state included, so a listener misses nothing published
    while it reconnects.

    MQTT 5 where the broker offers it, because only its acknowledgements say when a
    publish is refused; MQTT 3.1.1 otherwise (``note`` says so). With several servers,
    each is tried in turn. Returns once a broker accepted the login; BrokerConnectionError
    saying what to do otherwise. The caller disconnects it and stops its loop.
    """
    failure: BrokerConnectionError | None = None
    for endpoint in settings.endpoints():
        try:
            if persistent_session:
                return _connect_with(endpoint, client_id, timeout_s, None, persistent_session=True)
            return _connect_one(endpoint, client_id, timeout_s, note)
        except BrokerConnectionError as error:
            if error.reason == "login-refused":
                raise
            failure = error
    assert failure is not None
    raise failure


def _connect_one(
    settings: BrokerSettings, client_id: str, timeout_s: float, note: Callable[[str], None]
) -> mqtt.Client:
    import paho.mqtt.client as mqtt

    try:
        return _connect_with(settings, client_id, timeout_s, mqtt.MQTTv5)
    except BrokerConnectionError as error:
        if error.reason != "old-protocol":
            raise
    note(
        f"Note: {settings.url} speaks MQTT 3.1.1, not 5: a stroke its access rules refuse "
        "cannot be reported as refused (MQTT 3.1.1 acknowledges every publish)."
    )
    return _connect_with(settings, client_id, timeout_s, mqtt.MQTTv311)


def _connect_with(
    settings: BrokerSettings,
    client_id: str,
    timeout_s: float,
    protocol: MQTTProtocolVersion | None,
    *,
    persistent_session: bool = False,
) -> mqtt.Client:
    import paho.mqtt.client as mqtt

    client = new_client(
        settings, client_id=client_id, protocol=protocol, persistent_session=persistent_session
    )
    client.connect_timeout = timeout_s
    try:
        answers = _send_login(client, settings, keepalive_s=KEEPALIVE_S)
    except (OSError, mqtt.WebsocketConnectionError) as error:
        raise BrokerConnectionError(
            failure_reason(error), connect_failure_message(settings, error), url=settings.url
        ) from None
    failure = _await_connack(client, answers, timeout_s=timeout_s, poll_s=CONNACK_POLL_S)
    if failure is not None:
        client.disconnect()
        raise BrokerConnectionError(
            failure_reason(failure), connect_failure_message(settings, failure), url=settings.url
        )
    client.on_connect = None
    if answers[0].is_failure:
        client.disconnect()
        if protocol == mqtt.MQTTv5 and answers[0].value == UNSUPPORTED_PROTOCOL_VERSION:
            raise BrokerConnectionError("old-protocol", "MQTT 5 is not offered", url=settings.url)
        raise BrokerConnectionError(
            "login-refused", connect_failure_message(settings, answers[0]), url=settings.url
        )
    client.loop_start()
    return client


def probe_login(
    settings: BrokerSettings, *, client_id: str, timeout_s: float, poll_s: float = PROBE_POLL_S
) -> bool | None:
    """Try one MQTT 3.1.1 login and leave: True if accepted, False if refused, None if
    nobody answered within ``timeout_s`` (the broker is not listening yet, or not ready)."""
    client = new_client(settings, client_id=client_id)
    try:
        answers = _send_login(client, settings, keepalive_s=PROBE_KEEPALIVE_S)
    except OSError:
        return None
    _await_connack(client, answers, timeout_s=timeout_s, poll_s=poll_s)
    # Without a network thread paho writes the DISCONNECT and closes the socket right here.
    client.disconnect()
    return not answers[0].is_failure if answers else None


def _send_login(
    client: mqtt.Client, settings: BrokerSettings, *, keepalive_s: int
) -> list[ReasonCode]:
    """Open the connection and send the CONNECT; the list ``on_connect`` puts the CONNACK in."""
    answers: list[ReasonCode] = []

    def on_connect(
        _client: mqtt.Client, _userdata: Any, _flags: Any, code: ReasonCode, _props: Any
    ) -> None:
        answers.append(code)

    client.on_connect = on_connect
    client.connect(settings.host, settings.port, keepalive=keepalive_s)
    return answers


def _await_connack(
    client: mqtt.Client, answers: list[ReasonCode], *, timeout_s: float, poll_s: float
) -> OSError | None:
    """Drive ``client`` by hand until ``on_connect`` has put the CONNACK in ``answers``.

    By hand, not on a network thread: that would retry a refused login. None once the
    CONNACK is in; else why not: TimeoutError, or ConnectionResetError if the connection
    closed first.
    """
    import paho.mqtt.client as mqtt

    deadline_s = time.monotonic() + timeout_s
    while not answers:
        remaining_s = deadline_s - time.monotonic()
        if remaining_s <= 0:
            return TimeoutError()
        if client.loop(timeout=min(remaining_s, poll_s)) != mqtt.MQTT_ERR_SUCCESS and not answers:
            return ConnectionResetError()
    return None
