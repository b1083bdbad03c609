"""Serve the built drawing client and the ``/config.json`` that tells it where the broker is.

Loopback only: the page gets the sender's broker password from ``/config.json``,
which must not leave this machine.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

from feelmysign.errors import FeelMySignError

WEB_DIST = Path(__file__).resolve().parents[3] / "web" / "dist"
# An API mounted under /api/ (the study's): (method, path, host, body, content type) ->
# (status, content type, body). It answers every error itself.
Api = Callable[[str, str, str, bytes, str], tuple[int, str, bytes]]
MAX_API_BODY_BYTES = 64 * 1024


class _Handler(SimpleHTTPRequestHandler):
    config: bytes = b"{}"
    api: Api | None = None

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
        if not self._api("POST"):
            self.send_error(404)

    def do_GET(self) -> None:
        if self._api("GET"):
            return
        if self.path.split("?")[0] in ("/study", "/study/"):
            self.path = "/study.html"  # the researcher's page of the recognition study
        if self.path.split("?")[0] == "/config.json":
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.send_header("Cache-Control", "no-store")
            self.send_header("Content-Length", str(len(self.config)))
            self.end_headers()
            self.wfile.write(self.config)
            return
        super().do_GET()

    def end_headers(self) -> None:
        if not self.path.startswith("/assets/"):
            self.send_header("Cache-Control", "no-cache")  # a rebuilt client is seen at once
        super().end_headers()

    def log_message(self, format: str, *args: Any) -> None:
        pass  # quiet: the terminal belongs to the sleeve's log


class WebServer:
    """``with WebServer(port=8000, config={...}) as server: server.url``."""

    def __init__(
        self,
        *,
        port: int,
        config: dict[str, Any],
        directory: Path = WEB_DIST,
        api: Api | None = None,
    ) -> None:
        index = directory / "index.html"
        if not index.is_file():
            raise FeelMySignError(
                f"the drawing client is not built ({index} is missing); run 'make web-build' "
                "(or 'make up', which builds it)"
            )
        handler = type(
            "ConfigHandler",
            (_Handler,),
            {"config": json.dumps(config).encode(), "api": staticmethod(api) if api else None},
        )
        try:
            self._server = ThreadingHTTPServer(
                ("127.0.0.1", port), partial(handler, directory=str(directory))
            )
        except OSError as error:
            raise FeelMySignError(
                f"cannot serve the drawing client on 127.0.0.1:{port}: {error.strerror}; "
                "choose another port with --http-port"
            ) from error
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True)

    @property
    def url(self) -> str:
        host, port = self._server.server_address[:2]
        return f"http://{host!s}:{port}/"

    def __enter__(self) -> WebServer:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._server.shutdown()
        self._server.server_close()
