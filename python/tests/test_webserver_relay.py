"""The page server's ``/mqtt`` relay to the broker's WebSocket listener, with a real broker:
MQTT both ways through it with the access key's cookie, the broker's subprotocol passed on,
and what it answers without the key, to a request that is not a WebSocket handshake, and
when the broker's listener is gone."""

from __future__ import annotations

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
from feelmysign.webserver import KEY_COOKIE, WebServer

KEY = "relay-test-key"


@pytest.fixture
def site(tmp_path: Path) -> Path:
    (tmp_path / "index.html").write_text("<!doctype html><title>feelmysign</title>")
    return tmp_path


def _port(server: WebServer) -> int:
    return int(server.url.rstrip("/").rsplit(":", 1)[1])


def _websocket_client(broker: Broker, port: int, role: str) -> tuple[mqtt.Client, list[bytes]]:
    c = broker.credentials
    login = c.sender if role == "sender" else c.sleeve
    client = mqtt.Client(
        CallbackAPIVersion.VERSION2, client_id=f"relay-{uuid.uuid4()}", transport="websockets"
    )
    client.ws_set_options(path="/mqtt", headers={"Cookie": f"{KEY_COOKIE}={KEY}"})
    client.username_pw_set(login.username, login.password)
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


def test_mqtt_goes_both_ways_through_the_relay(broker: Broker, site: Path) -> None:
    c = broker.credentials
    with WebServer(
        port=0, config={}, directory=site, access_key=KEY, mqtt_ws_port=c.ws_port
    ) as server:
        receiver, received = _websocket_client(broker, _port(server), "sleeve")
        sender, _ = _websocket_client(broker, _port(server), "sender")
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
