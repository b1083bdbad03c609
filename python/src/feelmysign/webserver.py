"""Serve the built drawing client and the ``/config.json`` that tells it where the broker is.

On loopback by default: the page gets the sender's broker password from
``/config.json``. Off loopback (``feelmysign up --lan``) everything is HTTPS, the
broker is reached through ``/mqtt`` on the same origin (the relay below), and
``/config.json`` and ``/mqtt`` need the access key of the printed URL: opening
``/?key=KEY`` once leaves it in a cookie only this origin sees over HTTPS.

``/config.json`` is also served only to requests whose ``Host`` header names this
server: a loopback name (``127.0.0.1``, ``localhost``, ``[::1]``), the address it
listens on, or one of ``hosts``, with its port; any other Host gets ``403
Forbidden`` with the reason. Else a web page from anywhere could point its own
host name at this machine (DNS rebinding) and read the password as its own.

The server is aiohttp's (HTTP parsing with size limits, TLS, the WebSocket handshake
for the relay), on one asyncio loop in one thread: an idle or hostile connection costs a few
kilobytes, never a thread. What a network peer sends (a malformed or oversized
request, TLS garbage, a cut handshake, a device that does not trust the certificate
yet, a disconnect at any point) is answered with its HTTP status or a closed
connection, and its details go to the debug log (``debug_log``) as one line each, never to
the terminal, which belongs to the sleeve's lines. A traceback in that log is a bug of the
server's own. A device that refuses the certificate
gets one line there, in words, at most once a minute.

Bounds: a request's line and headers (and body) must arrive within
``HEADER_TIMEOUT_S`` of the connection opening or of the previous answer, else the
connection is closed; at most ``MAX_CONNECTIONS`` are held, and a new one is always
taken: the one idle longest is closed to make room, so idle connections never keep a
page load out.

With TLS, plain ``http://`` on the same port (a user who typed the address) is told
to go to ``https://``: the first byte tells a TLS handshake (0x16) from anything else.
"""

from __future__ import annotations

import asyncio
import hmac
import json
import logging
import logging.handlers
import socket
import ssl
import sys
import threading
import time
from collections import OrderedDict, deque
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from http.cookies import CookieError, SimpleCookie
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, quote, urlsplit

import aiohttp
from aiohttp import web
from aiohttp.abc import AbstractStreamWriter
from aiohttp.http_exceptions import HttpProcessingError

from feelmysign.broker.tls import TlsFiles
from feelmysign.errors import FeelMySignError

WEB_DIST = Path(__file__).resolve().parents[3] / "web" / "dist"
# An API mounted under /api/ (the study's): (method, path, host, body, content type) ->
# (status, content type, body). It answers every error itself.
Api = Callable[[str, str, str, bytes, str], tuple[int, str, bytes]]
MAX_API_BODY_BYTES = 64 * 1024
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "[::1]")
KEY_COOKIE = "feelmysign_key"
# The wearer's page (/wearer) and its API (/api/wearer/) take the wearer's key, in a cookie of
# its own: the sender's key does not open them, nor does the wearer's open the broker's login.
WEARER_COOKIE = "feelmysign_wearer_key"
WEARER_API_PREFIX = "/api/wearer/"

# A request's line and headers (and its body) within this, from the connection's start
# or the previous answer: a slow or silent client is closed, not waited for.
HEADER_TIMEOUT_S = 10.0
TLS_HANDSHAKE_TIMEOUT_S = 10.0
# The longest a page, file or API answer may take to be sent (a phone on a slow network
# loads the page's few hundred kilobytes in far less). The /mqtt relay is not bounded by
# it: the broker ends a silent MQTT session itself (its keep-alive).
REQUEST_TIMEOUT_S = 60.0
# Connections held at once; past it the one idle longest is closed (never a new one).
MAX_CONNECTIONS = 512
ACCEPT_BATCH = 256  # connections taken from the listening socket's queue per turn of the loop
# aiohttp's parser limits: a request line or a header of at most 8 KiB, 100 headers.
MAX_LINE_BYTES = 8190
MAX_FIELD_BYTES = 8190
MAX_HEADERS = 100
RELAY_CONNECT_TIMEOUT_S = 5.0
# The WebSocket subprotocols of MQTT (3.1.1 and 5; 3.1): a page that offers others gets 400.
MQTT_SUBPROTOCOLS = frozenset({"mqtt", "mqttv3.1"})
# A device's line in the terminal (e.g. it refused the certificate): at most this often.
NOTICE_INTERVAL_S = 60.0
NOTICE_LINES = 5  # of such lines in all per interval, whatever the number of devices
DEBUG_LOG_BYTES = 1024 * 1024  # the debug log rotates at this size, one old file kept
# TLS alerts by which a client says it does not trust the certificate.
_CERTIFICATE_REFUSED = {
    "TLSV1_ALERT_UNKNOWN_CA",
    "SSLV3_ALERT_CERTIFICATE_UNKNOWN",
    "SSLV3_ALERT_BAD_CERTIFICATE",
}
_TLS_HANDSHAKE_RECORD = 0x16
# What a network peer does that is no fault of the server's: a malformed or oversized request
# (aiohttp's parser), a connection gone mid-answer (a closed tab, a phone changing networks).
_PEER_FAULTS = (HttpProcessingError, ConnectionError)
_PEER_FAULT_TEXT_CHARS = 200  # of the exception's text in its debug line (it may quote the request)

# aiohttp's own loggers (its parser's and WebSocket errors, with tracebacks) go to the debug
# log of the server that is running, never to the terminal.
_AIOHTTP_LOG = logging.getLogger("aiohttp")
_AIOHTTP_LOG.propagate = False
_AIOHTTP_LOG.addHandler(logging.NullHandler())


def _new_loop() -> asyncio.AbstractEventLoop:
    """libuv's event loop (uvloop) where it is built: a relayed MQTT message costs about half
    the CPU time of asyncio's own loop, whose plain sockets read into a fresh 256 KiB buffer
    each time (above glibc's mmap threshold: a map and an unmap per message). Elsewhere
    (Windows) asyncio's."""
    try:
        import uvloop
    except ImportError:
        return asyncio.new_event_loop()
    return uvloop.new_event_loop()


class _PeerFaults(logging.Filter):
    """A peer's fault as one debug line, without a traceback: aiohttp logs an oversized
    request or a client gone mid-answer as an error with its traceback, which is for bugs."""

    def filter(self, record: logging.LogRecord) -> bool:
        fault = record.exc_info[1] if record.exc_info else None
        if isinstance(fault, _PEER_FAULTS):
            text = " ".join(str(fault).split())[:_PEER_FAULT_TEXT_CHARS]
            record.msg = f"{record.getMessage()}: {type(fault).__name__}: {text}"
            record.args = None
            record.exc_info = None
            record.exc_text = None
            record.levelno, record.levelname = logging.DEBUG, logging.getLevelName(logging.DEBUG)
        return True


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


@dataclass(eq=False)
class _Connection:
    """One client connection, for the timeout and the connection cap."""

    sock: socket.socket
    peer: str
    port: int
    idle_since_s: float
    opening: asyncio.Task[None] | None = None
    transport: asyncio.BaseTransport | None = None
    active: int = 0  # requests being answered (a relayed WebSocket: its whole session)

    @property
    def closed(self) -> bool:
        return self.sock.fileno() < 0

    def close(self) -> None:
        if self.transport is not None:
            self.transport.abort()  # type: ignore[attr-defined]
        elif self.opening is not None:
            self.opening.cancel()  # closes the socket
        else:
            self.sock.close()


@dataclass
class _Notices:
    """A line in the terminal per device, at most once per ``NOTICE_INTERVAL_S``, and at most
    ``NOTICE_LINES`` lines in all per interval: a peer with many addresses (IPv6 gives a
    device as many as it likes) would otherwise fill the terminal, a line per address. Past
    that, one line says that more are held back (each is in the debug log)."""

    last_s: dict[str, float] = field(default_factory=dict)
    said_s: deque[float] = field(default_factory=deque)
    held_back: bool = False

    def say(self, peer: str, line: str, held_back: str) -> None:
        now = time.monotonic()
        if now - self.last_s.get(peer, -NOTICE_INTERVAL_S) < NOTICE_INTERVAL_S:
            return
        if len(self.last_s) > 1024:  # many devices: forget those not heard of for a while
            self.last_s = {p: t for p, t in self.last_s.items() if now - t < NOTICE_INTERVAL_S}
        self.last_s[peer] = now
        while self.said_s and now - self.said_s[0] >= NOTICE_INTERVAL_S:
            self.said_s.popleft()
        if len(self.said_s) < NOTICE_LINES:
            self.said_s.append(now)
            self.held_back = False
        elif self.held_back:
            return
        else:
            self.held_back = True
            line = held_back
        sys.stdout.write(line + "\n")
        sys.stdout.flush()


def _text(status: int, text: str, cache: str = "no-cache") -> web.Response:
    return web.Response(
        status=status,
        text=text if text.endswith("\n") else text + "\n",
        headers={"Cache-Control": cache},
    )


class WebServer:
    """``with WebServer(port=8000, config={...}) as server: server.url``.

    ``hosts``: names besides the loopback ones under which pages may read
    ``/config.json`` (e.g. the machine's LAN address, when serving there).
    ``debug_log``: where the details of what peers did wrong go (rotated; none: dropped).
    ``wearer_api`` and ``wearer_key``: the wearer's page at ``/wearer`` and its API under
    ``/api/wearer/``, which needs the wearer's key (opened once as ``/wearer?key=KEY``, then
    a cookie) whether on loopback or not, and a ``Host`` naming this server.
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
        debug_log: Path | None = None,
        wearer_api: Api | None = None,
        wearer_key: str | None = None,
        sock: socket.socket | None = None,
    ) -> None:
        check_built(directory)
        self._root = directory.resolve()
        self._config = json.dumps(config).encode()
        self._api = api
        if (wearer_api is None) != (wearer_key is None):
            raise ValueError("the wearer's API and the wearer's key go together")
        self._wearer_api = wearer_api
        self._wearer_key = wearer_key
        self._access_key = access_key
        self._mqtt_ws_port = mqtt_ws_port
        # ``sock``: bound beforehand by listen(host, port), so the port is known to be ours
        # before anything else starts (feelmysign up binds it before its broker writes a file).
        self._sock = sock if sock is not None else listen(host, port)
        self._tls = _tls_context(tls) if tls is not None else None
        self._ca_fingerprint = tls.ca_fingerprint if tls is not None else None
        # Known once bound (port 0 picks one): only now can the Host values be listed.
        self._allowed_hosts = host_header_names((*LOOPBACK_HOSTS, host, *hosts), self.port)
        self._log = logging.getLogger(f"feelmysign.webserver.{id(self)}")
        self._log.propagate = False
        self._log.setLevel(logging.DEBUG)
        self._log_handler: logging.Handler = logging.NullHandler()
        if debug_log is not None:
            debug_log.parent.mkdir(parents=True, exist_ok=True)
            self._log_handler = logging.handlers.RotatingFileHandler(
                debug_log, maxBytes=DEBUG_LOG_BYTES, backupCount=1, encoding="utf-8", delay=True
            )
            self._log_handler.setFormatter(
                logging.Formatter("%(asctime)s %(name)s %(levelname)s %(message)s")
            )
            self._log_handler.addFilter(_PeerFaults())
        self._log.addHandler(self._log_handler)
        self._notices = _Notices()
        # Least recently active first (moved to the end after each answer): the one to close
        # at the cap is found at the front, in constant time however many are held.
        self._connections: OrderedDict[tuple[str, int], _Connection] = OrderedDict()
        # The study API blocks (SQLite, the broker): one thread answers it, away from the loop.
        self._api_pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="page-api")
        self._loop = _new_loop()
        self._thread = threading.Thread(
            target=self._loop.run_forever, name="page-server", daemon=True
        )
        self._stopped: asyncio.Future[None] | None = None

    # -- the public side ----------------------------------------------------------------

    def set_config(self, config: dict[str, Any]) -> None:
        """Serve ``config`` as /config.json from now on (e.g. once the port is known)."""
        self._config = json.dumps(config).encode()

    @property
    def port(self) -> int:
        return int(self._sock.getsockname()[1])

    @property
    def authority(self) -> str:
        """``host:port`` as a URL holds it."""
        host = self._sock.getsockname()[0]
        return f"[{host}]:{self.port}" if ":" in host else f"{host}:{self.port}"

    @property
    def url(self) -> str:
        return f"{'https' if self._tls else 'http'}://{self.authority}/"

    def __enter__(self) -> WebServer:
        _AIOHTTP_LOG.addHandler(self._log_handler)
        _AIOHTTP_LOG.setLevel(logging.DEBUG)
        self._thread.start()
        asyncio.run_coroutine_threadsafe(self._start(), self._loop).result(timeout=30)
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            asyncio.run_coroutine_threadsafe(self._stop(), self._loop).result(timeout=30)
        finally:
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(timeout=30)
            if not self._thread.is_alive():
                self._loop.close()
            self._sock.close()
            self._api_pool.shutdown(wait=False, cancel_futures=True)
            _AIOHTTP_LOG.removeHandler(self._log_handler)
            self._log.removeHandler(self._log_handler)
            self._log_handler.close()

    # -- the loop's side ------------------------------------------------------------------

    async def _start(self) -> None:
        loop = asyncio.get_running_loop()
        loop.set_exception_handler(self._loop_exception)
        # aiohttp opens and reads files in the loop's executor: a few threads, whatever the cores.
        loop.set_default_executor(
            ThreadPoolExecutor(max_workers=4, thread_name_prefix="page-files")
        )
        options: dict[str, Any] = {
            "logger": self._log,
            "access_log": None,
            "keepalive_timeout": HEADER_TIMEOUT_S,
            "max_line_size": MAX_LINE_BYTES,
            "max_field_size": MAX_FIELD_BYTES,
            "max_headers": MAX_HEADERS,
        }
        self._pages = web.Server(self._handle, **options)
        self._redirects = web.Server(self._redirect, **options)
        self._client = aiohttp.ClientSession(
            timeout=aiohttp.ClientTimeout(total=None, connect=RELAY_CONNECT_TIMEOUT_S)
        )
        self._sock.setblocking(False)
        self._tasks = [
            loop.create_task(self._accept()),
            loop.create_task(self._sweep()),
        ]

    async def _stop(self) -> None:
        for task in self._tasks:
            task.cancel()
        for connection in list(self._connections.values()):
            connection.close()
        await asyncio.gather(*self._tasks, return_exceptions=True)
        await self._pages.shutdown(timeout=1.0)
        await self._redirects.shutdown(timeout=1.0)
        await self._client.close()

    def _loop_exception(self, loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        self._log.debug("%s", context.get("message"), exc_info=context.get("exception"))

    async def _accept(self) -> None:
        loop = asyncio.get_running_loop()
        while True:
            try:
                sock, address = await loop.sock_accept(self._sock)
            except OSError as error:  # e.g. out of file descriptors: wait, then go on
                self._log.debug("accept: %s", error)
                await asyncio.sleep(0.1)
                continue
            self._take(loop, sock, address)
            # The rest of a burst at once: a turn of the loop for each connection waiting made
            # a page load behind a thousand of them wait about a second.
            for _ in range(ACCEPT_BATCH):
                try:
                    sock, address = self._sock.accept()
                except (BlockingIOError, InterruptedError):
                    break
                except OSError as error:
                    self._log.debug("accept: %s", error)
                    break
                sock.setblocking(False)
                self._take(loop, sock, address)

    def _take(self, loop: asyncio.AbstractEventLoop, sock: socket.socket, address: Any) -> None:
        self._make_room()
        peer = (str(address[0]), int(address[1]))
        connection = _Connection(sock, peer[0], peer[1], time.monotonic())
        self._connections[peer] = connection
        self._connections.move_to_end(peer)  # the address of one closed a moment ago
        connection.opening = loop.create_task(self._open(connection, peer))

    def _make_room(self) -> None:
        """Below the cap, by closing the connection idle longest (never refusing a new one)."""
        if len(self._connections) < MAX_CONNECTIONS:
            return
        for peer, connection in self._connections.items():
            if connection.closed or connection.active == 0:
                del self._connections[peer]
                if not connection.closed:
                    self._log.debug("connection cap: closed an idle one from %s", peer[0])
                    connection.close()
                return

    async def _sweep(self) -> None:
        """Close connections that sent no whole request within ``HEADER_TIMEOUT_S``."""
        while True:
            await asyncio.sleep(1.0)
            now = time.monotonic()
            for peer, connection in list(self._connections.items()):
                if connection.closed:
                    del self._connections[peer]
                elif connection.active == 0 and now - connection.idle_since_s > HEADER_TIMEOUT_S:
                    self._log.debug("%s sent no whole request in time: closed", connection.peer)
                    connection.close()

    async def _open(self, connection: _Connection, peer: tuple[str, int]) -> None:
        """Hand the connection to aiohttp: the pages, or (plain HTTP on the TLS port) the
        redirect to https://."""
        loop = asyncio.get_running_loop()
        sock = connection.sock
        try:
            server, context = self._pages, None
            if self._tls is not None:
                first = await asyncio.wait_for(_first_byte(sock), HEADER_TIMEOUT_S)
                if first is None:
                    sock.close()
                    return
                if first == _TLS_HANDSHAKE_RECORD:
                    context = self._tls
                else:
                    server = self._redirects
            transport, _ = await loop.connect_accepted_socket(
                server,
                sock,
                ssl=context,
                ssl_handshake_timeout=TLS_HANDSHAKE_TIMEOUT_S if context else None,
            )
            connection.transport = transport
        except ssl.SSLError as error:
            self._tls_failed(connection, error)
            sock.close()
        except (OSError, asyncio.TimeoutError, asyncio.CancelledError) as error:
            self._log.debug("%s: connection ended before a request: %r", connection.peer, error)
            sock.close()
        finally:
            connection.opening = None

    def _tls_failed(self, connection: _Connection, error: ssl.SSLError) -> None:
        self._log.debug("%s: TLS handshake failed: %r", connection.peer, error)
        if getattr(error, "reason", None) in _CERTIFICATE_REFUSED:
            fingerprint = (
                f" (CA SHA-256 {self._ca_fingerprint[:16]}...)" if self._ca_fingerprint else ""
            )
            self._notices.say(
                connection.peer,
                f"A device at {connection.peer} did not accept this machine's certificate: "
                f"on it, open the printed URL and accept the certificate{fingerprint}.",
                "More devices did not accept this machine's certificate; for a minute they are "
                "not named here (each is in page-server.log).",
            )

    def _connection_of(self, request: web.BaseRequest) -> _Connection | None:
        transport = request.transport
        peer = transport.get_extra_info("peername") if transport is not None else None
        if not peer:
            return None
        return self._connections.get((str(peer[0]), int(peer[1])))

    # -- the answers ----------------------------------------------------------------------

    async def _redirect(self, request: web.BaseRequest) -> web.StreamResponse:
        """Plain HTTP on the TLS port: to the same path over HTTPS, at this server's name."""
        # The target as a path: a request in absolute form (``GET http://name/x``, as sent to
        # a proxy) would otherwise leave its scheme and name after this server's.
        return web.Response(
            status=301,
            headers={
                "Location": f"https://{self.authority}{request.rel_url.raw_path_qs}",
                "Cache-Control": "no-store",
                "Connection": "close",
            },
        )

    async def _handle(self, request: web.BaseRequest) -> web.StreamResponse:
        connection = self._connection_of(request)
        if connection is not None:
            connection.active += 1
        try:
            if self._is_relay(request):
                return await self._relay(request)
            try:
                return await asyncio.wait_for(self._answer_sent(request), REQUEST_TIMEOUT_S)
            except asyncio.TimeoutError:
                self._log.debug("%s: request not done in time: closed", request.remote)
                if request.transport is not None:
                    request.transport.abort()
                return web.Response(status=408)
        finally:
            if connection is not None:
                connection.active -= 1
                connection.idle_since_s = time.monotonic()
                peer = (connection.peer, connection.port)
                if self._connections.get(peer) is connection:
                    self._connections.move_to_end(peer)

    async def _answer_sent(self, request: web.BaseRequest) -> web.StreamResponse:
        """The answer, sent here within the time limit (aiohttp would send it after)."""
        response = await self._answer(request)
        try:
            if not response.prepared:
                await response.prepare(request)
                await response.write_eof()
        except ConnectionError as error:  # a closed tab, a phone that changed networks
            self._log.debug(
                "%s went away before %s was sent: %r", request.remote, request.path, error
            )
            if request.transport is not None:
                request.transport.abort()
        return response

    def _is_relay(self, request: web.BaseRequest) -> bool:
        return (
            request.path == "/mqtt"
            and self._mqtt_ws_port is not None
            and request.method == "GET"
            and request.headers.get("Upgrade", "").lower() == "websocket"
            and self._key_checked(request) is None
        )

    async def _answer(self, request: web.BaseRequest) -> web.StreamResponse:
        path = request.path
        if self._wearer_api is not None and (
            path in ("/wearer", "/wearer/") or path.startswith(WEARER_API_PREFIX)
        ):
            return await self._wearer(request)
        if self._access_key is not None:
            refused = self._key_checked(request)
            if refused is not None:
                return refused
        if self._api is not None and path.startswith("/api/"):
            if request.method not in ("GET", "HEAD"):
                refused = self._foreign_origin(request)
                if refused is not None:
                    return refused
            return await self._call_api(request)
        if request.method == "POST":
            return _text(404, "Not Found")
        if request.method not in ("GET", "HEAD"):
            return _text(501, f"Unsupported method {request.method!r}")
        if path == "/config.json":
            return self._config_json(request)
        return self._static(path)

    def _key_checked(self, request: web.BaseRequest) -> web.StreamResponse | None:
        """None to go on; else the answer: a cookie and a redirect, or 403."""
        if self._access_key is None:
            return None
        path = request.path
        offered = parse_qs(request.query_string).get("key", [None])[0]
        if offered is not None and hmac.compare_digest(offered.encode(), self._access_key.encode()):
            return web.Response(
                status=303,
                headers={
                    "Set-Cookie": f"{KEY_COOKIE}={self._access_key}; Secure; HttpOnly; "
                    "SameSite=Strict; Path=/",
                    "Location": _local_location(path),
                    "Cache-Control": "no-store",
                },
            )
        if path not in ("/config.json", "/mqtt") and not path.startswith("/api/"):
            return None  # the page itself is public; the broker, its password, the API are not
        try:
            cookie = SimpleCookie(request.headers.get("Cookie", ""))
        except CookieError:
            cookie = SimpleCookie()
        held = cookie[KEY_COOKIE].value if KEY_COOKIE in cookie else ""
        if hmac.compare_digest(held.encode(), self._access_key.encode()):
            return None
        return _text(403, "Forbidden: open the URL that 'feelmysign up' printed (it holds the key)")

    def _foreign_origin(self, request: web.BaseRequest) -> web.StreamResponse | None:
        """None to go on; else 403 for a browser's request made by a page of another origin.

        A cookie goes with every request a browser makes to this host, whichever page makes
        it, on any of the host's ports: a page served elsewhere on this machine (or by another
        service on the same address) could otherwise pause the sleeve or unblock a sender
        with the wearer's cookie, or speak MQTT through ``/mqtt`` with the sender's. Browsers
        name the page's origin in ``Origin`` on such requests; a client that is not a browser
        sends none, or (paho) this server's."""
        origin = request.headers.get("Origin")
        if origin is None or _origin_authority(origin) in self._allowed_hosts:
            return None
        self._log.debug("%s: refused a request from the origin %r", request.remote, origin[:80])
        return _text(
            403,
            f"Forbidden: a page from {origin[:80]!r} may not use this server; open the URL "
            "that 'feelmysign up' printed.",
            cache="no-store",
        )

    async def _wearer(self, request: web.BaseRequest) -> web.StreamResponse:
        """The wearer's page and API: only for a Host naming this server (else a page from
        anywhere could rebind its name to this machine and pause or unblock), and the API
        only with the wearer's key."""
        key = self._wearer_key
        assert key is not None
        host = (request.headers.get("Host") or "").strip().lower()
        if host not in self._allowed_hosts:
            return _text(
                403,
                f"Forbidden: the wearer's page is served only at this server's addresses "
                f"({', '.join(sorted(self._allowed_hosts))}), not to Host {host[:80]!r}. Open "
                "the wearer's URL that 'feelmysign up' printed.",
                cache="no-store",
            )
        offered = parse_qs(request.query_string).get("key", [None])[0]
        if offered is not None and hmac.compare_digest(offered.encode(), key.encode()):
            secure = "Secure; " if self._tls is not None else ""
            return web.Response(
                status=303,
                headers={
                    "Set-Cookie": f"{WEARER_COOKIE}={key}; {secure}HttpOnly; "
                    "SameSite=Strict; Path=/",
                    "Location": "/wearer",
                    "Cache-Control": "no-store",
                },
            )
        if not request.path.startswith(WEARER_API_PREFIX):
            if request.method not in ("GET", "HEAD"):
                return _text(405, f"Unsupported method {request.method!r} for the wearer's page")
            return self._static("/wearer.html")  # the page is public; its API is not
        try:
            cookie = SimpleCookie(request.headers.get("Cookie", ""))
        except CookieError:
            cookie = SimpleCookie()
        if request.method not in ("GET", "HEAD"):
            refused = self._foreign_origin(request)
            if refused is not None:
                return refused
        held = cookie[WEARER_COOKIE].value if WEARER_COOKIE in cookie else ""
        if not hmac.compare_digest(held.encode(), key.encode()):
            return web.json_response(
                {
                    "error": "This phone does not hold the wearer's key: open the wearer's URL "
                    "that 'feelmysign up' printed (or scan its QR code) once."
                },
                status=403,
                headers={"Cache-Control": "no-store"},
            )
        return await self._call_api(request, self._wearer_api)

    def _config_json(self, request: web.BaseRequest) -> web.StreamResponse:
        host = (request.headers.get("Host") or "").strip().lower()
        if host not in self._allowed_hosts:
            return _text(
                403,
                f"Forbidden: /config.json holds the broker login and is served only to pages "
                f"opened from this server ({', '.join(sorted(self._allowed_hosts))}), not to "
                f"Host {host[:80]!r}. Open the drawing client at one of those addresses.",
                cache="no-store",
            )
        return web.Response(
            body=self._config,
            content_type="application/json",
            headers={"Cache-Control": "no-store"},
        )

    async def _call_api(
        self, request: web.BaseRequest, api: Api | None = None
    ) -> web.StreamResponse:
        api = api or self._api
        assert api is not None
        # At most one byte past the limit: enough for the API to refuse it as too large.
        body = await _read_at_most(request, MAX_API_BODY_BYTES + 1)
        status, kind, payload = await asyncio.get_running_loop().run_in_executor(
            self._api_pool,
            api,
            request.method,
            request.path,
            request.headers.get("Host", ""),
            body,
            request.headers.get("Content-Type", ""),
        )
        return web.Response(
            status=status, body=payload, headers={"Content-Type": kind, "Cache-Control": "no-store"}
        )

    def _static(self, path: str) -> web.StreamResponse:
        if path in ("/study", "/study/"):
            path = "/study.html"  # the researcher's page of the recognition study
        try:
            target = (self._root / path.lstrip("/")).resolve()
            if target.is_dir():
                target = target / "index.html"
            found = target.is_relative_to(self._root) and target.is_file()
        except (OSError, ValueError):  # a name the file system cannot hold (e.g. a NUL)
            found = False
        if not found:
            return _text(404, "Not Found")
        # A rebuilt client is seen at once; assets/ names carry their content's hash.
        assets = path.startswith("/assets/")
        return _FileResponse(target, headers={} if assets else {"Cache-Control": "no-cache"})

    async def _relay(self, request: web.BaseRequest) -> web.StreamResponse:
        """MQTT over WebSockets from the page's own origin: ``/mqtt`` relayed to the broker's
        WebSocket listener on 127.0.0.1.

        Off loopback the page is served over HTTPS with the local CA's certificate. A phone
        that accepts that certificate once for the page would have to accept it again for a
        broker on another port; relaying keeps a single origin, so one acceptance covers
        both, and the broker's WebSocket listener never leaves loopback.

        The page's handshake is checked here, then made again with the broker (its key and
        subprotocols, nothing else: no cookie, no compression), and the broker's answer is
        the page's. From then on the relay passes bytes both ways as they come, each
        transport's reads written to the other by the event loop itself (``_ToPage``,
        ``_ToBroker``): the frames are the page's and the broker's, not decoded and encoded
        again, no task wakes per message (which cost about four times the CPU time of the
        byte relay before aiohttp, and a visible latency), and no Python of the relay's or
        aiohttp's runs per message.
        """
        refused = self._foreign_origin(request)
        if refused is not None:
            return refused
        offered = [p.strip() for p in request.headers.get("Sec-WebSocket-Protocol", "").split(",")]
        offered = [p for p in offered if p]
        if not web.WebSocketResponse(protocols=offered).can_prepare(request).ok:
            return _text(400, "Bad Request: not a WebSocket handshake")
        if offered and not set(offered) & MQTT_SUBPROTOCOLS:
            # The broker would close the connection unanswered, which reads as its fault (502).
            return _text(
                400,
                "Bad Request: /mqtt speaks the WebSocket subprotocol "
                f"{' or '.join(sorted(MQTT_SUBPROTOCOLS))}, not {', '.join(offered)[:80]!r}",
            )
        loop = asyncio.get_running_loop()
        page, port = request.transport, self._mqtt_ws_port
        assert port is not None  # _is_relay: only with the broker's WebSocket port
        if page is None:
            return _text(400, "Bad Request: the connection is closed")
        try:
            upstream_transport, upstream = await asyncio.wait_for(
                loop.create_connection(
                    lambda: _Upstream(page),
                    "127.0.0.1",
                    port,
                ),
                RELAY_CONNECT_TIMEOUT_S,
            )
        except (OSError, asyncio.TimeoutError) as error:
            self._log.debug("relay: the broker's WebSocket listener: %r", error)
            return _text(502, "The broker's WebSocket listener does not answer")
        try:
            upstream_transport.write(_upstream_handshake(request, port, offered))
            status, headers = await asyncio.wait_for(upstream.head, RELAY_CONNECT_TIMEOUT_S)
            if status != 101:
                raise ConnectionError(f"the broker answered the handshake with {status}")
        except (OSError, ValueError, asyncio.TimeoutError) as error:
            self._log.debug("relay: the broker's WebSocket handshake: %r", error)
            upstream_transport.abort()
            return _text(502, "The broker's WebSocket listener does not answer")
        switched = _Switched(
            status=101,
            headers={
                name: value for name, value in headers.items() if name.lower() in _UPGRADE_HEADERS
            },
        )
        switched.force_close()
        try:
            await switched.prepare(request)
            request.protocol.keep_alive(False)
            # Any bytes that came with the handshake go to the broker (as aiohttp's own
            # WebSocketResponse takes them), then the page's connection is the relay's.
            request.protocol.set_parser(_PageBytes(upstream_transport, upstream))  # type: ignore[arg-type]
            page.set_protocol(_ToBroker(upstream_transport, request.protocol))
            upstream.start()
            if page.is_closing():  # gone before its bytes came here: no end of them will
                upstream_transport.close()
            await upstream.ended
        except (OSError, asyncio.CancelledError) as error:
            self._log.debug("relay from %s ended: %r", request.remote, error)
        finally:
            upstream_transport.close()
            page.close()
        return switched


# Of the broker's answer to the handshake, what the page gets: the rest (its Server, Date)
# is the relay's own.
_UPGRADE_HEADERS = {"upgrade", "connection", "sec-websocket-accept", "sec-websocket-protocol"}
_HANDSHAKE_HEAD_BYTES = 8192  # the broker's answer to the handshake: a few hundred bytes


def _upstream_handshake(request: web.BaseRequest, port: int, protocols: list[str]) -> bytes:
    """The page's WebSocket handshake, as this relay makes it to the broker: the page's key
    (so the broker's answer is one the page accepts) and subprotocols, and nothing else."""
    lines = [
        "GET /mqtt HTTP/1.1",
        f"Host: 127.0.0.1:{port}",
        "Upgrade: websocket",
        "Connection: Upgrade",
        f"Sec-WebSocket-Key: {request.headers['Sec-WebSocket-Key']}",
        "Sec-WebSocket-Version: 13",
    ]
    if protocols:
        lines.append(f"Sec-WebSocket-Protocol: {', '.join(protocols)}")
    return ("\r\n".join(lines) + "\r\n\r\n").encode("latin-1")


class _Switched(web.StreamResponse):
    """The broker's 101 Switching Protocols, as the page's answer. After it the connection
    carries the relay's bytes, so aiohttp has nothing to end it with."""

    async def write_eof(self, data: bytes = b"") -> None:
        return None


class _Upstream(asyncio.Protocol):
    """The relay's connection to the broker until the page has its 101: the broker's answer
    to the handshake (``head``), and what follows it held for the page. Then (``start``)
    the connection is a ``_ToPage``'s."""

    def __init__(self, page: asyncio.Transport) -> None:
        self._page = page
        self._buffer = bytearray()
        self._head_read = False
        self.transport: asyncio.Transport | None = None
        loop = asyncio.get_running_loop()
        self.head: asyncio.Future[tuple[int, dict[str, str]]] = loop.create_future()
        self.ended: asyncio.Future[None] = loop.create_future()

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport  # type: ignore[assignment]
        sock = transport.get_extra_info("socket")
        if sock is not None:  # each MQTT packet at once, not held for the next (Nagle)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def data_received(self, data: bytes) -> None:
        self._buffer += data
        if self._head_read:
            return
        end = self._buffer.find(b"\r\n\r\n")
        if end < 0:
            if len(self._buffer) > _HANDSHAKE_HEAD_BYTES and not self.head.done():
                self.head.set_exception(ValueError("the broker's handshake answer is too long"))
            return
        if not self.head.done():
            try:
                self.head.set_result(_parse_head(bytes(self._buffer[:end])))
            except ValueError as error:
                self.head.set_exception(error)
                return
        del self._buffer[: end + 4]
        self._head_read = True

    def start(self) -> None:
        """Relay to the page from now on (its 101 is sent), with what came after the head."""
        assert self.transport is not None
        if self._buffer:
            self._page.write(bytes(self._buffer))
            self._buffer.clear()
        self.transport.set_protocol(_ToPage(self._page, self.ended))

    def connection_lost(self, exc: Exception | None) -> None:
        if not self.head.done():
            self.head.set_exception(ConnectionResetError("the broker closed the connection"))
        if not self.ended.done():
            self.ended.set_result(None)


# Once relaying, each connection's protocol is one of the two below. Its ``data_received``
# is the other transport's own ``write``: the event loop hands each read straight to the
# other socket, with no Python of the relay's per message (the relay's CPU time is then
# the sockets'). The flow control is asyncio's: when one side's unsent bytes pass its
# transport's high-water mark, reading from the other stops until they are sent, so a
# page or a broker that does not read makes the relay hold no more than that.


class _ToPage(asyncio.Protocol):
    """The broker's connection: its bytes on to the page as they come."""

    def __init__(self, page: asyncio.Transport, ended: asyncio.Future[None]) -> None:
        self.data_received = page.write  # type: ignore[method-assign]
        self._page = page
        self._ended = ended

    def pause_writing(self) -> None:  # the broker reads slower than the page sends
        self._page.pause_reading()

    def resume_writing(self) -> None:
        self._page.resume_reading()

    def connection_lost(self, exc: Exception | None) -> None:
        if not self._ended.done():
            self._ended.set_result(None)


class _ToBroker(asyncio.Protocol):
    """The page's connection, in the place of aiohttp's protocol: its bytes on to the broker
    as they come. Its end is still aiohttp's to handle (its ``connection_lost`` ends the
    request, and through ``_PageBytes`` the relay)."""

    def __init__(self, upstream: asyncio.Transport, aiohttp_protocol: asyncio.Protocol) -> None:
        self.data_received = upstream.write  # type: ignore[method-assign]
        self._upstream = upstream
        self._aiohttp = aiohttp_protocol

    def pause_writing(self) -> None:  # the page reads slower than the broker sends
        self._upstream.pause_reading()

    def resume_writing(self) -> None:
        self._upstream.resume_reading()

    def eof_received(self) -> bool | None:
        return self._aiohttp.eof_received()

    def connection_lost(self, exc: Exception | None) -> None:
        self._aiohttp.connection_lost(exc)


class _PageBytes:
    """What the page sent with its handshake, on to the broker, and the page's end (aiohttp's
    protocol calls ``feed_eof`` when the connection is lost)."""

    def __init__(self, upstream: asyncio.Transport, ending: _Upstream) -> None:
        self._upstream = upstream
        self._ending = ending

    def feed_data(self, data: bytes) -> tuple[bool, bytes]:
        self._upstream.write(data)
        return False, b""

    def feed_eof(self) -> None:  # the page went away
        self._upstream.close()
        if not self._ending.ended.done():
            self._ending.ended.set_result(None)


def _origin_authority(origin: str) -> str:
    """``host:port`` of an ``Origin`` header (lower case; the scheme's port when it names
    none), as a ``Host`` header names it; "" for ``null`` or anything else."""
    try:
        parts = urlsplit(origin.strip())
        port = parts.port or {"http": 80, "https": 443}.get(parts.scheme)
    except ValueError:
        return ""
    host = parts.hostname
    if not host or port is None:
        return ""
    return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"


def _local_location(path: str) -> str:
    """A ``Location`` on this server for the decoded ``path``: percent-encoded, so that no CR
    or LF of the request reaches the header (aiohttp refuses to send one, a 500), and with
    one leading slash, so that ``//name/`` (a page on another host) stays on this one."""
    return "/" + quote(path.lstrip("/\\"), safe="/")


def _parse_head(head: bytes) -> tuple[int, dict[str, str]]:
    lines = head.decode("latin-1").split("\r\n")
    parts = lines[0].split(" ", 2)
    if len(parts) < 2 or not parts[0].startswith("HTTP/") or not parts[1].isdigit():
        raise ValueError(f"not an HTTP answer: {lines[0][:80]!r}")
    headers: dict[str, str] = {}
    for line in lines[1:]:
        name, colon, value = line.partition(":")
        if colon:
            headers[name.strip()] = value.strip()
    return int(parts[1]), headers


async def _read_at_most(request: web.BaseRequest, limit: int) -> bytes:
    chunks: list[bytes] = []
    size = 0
    while size < limit:
        chunk = await asyncio.wait_for(request.content.read(limit - size), HEADER_TIMEOUT_S)
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
    return b"".join(chunks)


async def _first_byte(sock: socket.socket) -> int | None:
    """The first byte the peer sent, left in the socket (None: it closed first)."""
    loop = asyncio.get_running_loop()
    ready: asyncio.Future[None] = loop.create_future()

    def readable() -> None:
        if not ready.done():
            ready.set_result(None)

    loop.add_reader(sock.fileno(), readable)
    try:
        await ready
    finally:
        loop.remove_reader(sock.fileno())
    try:
        first = sock.recv(1, socket.MSG_PEEK)
    except (BlockingIOError, InterruptedError):
        return await _first_byte(sock)
    return first[0] if first else None


def check_built(directory: Path) -> None:
    """FeelMySignError saying how to build the drawing client when ``directory`` lacks it."""
    index = directory / "index.html"
    if not index.is_file():
        raise FeelMySignError(
            f"the drawing client is not built ({index} is missing); run 'make web-build' "
            "(or 'make up', which builds it)"
        )


def listen(host: str, port: int) -> socket.socket:
    """A socket listening on ``host:port`` for WebServer(sock=...); FeelMySignError if not."""
    try:
        family, kind, proto, _, address = socket.getaddrinfo(
            host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
        )[0]
        sock = socket.socket(family, kind, proto)
    except OSError as error:
        raise FeelMySignError(
            f"cannot serve the drawing client on {host}:{port}: {error.strerror or error}; "
            "give an address of this machine"
        ) from error
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(address)
        sock.listen(1024)
    except OSError as error:
        sock.close()
        raise FeelMySignError(
            f"cannot serve the drawing client on {host}:{port}: {error.strerror}; "
            "choose another port with --http-port"
        ) from error
    return sock


def _tls_context(tls: TlsFiles) -> ssl.SSLContext:
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    context.minimum_version = ssl.TLSVersion.TLSv1_2
    context.load_cert_chain(tls.cert, tls.key)
    return context


class _FileResponse(web.FileResponse):
    """A file, sent within the time limit by ``_answer_sent``: aiohttp's own prepare after the
    handler returns is then a no-op, as for any response already sent (FileResponse's would
    send the file again, and fail on the finished writer, closing the connection)."""

    async def prepare(self, request: web.BaseRequest) -> AbstractStreamWriter | None:
        if self.prepared:
            return await web.StreamResponse.prepare(self, request)
        return await super().prepare(request)
