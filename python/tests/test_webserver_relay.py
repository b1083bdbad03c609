"""The page server's ``/mqtt`` relay to the broker's WebSocket listener, with a real broker:
MQTT both ways through it with the access key's cookie, the broker's subprotocol passed on,
and what it answers without the key, to a request that is not a WebSocket handshake, and
when the broker's listener is gone."""

from __future__ import annotations

import asyncio
import base64
import os
import socket
import threading
import uuid
from pathlib import Path

import paho.mqtt.client as mqtt
import pytest
from paho.mqtt.enums import CallbackAPIVersion

from feelmysign.broker import Broker
from feelmysign.broker.tls import TlsFiles, ensure_local_ca
from feelmysign.webserver import KEY_COOKIE, WebServer

KEY = "relay-test-key"


@pytest.fixture
def site(tmp_path: Path) -> Path:
    (tmp_path / "index.html").write_text("<!doctype html><title>feelmysign</title>")
    return tmp_path


def _port(server: WebServer) -> int:
    return int(server.url.rstrip("/").rsplit(":", 1)[1])


def _websocket_client(
    broker: Broker, port: int, role: str, tls: TlsFiles | None = None
) -> tuple[mqtt.Client, list[bytes]]:
    c = broker.credentials
    login = c.sender if role == "sender" else c.sleeve
    client = mqtt.Client(
        CallbackAPIVersion.VERSION2, client_id=f"relay-{uuid.uuid4()}", transport="websockets"
    )
    client.ws_set_options(path="/mqtt", headers={"Cookie": f"{KEY_COOKIE}={KEY}"})
    client.username_pw_set(login.username, login.password)
    if tls is not None:
        client.tls_set(ca_certs=str(tls.ca))
    received: list[bytes] = []
    got = threading.Condition()
    connected, subscribed = threading.Event(), threading.Event()

    def on_message(*args: object) -> None:
        message = args[2]
        with got:
            received.append(bytes(message.payload))  # type: ignore[attr-defined]
            got.notify_all()

    client.on_connect = lambda *a: connected.set()
    client.on_subscribe = lambda *a: subscribed.set()
    client.on_message = on_message
    client.connect("127.0.0.1", port)
    client.loop_start()
    assert connected.wait(10), "no CONNACK through the relay"
    if role == "sleeve":
        client.subscribe(f"feelmysign/{c.sleeve_id}/strokes", qos=1)
        assert subscribed.wait(10), "no SUBACK through the relay"
    return client, received


@pytest.mark.parametrize("scheme", ["ws", "wss"])
def test_mqtt_goes_both_ways_through_the_relay(
    broker: Broker, site: Path, tmp_path: Path, scheme: str
) -> None:
    """Plain, and over TLS as a phone on the LAN reaches it (``feelmysign up --lan``)."""
    c = broker.credentials
    tls = ensure_local_ca(tmp_path / "tls", ["127.0.0.1"]) if scheme == "wss" else None
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=c.ws_port, tls=tls
    ) as server:
        receiver, received = _websocket_client(broker, _port(server), "sleeve", tls)
        sender, _ = _websocket_client(broker, _port(server), "sender", tls)
        try:
            payloads = [os.urandom(n) for n in (1, 125, 126, 3000)]  # each frame length form
            for payload in payloads:
                sender.publish(
                    f"feelmysign/{c.sleeve_id}/strokes", payload, qos=1
                ).wait_for_publish(10)
            deadline = threading.Event()
            for _ in range(100):
                if len(received) >= len(payloads):
                    break
                deadline.wait(0.1)
            assert received == payloads
        finally:
            for client in (sender, receiver):
                client.disconnect()
                client.loop_stop()


def _upgrade(port: int, cookie: str, headers: str = "") -> bytes:
    key = base64.b64encode(os.urandom(16)).decode()
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.sendall(
            (
                f"GET /mqtt HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
                f"Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\n{headers}"
                f"{f'Sec-WebSocket-Key: {key}' if 'Key' not in headers else 'X-A: b'}\r\n"
                f"Cookie: {cookie}\r\n\r\n"
            ).encode()
        )
        answer = b""
        while b"\r\n\r\n" not in answer:
            chunk = sock.recv(4096)
            if not chunk:
                break
            answer += chunk
        return answer


def test_the_broker_s_subprotocol_is_the_page_s(broker: Broker, site: Path) -> None:
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=broker.credentials.ws_port
    ) as server:
        answer = _upgrade(_port(server), f"{KEY_COOKIE}={KEY}", "Sec-WebSocket-Protocol: mqtt\r\n")
    head = answer.decode("latin-1").lower()
    assert head.startswith("http/1.1 101")
    assert "sec-websocket-protocol: mqtt\r\n" in head
    assert "sec-websocket-extensions" not in head  # no compression


def test_without_the_key_the_relay_answers_403(broker: Broker, site: Path) -> None:
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=broker.credentials.ws_port
    ) as server:
        assert _upgrade(_port(server), f"{KEY_COOKIE}=wrong").startswith(b"HTTP/1.1 403")


def test_a_handshake_without_its_key_gets_400(broker: Broker, site: Path) -> None:
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=broker.credentials.ws_port
    ) as server:
        answer = _upgrade(_port(server), f"{KEY_COOKIE}={KEY}", "Sec-WebSocket-Key: short\r\n")
    assert answer.startswith(b"HTTP/1.1 400")


def test_a_broker_listener_that_is_gone_gets_502(site: Path) -> None:
    with socket.socket() as free:
        free.bind(("127.0.0.1", 0))
        gone_port = free.getsockname()[1]
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=gone_port
    ) as server:
        assert _upgrade(_port(server), f"{KEY_COOKIE}={KEY}").startswith(b"HTTP/1.1 502")


def _relay_sockets(server: WebServer, broker_port: int) -> tuple[socket.socket, socket.socket]:
    """This process's two sockets of the one relayed connection (duplicates, to be closed):
    the page's (on the server's port) and the relay's to the broker's WebSocket listener."""
    page = upstream = None
    for fd in os.listdir("/proc/self/fd"):
        try:
            sock = socket.socket(fileno=os.dup(int(fd)))
        except OSError:
            continue
        try:
            local, peer = sock.getsockname(), sock.getpeername()
        except (OSError, TypeError):
            sock.close()
            continue
        if sock.family == socket.AF_INET and local[1] == _port(server):
            page = sock
        elif sock.family == socket.AF_INET and peer[1] == broker_port:
            upstream = sock
        else:
            sock.close()
    assert page is not None and upstream is not None, "the relay's sockets are not found"
    return page, upstream


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="lists sockets in /proc")
def test_the_relay_sends_each_packet_at_once_both_ways(broker: Broker, site: Path) -> None:
    """TCP_NODELAY on both sockets the relay writes to: a PUBACK or a stroke is not held
    back by Nagle's algorithm until the previous one's ACK comes."""
    c = broker.credentials
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=c.ws_port
    ) as server:
        client, _ = _websocket_client(broker, _port(server), "sender")
        try:
            page, upstream = _relay_sockets(server, c.ws_port)
            with page, upstream:
                for sock in (page, upstream):
                    assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY), sock
        finally:
            client.disconnect()
            client.loop_stop()


def test_a_page_that_does_not_read_holds_the_broker_s_bytes_back(
    broker: Broker, site: Path
) -> None:
    """A page that stops reading while the broker sends it megabytes: the relay stops
    reading from the broker rather than keep them in the page server's memory (the broker
    holds them, or drops what its own limits drop), and reads again once the page does."""
    c = broker.credentials
    count, size = 4000, 4000  # 16 MB, past what the kernel's socket buffers hold on loopback
    topic = f"feelmysign/{c.sleeve_id}/strokes"
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=c.ws_port
    ) as server:

        def relay_state() -> tuple[int, bool]:
            """(bytes held for the page, whether the relay reads from the broker)"""

            async def state() -> tuple[int, bool]:
                connection = next(k for k in server._connections.values() if k.active)
                assert connection.transport is not None
                transport = connection.transport
                upstream = transport.get_protocol()._upstream  # type: ignore[attr-defined]
                return transport.get_write_buffer_size(), upstream.is_reading()  # type: ignore[attr-defined]

            return asyncio.run_coroutine_threadsafe(state(), server._loop).result(10)

        page = mqtt.Client(
            CallbackAPIVersion.VERSION2, client_id=f"relay-{uuid.uuid4()}", transport="websockets"
        )
        page.ws_set_options(path="/mqtt", headers={"Cookie": f"{KEY_COOKIE}={KEY}"})
        page.username_pw_set(c.sleeve.username, c.sleeve.password)
        received: list[int] = []
        page.on_message = lambda *args: received.append(len(args[2].payload))
        subscribed = threading.Event()
        page.on_subscribe = lambda *a: subscribed.set()
        page.connect("127.0.0.1", _port(server))
        page.subscribe(topic, qos=1)
        for _ in range(100):  # the page's loop by hand: it reads only when told to
            page.loop(0.1)
            if subscribed.is_set():
                break
        assert subscribed.is_set(), "no SUBACK through the relay"
        sender = mqtt.Client(CallbackAPIVersion.VERSION2, client_id=f"relay-{uuid.uuid4()}")
        sender.username_pw_set(c.sender.username, c.sender.password)
        sender.connect("127.0.0.1", c.mqtt_port)
        sender.loop_start()
        try:
            for _ in range(count):
                sender.publish(topic, b"x" * size, qos=1)
            sender.publish(topic, b"x" * size, qos=1).wait_for_publish(30)
            held, reading = 0, True
            for _ in range(300):  # until the relay stops reading from the broker
                held, reading = relay_state()
                if not reading:
                    break
                threading.Event().wait(0.1)
            assert not reading, f"the relay still reads from the broker, holding {held} bytes"
            assert held < 1024 * 1024, f"the relay holds {held} bytes for a page that does not read"
            for _ in range(100 * count):  # the page reads: the relay reads again
                page.loop(0.1)
                if received and relay_state() == (0, True):
                    break
            assert relay_state() == (0, True)
            assert received and set(received) == {size}
        finally:
            sender.disconnect()
            sender.loop_stop()
            page.disconnect()
