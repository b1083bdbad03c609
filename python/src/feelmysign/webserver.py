"""Serve the built drawing client and the ``/config.json`` that tells it where the broker is.

On loopback by default: the page gets the sender's broker password from
``/config.json``. Off loopback (``feelmysign up --lan``) everything is HTTPS, the
broker is reached through ``/mqtt`` on the same origin (``web_proxy``), and
``/config.json`` and ``/mqtt`` need the access key of the printed URL: opening
``/?key=KEY`` once leaves it in a cookie only this origin sees over HTTPS.

``/config.json`` is also served only to requests whose ``Host`` header names this
server: a loopback name (``127.0.0.1``, ``localhost``, ``[::1]``), the address it
listens on, or one of ``hosts``, with its port; any other Host gets ``403
Forbidden`` with the reason. Else a web page from anywhere could point its own
host name at this machine (DNS rebinding) and read the password as its own.
"""

from __future__ import annotations

import hmac
import json
import ssl
import threading
from collections.abc import Callable, Iterable
from functools import partial
from http.cookies import SimpleCookie
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs

from feelmysign.broker.tls import TlsFiles
from feelmysign.errors import FeelMySignError
from feelmysign.web_proxy import is_websocket_upgrade, relay_websocket

WEB_DIST = Path(__file__).resolve().parents[3] / "web" / "dist"
# An API mounted under /api/ (the study's): (method, path, host, body, content type) ->
# (status, content type, body). It answers every error itself.
Api = Callable[[str, str, str, bytes, str], tuple[int, str, bytes]]
MAX_API_BODY_BYTES = 64 * 1024
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "[::1]")


def host_header_names(hosts: Iterable[str], port: int) -> frozenset[str]:
    """The ``Host`` values a browser sends for ``hosts`` on ``port`` (lower case).

    An IPv6 address is written in brackets; port 80 may be left out, as browsers do.
    """
    names = set()
    for host in hosts:
        host = host.strip().lower()
        if ":" in host and not host.startswith("["):
            host = f"[{host}]"
        names.add(f"{host}:{port}")
        if port == 80:
            names.add(host)
    return frozenset(names)


KEY_COOKIE = "feelmysign_key"


class _Handler(SimpleHTTPRequestHandler):
    config: bytes = b"{}"
    allowed_hosts: frozenset[str] = frozenset()
    api: Api | None = None
    access_key: str | None = None
    mqtt_ws_port: int | None = None

    def _api(self, method: str) -> bool:
        path = self.path.split("?")[0]
        if self.api is None or not path.startswith("/api/"):
            return False
        length = min(int(self.headers.get("Content-Length") or 0), MAX_API_BODY_BYTES + 1)
        body = self.rfile.read(length) if length > 0 else b""
        status, kind, payload = self.api(
            method, path, self.headers.get("Host", ""), body, self.headers.get("Content-Type", "")
        )
        self.send_response(status)
        self.send_header("Content-Type", kind)
        self.send_header("Cache-Control", "no-store")
        self.send_header("Content-Length", str(len(payload)))
        self.end_headers()
        self.wfile.write(payload)
        return True

    def do_POST(self) -> None:
        path, _, query = self.path.partition("?")
        if self.access_key is not None and not self._key_checked(path, query):
            return
        if not self._api("POST"):
            self.send_error(404)

    def do_GET(self) -> None:
        path, _, query = self.path.partition("?")
        if self.access_key is not None and not self._key_checked(path, query):
            return
        if self._api("GET"):
            return
        if path in ("/study", "/study/"):
            self.path = "/study.html"  # the researcher's page of the recognition study
        if path == "/mqtt" and self.mqtt_ws_port is not None and is_websocket_upgrade(self):
            relay_websocket(self, self.mqtt_ws_port)
            return
        if path == "/config.json":
            if not self._host_allowed():
                return
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.send_header("Cache-Control", "no-store")
            self.send_header("Content-Length", str(len(self.config)))
            self.end_headers()
            self.wfile.write(self.config)
            return
        super().do_GET()

    def _key_checked(self, path: str, query: str) -> bool:
        """True to go on; else the answer (a cookie and a redirect, or 403) is sent."""
        assert self.access_key is not None
        offered = parse_qs(query).get("key", [None])[0]
        if offered is not None and hmac.compare_digest(offered, self.access_key):
            self.send_response(303)
            self.send_header(
                "Set-Cookie",
                f"{KEY_COOKIE}={self.access_key}; Secure; HttpOnly; SameSite=Strict; Path=/",
            )
            self.send_header("Location", path or "/")
            self.send_header("Content-Length", "0")
            self.end_headers()
            return False
        if path not in ("/config.json", "/mqtt") and not path.startswith("/api/"):
            return True  # the page itself is public; the broker, its password, the API are not
        cookie = SimpleCookie(self.headers.get("Cookie", ""))
        held = cookie[KEY_COOKIE].value if KEY_COOKIE in cookie else ""
        if hmac.compare_digest(held, self.access_key):
            return True
        self.send_error(403, "Open the URL that 'feelmysign up' printed (it holds the key)")
        return False

    def _host_allowed(self) -> bool:
        """Whether the request names this server; else answer 403 saying why."""
        host = (self.headers.get("Host") or "").strip().lower()
        if host in self.allowed_hosts:
            return True
        body = (
            f"Forbidden: /config.json holds the broker login and is served only to pages "
            f"opened from this server ({', '.join(sorted(self.allowed_hosts))}), not to "
            f"Host {host[:80]!r}. Open the drawing client at one of those addresses.\n"
        ).encode()
        self.send_response(403)
        self.send_header("Content-Type", "text/plain; charset=utf-8")
        self.send_header("Cache-Control", "no-store")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)
        return False

    def end_headers(self) -> None:
        if not self.path.startswith("/assets/"):
            self.send_header("Cache-Control", "no-cache")  # a rebuilt client is seen at once
        super().end_headers()

    def log_message(self, format: str, *args: Any) -> None:
        pass  # quiet: the terminal belongs to the sleeve's log


class WebServer:
    """``with WebServer(port=8000, config={...}) as server: server.url``.

    ``hosts``: names besides the loopback ones under which pages may read
    ``/config.json`` (e.g. the machine's LAN address, when serving there).
    """

    def __init__(
        self,
        *,
        port: int,
        config: dict[str, Any],
        directory: Path = WEB_DIST,
        api: Api | None = None,
        host: str = "127.0.0.1",
        tls: TlsFiles | None = None,
        access_key: str | None = None,
        mqtt_ws_port: int | None = None,
        hosts: Iterable[str] = (),
    ) -> None:
        self._hosts = (*LOOPBACK_HOSTS, host, *hosts)
        index = directory / "index.html"
        if not index.is_file():
            raise FeelMySignError(
                f"the drawing client is not built ({index} is missing); run 'make web-build' "
                "(or 'make up', which builds it)"
            )
        attributes: dict[str, object] = {
            "config": json.dumps(config).encode(),
            "api": staticmethod(api) if api else None,
            "access_key": access_key,
            "mqtt_ws_port": mqtt_ws_port,
            "allowed_hosts": frozenset(),
        }
        handler: type[_Handler] = type("ConfigHandler", (_Handler,), attributes)
        self._handler = handler
        try:
            self._server = ThreadingHTTPServer(
                (host, port), partial(handler, directory=str(directory))
            )
        except OSError as error:
            raise FeelMySignError(
                f"cannot serve the drawing client on {host}:{port}: {error.strerror}; "
                "choose another port with --http-port"
            ) from error
        self._tls = tls is not None
        if tls is not None:
            context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
            context.minimum_version = ssl.TLSVersion.TLSv1_2
            context.load_cert_chain(tls.cert, tls.key)
            # The handshake happens in the request's thread, not in accept(): a slow or
            # silent client cannot hold up everyone else.
            self._server.socket = context.wrap_socket(
                self._server.socket, server_side=True, do_handshake_on_connect=False
            )
        # Known once bound (port 0 picks one): only now can the Host values be listed.
        handler.allowed_hosts = host_header_names(self._hosts, self._server.server_address[1])
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True)

    def set_config(self, config: dict[str, Any]) -> None:
        """Serve ``config`` as /config.json from now on (e.g. once the port is known)."""
        self._handler.config = json.dumps(config).encode()

    @property
    def authority(self) -> str:
        """``host:port`` as a URL holds it."""
        address, port = self._server.server_address[:2]
        host = address.decode() if isinstance(address, bytes) else address
        return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"

    @property
    def url(self) -> str:
        return f"{'https' if self._tls else 'http'}://{self.authority}/"

    def __enter__(self) -> WebServer:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._server.shutdown()
        self._server.server_close()
