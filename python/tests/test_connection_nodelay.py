"""Every client of ``new_client`` sends each packet at once (TCP_NODELAY), over TCP and
under a WebSocket: with Nagle's algorithm a sleeve's event written just after a PUBACK
waited for the broker's delayed acknowledgement."""

from __future__ import annotations

import socket
from dataclasses import replace

import paho.mqtt.client as mqtt
import pytest
from paho.mqtt.enums import CallbackAPIVersion
from sleeve_watch import connected_client

from feelmysign.broker import Credentials
from feelmysign.connection import BrokerSettings
from feelmysign.connection.client import send_at_once


def _no_delay(client: mqtt.Client) -> int:
    sock = client.socket()
    tcp = getattr(sock, "_socket", sock)  # under a WebSocket, paho's wrapper holds it
    assert isinstance(tcp, socket.socket), type(tcp)
    return tcp.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY)


@pytest.mark.parametrize("transport", ["tcp", "websockets"])
def test_the_connection_sends_each_packet_at_once(
    broker_credentials: Credentials, transport: str
) -> None:
    settings: BrokerSettings = broker_credentials.settings("sender")
    if transport == "websockets":
        settings = replace(
            settings, transport="websockets", port=broker_credentials.ws_port, path="/mqtt"
        )
    client = connected_client(settings)
    try:
        assert _no_delay(client) != 0
    finally:
        client.disconnect()
        client.loop_stop()


def test_a_socket_without_tcp_options_is_left_as_it_is() -> None:
    left, right = socket.socketpair()  # a Unix socket: no TCP_NODELAY to set
    try:
        send_at_once(mqtt.Client(CallbackAPIVersion.VERSION2), None, left)
        left.sendall(b"x")
        assert right.recv(1) == b"x"
    finally:
        left.close()
        right.close()
