"""The page's server for ``feelmysign up``: on loopback as before, or on the LAN with TLS.

On the LAN the page and its broker share one origin (``https://HOST:PORT``, MQTT at
``/mqtt``), so a phone accepts the local CA's certificate once. The printed URL holds
an access key; the QR code carries the same URL for a phone's camera.
"""

from __future__ import annotations

import io
import secrets
from pathlib import Path
from typing import Any

import segno

from feelmysign.broker import Broker
from feelmysign.broker.sleeves import load_sleeves
from feelmysign.webserver import Api, WebServer

ACCESS_KEY_BYTES = 16  # 128 bits: not guessable from the LAN


def page_server(
    broker: Broker, *, http_port: int, directory: Path, api: Api | None = None
) -> tuple[WebServer, str]:
    """The server (not yet started) and the URL to open, with its key when off loopback."""
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
            port=http_port, config=config, directory=directory, api=api, debug_log=debug_log
        )
        return server, server.url
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
    )
    server.set_config({**config, "ws_url": f"wss://{server.authority}/mqtt"})
    return server, f"{server.url}?key={key}"


def qr_text(url: str) -> str:
    """``url`` as a QR code in terminal characters (two rows of modules per line)."""
    out = io.StringIO()
    segno.make(url, error="m").terminal(out=out, compact=True, border=2)
    return out.getvalue()
