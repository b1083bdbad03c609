"""``feelmysign sleeve --wearer-page [PORT]``: the wearer's page served by the sleeve itself.

On the Pi there is no ``feelmysign up``: the sleeve process serves the same page and API
(``feelmysign.wearer_api``) at ``/wearer``, calling its controls in-process, so the wearer
can pause even when the broker is down. Off loopback it is HTTPS with a certificate from
the same local CA machinery as ``up --lan`` (``feelmysign.broker.tls``), kept with the
wearer's key in ``$XDG_STATE_HOME/feelmysign/wearer-page``. Blocking senders needs the
broker feelmysign runs: when this sleeve reaches the broker kept in this machine's usual
state directory (a second sleeve beside ``up``, joined with ``broker add-sleeve``), the page
blocks there; otherwise (the Pi, whose broker runs elsewhere) the page says so.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from feelmysign.broker._config import StateFiles
from feelmysign.broker.credentials import load_credentials
from feelmysign.broker.mosquitto import default_state_dir
from feelmysign.broker.tls import LanOptions
from feelmysign.cli._page_server import qr_text
from feelmysign.cli.options.lan import default_route_address
from feelmysign.connection import BrokerSettings
from feelmysign.connection.settings import parse_broker_url
from feelmysign.daemon import Sleeve
from feelmysign.errors import BrokerError, FeelMySignError
from feelmysign.layout import Layout
from feelmysign.state_home import state_path
from feelmysign.wearer_api import Blocking, WearerApi, wearer_key
from feelmysign.webserver import LOOPBACK_HOSTS, WEB_DIST, WebServer


def state_dir() -> Path:
    return Path(state_path("wearer-page"))


LOOPBACK_NAMES = frozenset({"127.0.0.1", "localhost", "::1"})


def local_broker(settings: BrokerSettings) -> Blocking | None:
    """The broker feelmysign runs from this machine's usual state directory (as ``up`` and
    ``feelmysign broker`` keep it), when the sleeve's ``settings`` reach that broker; else
    None. Read at each call: the broker may start after the sleeve, or restart."""
    files = StateFiles(default_state_dir())
    try:
        credentials = load_credentials(files.credentials)
    except (FeelMySignError, OSError):
        return None  # no broker kept here (the Pi), or a file being rewritten
    urls = [credentials.mqtt_url, credentials.mqtts_url, credentials.ws_url]
    served = {_endpoint(parse_broker_url(url)) for url in urls if url}
    return Blocking(files, credentials) if _endpoint(settings) in served else None


def _endpoint(settings: BrokerSettings) -> tuple[str, int]:
    host = "127.0.0.1" if settings.host in LOOPBACK_NAMES else settings.host
    return host, settings.port


def wearer_page_server(
    args: argparse.Namespace,
    sleeve_id: str,
    layout: Layout,
    running: list[Sleeve],
    settings: BrokerSettings | None = None,
) -> tuple[WebServer, str] | None:
    """The server (not yet started) and what to print (the wearer's URL with the key, and a
    QR code off loopback), or None without --wearer-page.

    ``running`` holds the sleeve once it has started: until then the page says it starts.
    """
    if args.wearer_page is None:
        return None
    try:
        host = args.wearer_host or default_route_address()
    except BrokerError:
        raise FeelMySignError(
            "--wearer-page: this machine has no network route, so its LAN address is unknown: "
            "connect it to the network, or give the address with --wearer-host ADDRESS "
            "(127.0.0.1 for this machine only)."
        ) from None
    directory = state_dir()
    directory.mkdir(mode=0o700, parents=True, exist_ok=True)
    # Off loopback: TLS, with the local CA's certificate for this address (as up --lan).
    tls = None if host in LOOPBACK_HOSTS else LanOptions(host=host).tls_files(directory / "tls")
    key = wearer_key(directory)
    api = WearerApi(
        sleeve_id=sleeve_id,
        max_intensity=layout.max_intensity,
        controls=lambda: running[0].controls if running else None,
        online=lambda: bool(running) and running[0].connected.is_set(),
        blocking=None if settings is None else lambda: local_broker(settings),
    )
    server = WebServer(
        port=args.wearer_page,
        config={},  # no broker login here: only the wearer's page is meant to be used
        directory=WEB_DIST,
        host=host,
        tls=tls,
        wearer_api=api,
        wearer_key=key,
        debug_log=directory / "page-server.log",
    )
    url = f"{server.url}wearer?key={key}"
    accept = (
        "" if tls is None else f"; accept the certificate once{_fingerprint(tls.ca_fingerprint)}"
    )
    code = "" if tls is None else qr_text(url)
    return server, (
        "For the wearer's phone (pause, stop, a ceiling, do not disturb; keep this key from "
        f"senders{accept}):\n"
        f"  {url}\n{code}"
    )


def _fingerprint(ca_fingerprint: str | None) -> str:
    return f" (CA SHA-256 {ca_fingerprint[:16]}...)" if ca_fingerprint else ""
