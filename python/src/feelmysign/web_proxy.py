"""MQTT over WebSockets from the page's own origin: ``/mqtt`` relayed to the broker's listener.

Off loopback the page is served over HTTPS with the local CA's certificate. A phone
that accepts that certificate once for the page would have to accept it again for a
broker on another port; relaying ``wss://HOST:PORT/mqtt`` to Mosquitto's WebSocket
listener on 127.0.0.1 keeps a single origin, so one acceptance covers both, and the
broker's WebSocket listener never leaves loopback.

The relay forwards the client's upgrade request as it came and then copies bytes both
ways until either side closes: the WebSocket handshake and frames are Mosquitto's.
"""

from __future__ import annotations

import select
import socket
import ssl
from http.server import BaseHTTPRequestHandler

CONNECT_TIMEOUT_S = 5.0
CHUNK_BYTES = 65536
# Hop-by-hop headers a relay must not pass on, except the two a WebSocket upgrade needs.
_DROPPED_HEADERS = {"keep-alive", "proxy-connection", "te", "trailer", "transfer-encoding"}


def is_websocket_upgrade(handler: BaseHTTPRequestHandler) -> bool:
    return handler.headers.get("Upgrade", "").lower() == "websocket"


def relay_websocket(handler: BaseHTTPRequestHandler, port: int) -> None:
    """Relay this upgrade request to the broker's WebSocket listener on 127.0.0.1:``port``."""
    handler.close_connection = True
    try:
        upstream = socket.create_connection(("127.0.0.1", port), timeout=CONNECT_TIMEOUT_S)
    except OSError:
        handler.send_error(502, "The broker's WebSocket listener does not answer")
        return
    with upstream:
        upstream.settimeout(None)
        upstream.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        upstream.sendall(_request_bytes(handler))
        client = handler.connection
        client.settimeout(None)
        _copy_both_ways(client, upstream)


def _request_bytes(handler: BaseHTTPRequestHandler) -> bytes:
    lines = [f"{handler.command} {handler.path} HTTP/1.1"]
    lines += [
        f"{name}: {value}"
        for name, value in handler.headers.items()
        if name.lower() not in _DROPPED_HEADERS
    ]
    return ("\r\n".join(lines) + "\r\n\r\n").encode("latin-1")


def _copy_both_ways(client: socket.socket, upstream: socket.socket) -> None:
    """One thread, both directions: an SSL socket must not be read and written concurrently."""
    while True:
        # Bytes OpenSSL already decrypted are invisible to select(): take them first.
        pending = isinstance(client, ssl.SSLSocket) and client.pending() > 0
        readable = [client] if pending else select.select([client, upstream], [], [])[0]
        for source in readable:
            target = upstream if source is client else client
            try:
                data = source.recv(CHUNK_BYTES)
                if not data:
                    return
                target.sendall(data)
            except OSError:
                return
