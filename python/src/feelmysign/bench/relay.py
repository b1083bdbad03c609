"""The page's path to the sleeve: publish -> first actuator command over MQTT, over the
broker's WebSocket listener, and through the page server's ``/mqtt`` relay (as a phone on
the LAN sends), against a bare MQTT publish -> receive on the same broker in the same run.
And the page server under idle connections: the time to load the page while 0, 500 and
1,000 idle connections are held, with the process's threads and memory (the page within
200 ms with 500 held, at most 64 threads).

The relay is the page server's own (``feelmysign.webserver``), in a process of its own
as ``feelmysign up`` runs it, with the access key's cookie as the page holds it; its
figure is also given against the broker's own WebSocket listener in the same run, with
its budget; plain WebSocket on loopback, so that the figure is the
relay's, not TLS's. The sleeve is a process of its own, as on the Pi.

The samples are interleaved: each round sends one bare message (to a receiver process of
its own, as in the sleeve group: ``feelmysign.bench.sleeve``) and one stroke by each of the
three senders, in an order that turns by one each round, each once the one before it is
over and a settle has passed. So every path, and the baseline, is measured over the same
minutes, and the relay/listener ratio is the relay's, not the machine's changing load
between one path's hundred strokes and the next's; it comes with the interval that chance
alone gives it (bootstrap over the rounds).
"""

from __future__ import annotations

import http.client
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import paho.mqtt.client as mqtt
from paho.mqtt.enums import CallbackAPIVersion

from feelmysign.bench._mqtt import close
from feelmysign.bench.sleeve import (
    MEDIUM,
    WARM_UP,
    BareReceiver,
    Strokes,
    _client,
    _sleeve_process,
    add_bare_account,
    bare_receiver,
    end_to_end_ms,
    paired_interval,
    percentile,
)
from feelmysign.broker import Broker, Credentials
from feelmysign.topics import strokes_topic
from feelmysign.webserver import KEY_COOKIE, WebServer

IDLE_CONNECTIONS = (0, 500, 1000)
PAGE_LOADS = 20
STROKES = 100
RELAYED_MESSAGES = 3000  # each path, after WARM_UP unmeasured ones: enough for a p99
# The relay against the broker's own WebSocket listener, measured in the same run: what the
# relay adds must stay within the noise of a shared machine. (The aiohttp relay that decoded
# each frame measured 1.22x / 1.28x the bare baseline where the listener measured 1.04x /
# 0.84x; before and after, with the byte relay before aiohttp: docs/research.md.)
RELAY_BUDGET_P50 = 1.10
ACCESS_KEY = "bench-key"


def _websocket_sender(c: Credentials, port: int, path: str, cookie: str = "") -> mqtt.Client:
    """The sender's login over MQTT on WebSockets, as the page's mqtt.js connects."""
    client = mqtt.Client(
        CallbackAPIVersion.VERSION2,
        client_id=f"bench-ws-{uuid.uuid4()}",
        transport="websockets",
    )
    client.ws_set_options(path=path, headers={"Cookie": cookie} if cookie else None)
    client.username_pw_set(c.sender.username, c.sender.password)
    connected = threading.Event()
    client.on_connect = lambda *a: connected.set()
    client.connect("127.0.0.1", port)
    client.loop_start()
    if not connected.wait(10):
        raise TimeoutError(f"no CONNACK over ws://127.0.0.1:{port}{path}")
    return client


def _line(name: str, values: list[float], bare: list[float]) -> str:
    p50, p99 = statistics.median(values), percentile(values, 99)
    return (
        f"  {name:<68} p50 {p50:7.3f} ms   p99 {p99:7.3f} ms   (n={len(values)})"
        f"   {p50 / statistics.median(bare):.2f}x / {p99 / percentile(bare, 99):.2f}x"
        " baseline p50 / p99"
    )


def _against_listener(relayed: list[float], listener: list[float]) -> str:
    """What the relay adds: through it against the broker's own listener, same rounds (the
    i-th sample of each from the same round: pairs for the interval of chance)."""
    p50 = statistics.median(relayed) / statistics.median(listener)
    p99 = percentile(relayed, 99) / percentile(listener, 99)
    low, high = paired_interval(relayed, listener, statistics.median)
    verdict = "within" if p50 <= RELAY_BUDGET_P50 else "OVER"
    return (
        f"  the relay against the broker's WebSocket listener: {p50:.2f}x p50"
        f" (chance: {low:.2f} to {high:.2f}x) / {p99:.2f}x p99"
        f"   ({verdict} the budget of {RELAY_BUDGET_P50:.2f}x p50)"
    )


def _get_page_ms(port: int) -> float:
    started = time.perf_counter()
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    try:
        connection.request("GET", "/")
        response = connection.getresponse()
        response.read()
        if response.status != 200:
            raise RuntimeError(f"the page answered {response.status}")
    finally:
        connection.close()
    return (time.perf_counter() - started) * 1000


def _process_status(field: str) -> int:
    status = Path("/proc/self/status").read_text()
    return int(next(line for line in status.splitlines() if line.startswith(field)).split()[1])


def _idle_lines(site: Path) -> list[str]:
    """The page's load time with idle connections held, and what holding them costs."""
    lines = ["  the page while idle connections are held (aim: within 200 ms, at most 64 threads):"]
    with WebServer(port=0, config={}, directory=site) as server:
        port = int(server.url.rstrip("/").rsplit(":", 1)[1])
        for _ in range(WARM_UP):
            _get_page_ms(port)
        threads, rss_kib = _process_status("Threads:"), _process_status("VmRSS:")
        for idle_count in IDLE_CONNECTIONS:
            idle = [socket.create_connection(("127.0.0.1", port)) for _ in range(idle_count)]
            try:
                time.sleep(0.5)  # the server has taken them all (accepted, a thread each before)
                times = [_get_page_ms(port) for _ in range(PAGE_LOADS)]
                lines.append(
                    f"  page with {idle_count:>4} idle connections held:"
                    f"   p50 {statistics.median(times):7.3f} ms   max {max(times):7.3f} ms"
                    f"   threads +{_process_status('Threads:') - threads}"
                    f"   memory +{(_process_status('VmRSS:') - rss_kib) / 1024:.1f} MiB"
                )
            finally:
                for sock in idle:
                    sock.close()
    return lines


# The page server alone in a process, for its CPU time per relayed message.
_SERVE = """
import sys
from pathlib import Path
from feelmysign.webserver import WebServer
server = WebServer(port=0, config={}, directory=Path(sys.argv[1]), access_key=sys.argv[3],
                   mqtt_ws_port=int(sys.argv[2]))
with server:
    print(server.url, flush=True)
    sys.stdin.read()
"""


def _cpu_s(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@contextmanager
def _page_server_process(c: Credentials, site: Path) -> Iterator[tuple[int, int]]:
    """The page server in a process of its own, as ``feelmysign up`` runs it apart from any
    sender: (its pid, its port). In the bench's own process its loop would wait for the GIL
    behind the bench's MQTT clients, which is not the relay's cost."""
    server = subprocess.Popen(
        [sys.executable, "-c", _SERVE, str(site), str(c.ws_port), ACCESS_KEY],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert server.stdout is not None
        port = int(server.stdout.readline().strip().rstrip("/").rsplit(":", 1)[1])
        yield server.pid, port
    finally:
        server.communicate("", timeout=30)


def _relay_cpu_line(c: Credentials, pid: int, port: int) -> str:
    """The page server's CPU time per message relayed (a QoS 1 publish and its PUBACK:
    one message each way), in a process of its own: the relay's, not the bench's."""
    sender = _websocket_sender(c, port, "/mqtt", f"{KEY_COOKIE}={ACCESS_KEY}")
    topic = strokes_topic("bench-nobody")  # no sleeve listens: only the relay works
    for _ in range(WARM_UP * 20):
        sender.publish(topic, b"warm-up", qos=1).wait_for_publish(10)
    before_s = _cpu_s(pid)
    for _ in range(RELAYED_MESSAGES):
        sender.publish(topic, b"x" * 200, qos=1).wait_for_publish(10)
    per_message_us = (_cpu_s(pid) - before_s) / (2 * RELAYED_MESSAGES) * 1e6
    close(sender)
    return (
        f"  the page server's CPU per relayed MQTT message: {per_message_us:6.1f} us"
        f"   ({RELAYED_MESSAGES} publishes and their PUBACKs)"
    )


BARE = "bare MQTT publish -> receive (a process of its own)"


def interleaved_latencies(
    senders: dict[str, mqtt.Client],
    bare: BareReceiver,
    bare_sender: mqtt.Client,
    strokes: Strokes,
    rounds: int,
) -> dict[str, list[float]]:
    """Each round one bare message (by ``bare_sender``) and one 3 cm stroke by each sender,
    in an order that turns by one each round; after WARM_UP rounds unmeasured. The
    latencies (ms) by sender, and the bare ones under BARE."""

    def bare_one() -> float:
        return bare.latency_ms(bare_sender)

    def stroke_by(sender: mqtt.Client) -> Callable[[], float]:
        return lambda: end_to_end_ms([strokes.latency(MEDIUM, sender)])[0]

    samplers = {BARE: bare_one} | {name: stroke_by(s) for name, s in senders.items()}
    names = list(samplers)
    measured: dict[str, list[float]] = {name: [] for name in names}
    for k in range(WARM_UP + rounds):
        for name in names[k % len(names) :] + names[: k % len(names)]:
            value = samplers[name]()
            if k >= WARM_UP:
                measured[name].append(value)
    return measured


def report() -> list[str]:
    lines = ["Relay (the page's path: real Mosquitto, page server and sleeve process on loopback)"]
    with tempfile.TemporaryDirectory() as state:
        site = Path(state) / "site"
        site.mkdir()
        (site / "index.html").write_text("<!doctype html><title>bench</title>\n")
        account = add_bare_account(Path(state) / "broker")
        with Broker(state_dir=Path(state) / "broker", port=0, ws_port=0) as broker:
            c = broker.credentials
            with (
                _page_server_process(c, site) as (pid, port),
                _sleeve_process(c, broker.credentials_path),
                bare_receiver(c, account) as bare,
            ):
                senders: dict[str, mqtt.Client] = {
                    "over MQTT (TCP)": _client(c, "sender"),
                    "over the broker's WebSocket listener": _websocket_sender(
                        c, c.ws_port, "/mqtt"
                    ),
                    "through the page server's /mqtt relay": _websocket_sender(
                        c, port, "/mqtt", f"{KEY_COOKIE}={ACCESS_KEY}"
                    ),
                }
                strokes = Strokes(c)
                measured = interleaved_latencies(
                    senders, bare, senders["over MQTT (TCP)"], strokes, STROKES
                )
                close(*senders.values())
                strokes.close()
                paired = measured[BARE]
                lines.append(
                    "  one bare message and one stroke by each sender a round, interleaved:"
                )
                lines.append(_line(f"baseline: {BARE}", paired, paired))
                for name in senders:
                    lines.append(
                        _line(f"3 cm {name}: publish -> first command", measured[name], paired)
                    )
                lines.append(
                    _against_listener(
                        measured["through the page server's /mqtt relay"],
                        measured["over the broker's WebSocket listener"],
                    )
                )
                lines.append(_relay_cpu_line(c, pid, port))
        lines += _idle_lines(site)
    return lines


if __name__ == "__main__":  # python -m feelmysign.bench.relay: this group alone
    for line in report():
        print(line, flush=True)
