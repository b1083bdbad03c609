"""The page server as a network sees it, against a real ``feelmysign up`` (on loopback, and
with TLS on another address as ``--host`` serves it): malformed and oversized requests, a
bad Content-Length, TLS garbage, a cut handshake, a client that does not trust the
certificate, plain HTTP on the TLS port, disconnects at any point, hundreds of idle
connections, and a seeded fuzz pass over request lines and headers. Each gets its HTTP
status or a closed connection; ``up``'s terminal shows no traceback, and a device that
refused the certificate one line in words."""

from __future__ import annotations

import queue
import random
import re
import signal
import socket
import ssl
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from lan import Lan, lan

from feelmysign.webserver import MAX_CONNECTIONS, NOTICE_LINES

WAIT_S = 60.0
IDLE_CONNECTIONS = 500
MAX_THREADS = 64
FUZZ_REQUESTS = 300
FUZZ_SEED = 23
BIG_FILE_BYTES = 16_000_000
FEELMYSIGN = [sys.executable, "-m", "feelmysign"]
STATUS_LINE = re.compile(rb"^HTTP/1\.[01] (\d{3}) ")

pytestmark = pytest.mark.broker


@dataclass
class Up:
    process: subprocess.Popen[str]
    url: str
    host: str
    port: int
    state_dir: Path
    lines: list[str] = field(default_factory=list)

    @property
    def tls(self) -> bool:
        return self.url.startswith("https://")

    @property
    def key(self) -> str:
        return self.url.split("?key=", 1)[1] if "?key=" in self.url else ""

    def output_since(self, mark: int) -> str:
        time.sleep(0.5)  # what the server writes about the last input has reached the pipe
        return "\n".join(self.lines[mark:])

    def threads(self) -> int:
        status = Path(f"/proc/{self.process.pid}/status").read_text()
        return int(re.search(r"^Threads:\s+(\d+)", status, re.MULTILINE)[1])  # type: ignore[index]

    def ca_file(self) -> Path:
        return next(self.state_dir.rglob("ca.pem"))


def _start_up(tmp_path: Path, *lan_args: str) -> Iterator[Up]:
    site = tmp_path / "web"
    site.mkdir()
    (site / "index.html").write_text("<!doctype html><title>feelmysign</title>\n")
    (site / "assets").mkdir()
    # For a disconnect mid-answer: more than the socket buffers on both sides can hold.
    (site / "assets" / "big.js").write_text("x" * BIG_FILE_BYTES)
    state = tmp_path / "state"
    ports = ["--http-port", "0", "--port", "0", "--ws-port", "0"]
    process = subprocess.Popen(
        [*FEELMYSIGN, "up", "--state-dir", str(state), "--web-dir", str(site), *ports, *lan_args],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    lines: list[str] = []
    ready: queue.Queue[str] = queue.Queue()

    def read() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            lines.append(line.rstrip("\n"))
            if line.startswith("Press Ctrl-C") or "Draw here:" in line:
                ready.put(line)

    threading.Thread(target=read, daemon=True).start()
    try:
        url = ""
        while True:
            line = ready.get(timeout=WAIT_S)
            if "Draw here:" in line:
                url = line.split("Draw here:", 1)[1].strip()
            if line.startswith("Press Ctrl-C"):
                break
        authority = url.split("://", 1)[1].split("/", 1)[0]
        host, port = authority.rsplit(":", 1)
        up = Up(process, url, host, int(port), state, lines)
        yield up
    finally:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout=WAIT_S)
        finally:
            if process.poll() is None:
                process.kill()
    assert "Traceback" not in "\n".join(lines), "\n".join(lines)


@pytest.fixture(scope="module")
def loopback_up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    yield from _start_up(tmp_path_factory.mktemp("loopback"))


@pytest.fixture(scope="module")
def tls_up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    with lan() as network:
        yield from _lan_up(tmp_path_factory.mktemp("tls"), network)


def _lan_up(tmp_path: Path, network: Lan) -> Iterator[Up]:
    yield from _start_up(tmp_path, "--host", network.host_address, "--tls-port", "0")


@pytest.fixture(params=["loopback", "tls"])
def up(request: pytest.FixtureRequest) -> Up:
    return request.getfixturevalue(f"{request.param}_up")  # type: ignore[no-any-return]


# -- talking to it --------------------------------------------------------------------------


def _connect(up: Up, *, verify: bool = True) -> socket.socket:
    raw = socket.create_connection((up.host, up.port), timeout=WAIT_S)
    if not up.tls:
        return raw
    context = ssl.create_default_context(cafile=str(up.ca_file()) if verify else None)
    context.check_hostname = False
    return context.wrap_socket(raw)


def _exchange(up: Up, data: bytes, *, tls: bool | None = None) -> bytes:
    """Send ``data``, then read the answer until the server closes (or a whole response)."""
    sock = _connect(up) if tls is None or tls == up.tls else _plain(up)
    with sock:
        sock.sendall(data)
        return _read_answer(sock)


def _plain(up: Up) -> socket.socket:
    return socket.create_connection((up.host, up.port), timeout=WAIT_S)


def _read_answer(sock: socket.socket) -> bytes:
    received = b""
    while True:
        try:
            chunk = sock.recv(65536)
        except (ConnectionResetError, ssl.SSLError):
            return received
        if not chunk:
            return received
        received += chunk
        head, _, body = received.partition(b"\r\n\r\n")
        length = re.search(rb"(?im)^content-length:\s*(\d+)", head)
        if length and len(body) >= int(length[1]):
            return received


def _status(answer: bytes) -> int | None:
    """The status of an HTTP answer, None for a connection closed without one."""
    found = STATUS_LINE.match(answer)
    return int(found[1]) if found else None


def _request(up: Up, path: str, *headers: str, method: str = "GET") -> bytes:
    lines = [f"{method} {path} HTTP/1.1", f"Host: {up.host}:{up.port}", *headers]
    return _exchange(up, ("\r\n".join([*lines, "Connection: close"]) + "\r\n\r\n").encode())


# -- the tests ------------------------------------------------------------------------------


def test_the_page_and_its_refusals_are_as_before(up: Up) -> None:
    mark = len(up.lines)
    assert _status(_request(up, "/")) == 200
    assert _status(_request(up, "/nothing-here")) == 404
    assert _status(_request(up, "/../../etc/passwd")) == 404
    page = _request(up, "/")
    assert b"cache-control: no-cache" in page.lower()
    config = _request(up, "/config.json")
    if up.tls:  # the broker login only with the key of the printed URL
        assert _status(config) == 403 and b"password" not in config
        given = _request(up, f"/?key={up.key}")
        assert _status(given) == 303 and b"feelmysign_key=" in given
        config = _request(up, "/config.json", f"Cookie: feelmysign_key={up.key}")
    assert _status(config) == 200 and b'"password"' in config
    assert b"cache-control: no-store" in config.lower()
    foreign = _exchange(up, b"GET /config.json HTTP/1.1\r\nHost: attacker.example\r\n\r\n")
    assert _status(foreign) == 403 and b'"password"' not in foreign
    assert "Traceback" not in up.output_since(mark)


BAD_REQUESTS = {
    "a request line that is not HTTP": b"HELLO THERE\r\n\r\n",
    "a request line of 70 KiB": b"GET /" + b"a" * 70_000 + b" HTTP/1.1\r\nHost: x\r\n\r\n",
    "a header of 70 KiB": b"GET / HTTP/1.1\r\nHost: x\r\nX-Big: " + b"b" * 70_000 + b"\r\n\r\n",
    "500 headers": b"GET / HTTP/1.1\r\n"
    + b"".join(b"X-%d: y\r\n" % i for i in range(500))
    + b"\r\n",
    "a Content-Length that is not a number": (
        b"POST /api/study HTTP/1.1\r\nHost: x\r\nContent-Length: abc\r\n\r\n"
    ),
    "two different Content-Lengths": (
        b"POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 1\r\nContent-Length: 2\r\n\r\nab"
    ),
    "a negative Content-Length": b"POST / HTTP/1.1\r\nHost: x\r\nContent-Length: -5\r\n\r\n",
    "a header without a colon": b"GET / HTTP/1.1\r\nHost: x\r\nnot a header\r\n\r\n",
    "a NUL in the path": b"GET /\x00 HTTP/1.1\r\nHost: x\r\n\r\n",
    "an HTTP version from the future": b"GET / HTTP/9.9\r\nHost: x\r\n\r\n",
    "binary garbage": bytes(range(1, 256)) + b"\r\n\r\n",
    "a cookie that is not one": (
        b'GET /config.json HTTP/1.1\r\nHost: x\r\nCookie: "\\\x7f;;=\r\n\r\n'
    ),
}


@pytest.mark.parametrize("name", BAD_REQUESTS)
def test_a_bad_request_gets_a_status_or_a_closed_connection(up: Up, name: str) -> None:
    mark = len(up.lines)
    answer = _exchange(up, BAD_REQUESTS[name])
    status = _status(answer)
    assert status is None or 400 <= status < 600, answer[:200]
    assert answer == b"" or status is not None, answer[:200]  # no half answer
    assert status != 500, answer[:500]
    assert "Traceback" not in up.output_since(mark)
    assert _status(_request(up, "/")) == 200  # and the next one is served


def test_disconnects_at_any_point_are_quiet(up: Up) -> None:
    mark = len(up.lines)
    full = f"GET /assets/big.js HTTP/1.1\r\nHost: {up.host}:{up.port}\r\n\r\n".encode()
    for cut in (0, 3, len(full) // 2, len(full) - 2):  # before or inside the request
        with _connect(up) as sock:
            sock.sendall(full[:cut])
    for _ in range(3):  # with the answer under way: the client resets the connection
        sock = _connect(up)
        sock.sendall(full)
        sock.recv(100)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\x01\x00\x00\x00\x00\x00\x00\x00")
        sock.close()
    with _connect(up) as sock:  # a body promised and never sent
        sock.sendall(b"POST /api/study HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\nab")
    assert "Traceback" not in up.output_since(mark)
    assert _status(_request(up, "/")) == 200


def test_a_closed_tab_or_an_oversized_request_is_one_debug_line_in_the_log(up: Up) -> None:
    """Expected peer behaviour goes to the debug log as a line each, never as an error with a
    traceback (those are for the server's own bugs)."""
    log = up.state_dir / "page-server.log"
    before = log.read_text() if log.exists() else ""
    for name in ("a request line of 70 KiB", "a header of 70 KiB"):
        assert _status(_exchange(up, BAD_REQUESTS[name])) == 400
    _close_mid_answer(up, "/assets/big.js")
    added = _log_once(log, before, "went away before /assets/big.js was sent")
    lines = added.splitlines()
    assert "Traceback" not in added and " ERROR " not in added, added
    assert sum("LineTooLong" in line for line in lines) == 2, added
    assert all(" DEBUG " in line for line in lines), added
    assert _status(_request(up, "/")) == 200


def _close_mid_answer(up: Up, path: str) -> None:
    """A tab closed while the answer is under way: a small receive window, a reset."""
    raw = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    raw.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    raw.settimeout(WAIT_S)
    raw.connect((up.host, up.port))
    sock = raw
    if up.tls:
        context = ssl.create_default_context(cafile=str(up.ca_file()))
        context.check_hostname = False
        sock = context.wrap_socket(raw)
    sock.sendall(f"GET {path} HTTP/1.1\r\nHost: {up.host}:{up.port}\r\n\r\n".encode())
    assert _status(sock.recv(100)) == 200
    time.sleep(0.2)  # the server is blocked on the full window
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\x01\x00\x00\x00\x00\x00\x00\x00")
    sock.close()


def _log_once(log: Path, before: str, line: str) -> str:
    """What the debug log gained since ``before``, once it holds ``line``."""
    deadline = time.monotonic() + WAIT_S
    while True:
        added = log.read_text()[len(before) :]
        if line in added or time.monotonic() > deadline:
            return added
        time.sleep(0.1)


def test_a_silent_or_slow_client_is_closed(up: Up) -> None:
    with _plain(up) as silent, _plain(up) as slow:
        slow.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n")  # and never the end of its headers
        for sock in (silent, slow):
            sock.settimeout(WAIT_S)  # closed by the server well before: else a timeout error
            assert _drained(sock)


def _drained(sock: socket.socket) -> bool:
    """True once the server has closed it (reading whatever it said first)."""
    while True:
        try:
            if not sock.recv(4096):
                return True
        except ConnectionResetError:
            return True


def test_the_page_is_served_with_hundreds_of_idle_connections(up: Up) -> None:
    mark = len(up.lines)
    idle = [_plain(up) for _ in range(IDLE_CONNECTIONS)]
    try:
        assert _status(_request(up, "/")) == 200
        assert up.threads() <= MAX_THREADS
    finally:
        for sock in idle:
            sock.close()
    assert "Traceback" not in up.output_since(mark)


def test_past_the_connection_cap_idle_connections_make_room_for_a_page_load(
    loopback_up: Up,
) -> None:
    up = loopback_up
    idle = [_plain(up) for _ in range(MAX_CONNECTIONS + 100)]
    try:
        assert _status(_request(up, "/")) == 200
        assert up.threads() <= MAX_THREADS
        idle[0].settimeout(WAIT_S)
        assert _drained(idle[0])  # the one idle longest was closed
    finally:
        for sock in idle:
            sock.close()


def test_fuzzed_request_lines_and_headers(loopback_up: Up) -> None:
    up = loopback_up
    mark = len(up.lines)
    generator = random.Random(FUZZ_SEED)
    for _ in range(FUZZ_REQUESTS):
        answer = _exchange(up, _fuzzed_request(generator))
        status = _status(answer)
        assert answer == b"" or status is not None, answer[:200]
        assert status is None or status < 500 or status == 501, answer[:500]
    assert "Traceback" not in up.output_since(mark)
    assert _status(_request(up, "/")) == 200


def _fuzzed_request(generator: random.Random) -> bytes:
    """A request line and headers, each part now and then replaced by something odd."""
    odd = [
        b"",
        b" ",
        b"\x00",
        b"\xff\xfe",
        b"\r",
        b"\n",
        b":",
        b"%",
        b"%zz",
        b"\t",
        b"a" * generator.choice([1, 100, 9000]),
        bytes(generator.randrange(256) for _ in range(generator.randrange(1, 40))),
    ]

    def part(usual: bytes) -> bytes:
        return generator.choice(odd) if generator.random() < 0.3 else usual

    method = part(generator.choice([b"GET", b"POST", b"HEAD", b"PUT", b"OPTIONS", b"BREW"]))
    path = part(generator.choice([b"/", b"/config.json", b"/api/study", b"/mqtt", b"/study"]))
    version = part(generator.choice([b"HTTP/1.1", b"HTTP/1.0"]))
    headers = [b"Host: " + part(b"127.0.0.1"), b"Connection: close"]
    for _ in range(generator.randrange(4)):
        name = part(generator.choice([b"Content-Length", b"Cookie", b"Upgrade", b"X-A"]))
        headers.append(name + part(b": ") + part(b"1"))
    generator.shuffle(headers)
    return b" ".join([method, path, version]) + b"\r\n" + b"\r\n".join(headers) + b"\r\n\r\n"


# -- with TLS only --------------------------------------------------------------------------


def test_plain_http_on_the_tls_port_is_sent_to_https(tls_up: Up) -> None:
    mark = len(tls_up.lines)
    answer = _exchange(tls_up, b"GET /some/page?x=1 HTTP/1.1\r\nHost: typed\r\n\r\n", tls=False)
    assert _status(answer) == 301, answer[:300]
    location = f"location: https://{tls_up.host}:{tls_up.port}/some/page?x=1"
    assert location.encode() in answer.lower()
    assert "Traceback" not in tls_up.output_since(mark)


def test_a_device_that_does_not_trust_the_certificate_gets_one_line(tls_up: Up) -> None:
    mark = len(tls_up.lines)
    for _ in range(3):  # a browser tries again and again: still one line
        with pytest.raises(ssl.SSLCertVerificationError):
            _connect(tls_up, verify=False)
    said = tls_up.output_since(mark)
    refused = [line for line in said.splitlines() if "did not accept" in line]
    assert len(refused) == 1, said
    assert refused[0].startswith(f"A device at {tls_up.host} did not accept this machine's")
    assert "accept the certificate (CA SHA-256 " in refused[0]
    assert "Traceback" not in said
    log = (tls_up.state_dir / "page-server.log").read_text()
    assert "TLSV1_ALERT_UNKNOWN_CA" in log  # the details are in the debug log


def test_tls_garbage_and_cut_handshakes_are_quiet(tls_up: Up) -> None:
    mark = len(tls_up.lines)
    hello = _client_hello(tls_up)
    for data in (
        b"\x16\x03\x01\x00\x05hello" + bytes(range(200)),  # a handshake record of garbage
        hello[: len(hello) // 2],  # a handshake cut half way
        hello,  # a whole hello, then gone
        b"\x16",
    ):
        with _plain(tls_up) as sock:
            sock.sendall(data)
            sock.shutdown(socket.SHUT_WR)
            assert _drained(sock)
    assert "Traceback" not in tls_up.output_since(mark)
    assert "did not accept" not in tls_up.output_since(mark)


def _client_hello(up: Up) -> bytes:
    """The bytes a TLS client opens with."""
    incoming, outgoing = ssl.MemoryBIO(), ssl.MemoryBIO()
    context = ssl.create_default_context()
    client = context.wrap_bio(incoming, outgoing, server_hostname=up.host)
    with pytest.raises(ssl.SSLWantReadError):
        client.do_handshake()
    return outgoing.read()


def test_plain_http_in_absolute_form_is_sent_to_this_server(tls_up: Up) -> None:
    """A request line as sent to a proxy names a host: the redirect keeps only its path."""
    answer = _exchange(
        tls_up, b"GET http://elsewhere.example/a/b?c=1 HTTP/1.1\r\nHost: typed\r\n\r\n", tls=False
    )
    assert _status(answer) == 301, answer[:300]
    location = f"location: https://{tls_up.host}:{tls_up.port}/a/b?c=1\r\n"
    assert location.encode() in answer.lower(), answer[:300]


@pytest.mark.parametrize(
    ("path", "location"),
    [
        ("/%0d%0aSet-Cookie:%20x=1", "/%0D%0ASet-Cookie%3A%20x%3D1"),  # no header injected
        ("//elsewhere.example/", "/elsewhere.example/"),  # not a page on another host
        ("/%5celsewhere.example/", "/elsewhere.example/"),
    ],
)
def test_the_key_url_leads_to_a_page_of_this_server(tls_up: Up, path: str, location: str) -> None:
    log = tls_up.state_dir / "page-server.log"
    before = log.read_text() if log.exists() else ""
    answer = _request(tls_up, f"{path}?key={tls_up.key}")
    assert _status(answer) == 303, answer[:300]
    assert f"\r\nLocation: {location}\r\n".encode() in answer, answer[:300]
    assert b"\r\nSet-Cookie: x" not in answer
    after = log.read_text() if log.exists() else ""
    assert "Traceback" not in after[len(before) :], after


def test_a_page_of_another_origin_cannot_use_the_keys_cookies(tls_up: Up) -> None:
    """A browser sends this host's cookies with a request from any page, on any of its
    ports; the relay and the wearer's API answer only this server's own pages."""
    up = tls_up
    wearer_key = next(up.state_dir.rglob("wearer-key")).read_text().strip()
    own, foreign = f"Origin: https://{up.host}:{up.port}", "Origin: https://elsewhere.example"
    websocket = (
        "Upgrade: websocket",
        "Connection: Upgrade",
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
        "Sec-WebSocket-Version: 13",
        "Sec-WebSocket-Protocol: mqtt",
        f"Cookie: feelmysign_key={up.key}",
    )
    for origin, status in ((foreign, 403), ("Origin: null", 403), (own, 101)):
        with _connect(up) as sock:
            head = f"GET /mqtt HTTP/1.1\r\nHost: {up.host}:{up.port}\r\n"
            sock.sendall((head + "\r\n".join((*websocket, origin)) + "\r\n\r\n").encode())
            assert _status(sock.recv(4096)) == status, origin
    wearer = (f"Cookie: feelmysign_wearer_key={wearer_key}", "Content-Length: 0")
    for origin, status in ((foreign, 403), (own, 200)):
        answer = _request(up, "/api/wearer/resume", *wearer, origin, method="POST")
        assert _status(answer) == status, answer[:300]


def test_devices_at_many_addresses_fill_no_terminal(tls_up: Up) -> None:
    """One peer may have many addresses: the lines about certificates are few in all."""
    mark = len(tls_up.lines)
    for last in range(100, 100 + 3 * NOTICE_LINES):  # loopback's addresses reach this one too
        raw = socket.create_connection(
            (tls_up.host, tls_up.port), timeout=WAIT_S, source_address=(f"127.0.0.{last}", 0)
        )
        context = ssl.create_default_context()
        context.check_hostname = False
        with pytest.raises(ssl.SSLCertVerificationError):
            context.wrap_socket(raw)
        raw.close()
    said = tls_up.output_since(mark).splitlines()
    named = [line for line in said if line.startswith("A device at 127.0.0.")]
    assert 1 <= len(named) <= NOTICE_LINES, said  # other tests' devices may have had a line
    assert sum(line.startswith("More devices did not accept") for line in said) == 1, said


def test_a_websocket_of_another_subprotocol_is_a_bad_request(tls_up: Up) -> None:
    """Not the broker's fault (502): the page asked for a protocol other than MQTT."""
    up = tls_up
    answer = _request(
        up,
        "/mqtt",
        "Upgrade: websocket",
        "Connection: Upgrade",
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
        "Sec-WebSocket-Version: 13",
        "Sec-WebSocket-Protocol: chat, superchat",
        f"Cookie: feelmysign_key={up.key}",
    )
    assert _status(answer) == 400, answer[:300]
    assert b"subprotocol mqtt" in answer, answer[:300]
