"""The page's server for ``feelmysign up``: on loopback as before, or on the LAN with TLS.

On the LAN the page and its broker share one origin (``https://HOST:PORT``, MQTT at
``/mqtt``), so a phone accepts the local CA's certificate once. The printed URL holds
an access key; the QR code carries the same URL for a phone's camera.
"""

from __future__ import annotations

import io
import secrets
import socket
from pathlib import Path
from typing import Any

import segno

from feelmysign.broker import Broker
from feelmysign.broker.sleeves import load_sleeves
from feelmysign.wearer_api import wearer_key
from feelmysign.webserver import Api, WebServer

ACCESS_KEY_BYTES = 16  # 128 bits: not guessable from the LAN


def page_server(
    broker: Broker,
    *,
    http_port: int,
    directory: Path,
    api: Api | None = None,
    wearer_api: Api | None = None,
    sock: socket.socket | None = None,
) -> tuple[WebServer, str, str | None]:
    """The server (not yet started), the URL to open, with its key when off loopback, and
    with ``wearer_api`` the wearer's URL (always with the wearer's key, kept in the state
    directory so that the wearer's bookmark outlives a restart). ``sock``: the page's
    socket, bound beforehand (``webserver.listen``) on ``http_port``."""
    w_key = wearer_key(broker.state_dir) if wearer_api is not None else None
    c = broker.credentials
    config: dict[str, Any] = {
        "ws_url": c.ws_url,
        "sleeve_id": c.sleeve_id,
        "sleeves": [c.sleeve_id, *sorted(load_sleeves(broker.files.sleeves))],
        "username": c.sender.username,
        "password": c.sender.password,
    }
    # What peers did wrong (bad requests, refused certificates), in detail: never the terminal.
    debug_log = broker.state_dir / "page-server.log"
    if broker.lan is None:
        server = WebServer(
            port=http_port,
            config=config,
            directory=directory,
            api=api,
            debug_log=debug_log,
            wearer_api=wearer_api,
            wearer_key=w_key,
            sock=sock,
        )
        return server, server.url, _wearer_url(server, w_key)
    key = secrets.token_urlsafe(ACCESS_KEY_BYTES)
    server = WebServer(
        port=http_port,
        config=config,
        directory=directory,
        api=api,
        host=broker.lan.host,
        tls=broker.tls,
        access_key=key,
        mqtt_ws_port=c.ws_port,
        debug_log=debug_log,
        wearer_api=wearer_api,
        wearer_key=w_key,
        sock=sock,
    )
    server.set_config({**config, "ws_url": f"wss://{server.authority}/mqtt"})
    return server, f"{server.url}?key={key}", _wearer_url(server, w_key)


def _wearer_url(server: WebServer, key: str | None) -> str | None:
    return f"{server.url}wearer?key={key}" if key is not None else None


def qr_text(url: str) -> str:
    """``url`` as a QR code in terminal characters (two rows of modules per line)."""
    out = io.StringIO()
    segno.make(url, error="m").terminal(out=out, compact=True, border=2)
    return out.getvalue()
