"""Load: N sleeves and N senders drawing at once, on Mosquitto and on a 3-node NATS cluster.

``python -m feelmysign.bench.load [N ...]`` (``make load``; N = 20 100 200 by default).

For each broker and each N, in one run:

- baseline: N bare receivers (each logged in as its sleeve) and N senders, each
  sender publishing ``STROKES`` strokes to its own sleeve at a hand's pace (QoS 1);
  publish -> receive, p50 and p99, and the messages that never arrived;
- sleeves: N sleeve daemons (the simulator backend, all in this process) and N
  senders drawing the same way; publish -> first actuator command (``sent_at_ms`` of
  the stroke to ``first_command_at_ms`` of its ``played`` event), p50 and p99, and
  the strokes never played.

Every sleeve has its own account, and the ACL (or the NATS permissions) gives each
only its own topics, as ``feelmysign broker add-sleeve`` does. Latencies are wall
clock on one machine; the sleeve figures are reported as a ratio to the baseline of
the same broker and N.
"""

from __future__ import annotations

import contextlib
import json
import logging
import multiprocessing
import resource
import sys
import tempfile
import threading
import time
import uuid
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.backends.sim import SimBackend
from feelmysign.broker import Broker
from feelmysign.broker.credentials import Account, Credentials, reuse_or_create
from feelmysign.broker.nats_cluster import NatsCluster
from feelmysign.broker.sleeves import add_sleeve
from feelmysign.connection import BrokerSettings, new_client, parse_broker_url
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

DEFAULT_COUNTS = (20, 100, 200)
STROKES = 10  # per sender: one short drawing
STROKE_MS = 100.0  # each stroke's duration, and the pause between two (a quick hand)
SETTLE_S = 60.0  # longest wait for the last stroke of a run
CONNECT_S = 120.0  # N logins (and, on NATS, N durable sessions) on a loaded machine


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q / 100 * (len(ordered) - 1)))]


@dataclass(frozen=True)
class Target:
    """A broker under load: where clients connect and the accounts of its N sleeves."""

    name: str
    url: str
    sender: Account
    sleeves: dict[str, Account]

    def settings(self, account: Account, sleeve_id: str = "s0") -> BrokerSettings:
        return parse_broker_url(
            self.url, username=account.username, password=account.password, sleeve_id=sleeve_id
        )


def _ids(count: int) -> list[str]:
    return [f"load{i}" for i in range(count)]


@contextlib.contextmanager
def mosquitto(count: int, state: Path) -> Iterator[Target]:
    ids = _ids(count)
    for sleeve_id in ids[1:]:
        add_sleeve(state / "sleeves.json", sleeve_id)
    with Broker(state_dir=state, port=0, ws_port=0, sleeve_id=ids[0]) as broker:
        c = broker.credentials
        yield Target("Mosquitto", c.mqtt_url, c.sender, _accounts(c, state, ids))


@contextlib.contextmanager
def nats(count: int, state: Path) -> Iterator[Target]:
    ids = _ids(count)
    credentials = reuse_or_create(
        state / "credentials.json", sleeve_id=ids[0], mqtt_url="mqtt://x:1", ws_url="ws://x:2"
    )
    others = {i: add_sleeve(state / "sleeves.json", i) for i in ids[1:]}
    with NatsCluster(state / "nats", credentials, other_sleeves=others) as cluster:
        yield Target(
            "NATS (3 nodes)",
            cluster.mqtt_urls,
            credentials.sender,
            _accounts(credentials, state, ids),
        )


def _accounts(c: Credentials, state: Path, ids: list[str]) -> dict[str, Account]:
    return {ids[0]: c.sleeve} | {i: add_sleeve(state / "sleeves.json", i) for i in ids[1:]}


def _connected(settings: BrokerSettings, client_id: str, on_message: Any = None) -> mqtt.Client:
    client = new_client(settings, client_id=client_id)
    ready = threading.Event()
    client.on_connect = lambda *_args: ready.set()
    if on_message is not None:
        client.on_message = on_message
    client.connect_async(settings.host, settings.port)
    client.loop_start()
    if not ready.wait(CONNECT_S):
        raise TimeoutError(f"{client_id} could not log in to {settings.url}")
    return client


class _Arrivals:
    """Arrival times (wall ms) of payloads, keyed by what the payload names."""

    def __init__(self, key: Callable[[bytes], str | None]) -> None:
        self.at_ms: dict[str, float] = {}
        self._key = key
        self._lock = threading.Lock()

    def __call__(self, _client: Any, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        now_ms = time.time_ns() / 1e6
        key = self._key(bytes(message.payload))
        if key is not None:
            with self._lock:
                self.at_ms.setdefault(key, now_ms)

    def count(self) -> int:
        with self._lock:
            return len(self.at_ms)


def _draw_all(target: Target, senders: list[mqtt.Client], ids: list[str]) -> dict[str, float]:
    """Every sender draws STROKES strokes to its sleeve at once; sent_at (wall ms) by key."""
    sent: dict[str, float] = {}
    lock = threading.Lock()

    def draw(sender: mqtt.Client, sleeve_id: str) -> None:
        drawing = str(uuid.uuid4())
        for seq in range(STROKES):
            stroke = Stroke((0.0, 1.0), (1.0, 1.0), STROKE_MS, 0.5, drawing, seq)
            now_ms = time.time_ns() / 1e6
            stroke = replace(stroke, sent_at_ms=now_ms)
            with lock:
                sent[f"{drawing}/{seq}"] = now_ms
            sender.publish(strokes_topic(sleeve_id), format_json(stroke), qos=1)
            time.sleep(STROKE_MS / 1000)

    threads = [
        threading.Thread(target=draw, args=(sender, sleeve_id))
        for sender, sleeve_id in zip(senders, ids, strict=True)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return sent


def _senders_main(target: Target, ids: list[str], out: Any) -> None:
    """In a process of its own: N sender clients draw at once; their sent_at times to ``out``.

    paho waits on its sockets with select(), which takes descriptors below 1024 only:
    one process holds about 340 clients, so the N senders get a process of their own.
    """
    senders = [
        _connected(target.settings(target.sender), f"sender-{i}-{uuid.uuid4()}")
        for i in range(len(ids))
    ]
    sent = _draw_all(target, senders, ids)
    time.sleep(1.0)  # the last PUBACKs
    for client in senders:
        client.loop_stop()
        client.disconnect()
    out.put(sent)


def _draw_in_process(target: Target, ids: list[str]) -> dict[str, float]:
    context = multiprocessing.get_context("spawn")  # a fresh descriptor table, no threads
    out = context.Queue()
    process = context.Process(target=_senders_main, args=(target, ids, out))
    process.start()
    sent: dict[str, float] = out.get(timeout=CONNECT_S + SETTLE_S)
    process.join(SETTLE_S)
    return sent


def _stroke_key(payload: bytes) -> str | None:
    try:
        data = json.loads(payload)
    except ValueError:
        return None
    return f"{data['drawing']}/{data['seq']}" if "drawing" in data else None


def _outcome(payload: bytes) -> tuple[str, str, float] | None:
    """(stroke key, 'played' or the refusal's reason, first command time or 0) of an event."""
    data = json.loads(payload)
    if "drawing" not in data or "seq" not in data:
        return None
    key = f"{data['drawing']}/{data['seq']}"
    if data.get("type") in ("played", "adjusted"):
        return key, "played", float(data["first_command_at_ms"])
    if data.get("type") == "rejected":
        return key, str(data.get("reason")), 0.0
    return None


def _wait(done: Callable[[], int], total: int) -> None:
    deadline = time.monotonic() + SETTLE_S
    while done() < total and time.monotonic() < deadline:
        time.sleep(0.1)


def baseline(target: Target) -> tuple[list[float], int]:
    """Publish -> receive for N senders to N bare receivers; latencies and messages lost."""
    ids = list(target.sleeves)
    arrivals = _Arrivals(_stroke_key)
    receivers = []
    for sleeve_id in ids:
        settings = target.settings(target.sleeves[sleeve_id], sleeve_id)
        receiver = _connected(settings, f"bare-{sleeve_id}-{uuid.uuid4()}", arrivals)
        receiver.subscribe(strokes_topic(sleeve_id), qos=1)
        receivers.append(receiver)
    time.sleep(1.0)  # SUBACKs: paho has no waiter for them
    sent = _draw_in_process(target, ids)
    _wait(arrivals.count, len(sent))
    latencies = [arrivals.at_ms[k] - sent[k] for k in sent if k in arrivals.at_ms]
    for client in receivers:
        client.loop_stop()
        client.disconnect()
    return latencies, len(sent) - len(latencies)


def sleeves(target: Target) -> tuple[list[float], int, Counter[str]]:
    """Publish -> first actuator command for N sleeve daemons.

    Returns the latencies of the played strokes, the strokes lost (no event at all: never
    reached the sleeve, or vanished), and the refusals by reason: a sleeve that falls
    more than a second behind its sender refuses strokes as ``late`` to return to real
    time, and reports each (the daemon's documented policy), which is not a loss.
    """
    ids = list(target.sleeves)
    played: dict[str, float] = {}
    refused: dict[str, str] = {}
    lock = threading.Lock()

    def on_event(_client: Any, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        found = _outcome(bytes(message.payload))
        if found is not None:
            key, outcome, first_ms = found
            with lock:
                if outcome == "played":
                    played.setdefault(key, first_ms)
                else:
                    refused.setdefault(key, outcome)

    watcher = _connected(target.settings(target.sender), f"watcher-{uuid.uuid4()}", on_event)
    watcher.subscribe(telemetry_topic("+", "events"), qos=1)
    running = [_start_sleeve(target, sleeve_id) for sleeve_id in ids]
    try:
        sent = _draw_in_process(target, ids)
        _wait(lambda: len(played.keys() | refused.keys()), len(sent))
        with lock:
            latencies = [played[k] - sent[k] for k in sent if k in played]
            reasons = Counter(refused[k] for k in sent if k in refused and k not in played)
            lost = sum(1 for k in sent if k not in played and k not in refused)
        watcher.loop_stop()
        watcher.disconnect()
    finally:
        for sleeve, thread, backend in running:
            sleeve.stop()
            thread.join(10)
            backend.close()
    return latencies, lost, reasons


def _start_sleeve(target: Target, sleeve_id: str) -> tuple[Sleeve, threading.Thread, SimBackend]:
    backend = SimBackend(PAPER_SLEEVE)
    options = SleeveOptions(sleeve_id=sleeve_id, legacy_topic=None)
    settings = target.settings(target.sleeves[sleeve_id], sleeve_id)
    sleeve = Sleeve(settings, PAPER_SLEEVE, backend, options)
    thread = threading.Thread(target=sleeve.run, daemon=True)
    thread.start()
    if not sleeve.connected.wait(CONNECT_S):
        raise TimeoutError(f"sleeve {sleeve_id} did not connect to {target.url}")
    return sleeve, thread, backend


def _line(
    what: str,
    latencies: list[float],
    lost: int,
    base_p99: float | None,
    refused: Counter[str] | None = None,
) -> str:
    if not latencies:
        return f"  {what:<30} nothing arrived ({lost} lost)"
    p50, p99 = percentile(latencies, 50), percentile(latencies, 99)
    ratio = f", p99 {p99 / base_p99:.2f}x baseline" if base_p99 else ""
    out = f", refused {dict(refused)}" if refused else ""
    return (
        f"  {what:<30} {len(latencies)} arrived: p50 {p50:7.1f} ms, p99 {p99:7.1f} ms"
        f"{ratio}; lost {lost}{out}"
    )


def report(counts: tuple[int, ...] = DEFAULT_COUNTS) -> list[str]:
    lines = [
        f"Load: N sleeves and N senders drawing at once ({STROKES} strokes of {STROKE_MS:g} ms "
        "each per sender, QoS 1); publish -> received (bare) and publish -> played (sleeve)"
    ]
    for start in (mosquitto, nats):
        for count in counts:
            with tempfile.TemporaryDirectory() as state, start(count, Path(state)) as target:
                base, base_lost = baseline(target)
                played, lost, refused = sleeves(target)
            base_p99 = percentile(base, 99) if base else None
            lines.append(f"{target.name}, N = {count}")
            lines.append(_line("bare publish -> receive", base, base_lost, None))
            lines.append(_line("publish -> played (sleeve)", played, lost, base_p99, refused))
            print("\n".join(lines[-3:]), flush=True)
    return lines


def main(argv: list[str]) -> None:
    counts = tuple(int(a) for a in argv) or DEFAULT_COUNTS
    # Each paho client holds a socket and a wake-up pair: 3 N clients need more than the
    # usual 1024 descriptors. Raised to the hard limit, as a broker's service would be.
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, hard), hard))
    # The sleeves' own log lines (a stroke played late, ...) would bury the figures.
    logging.getLogger("feelmysign").setLevel(logging.ERROR)
    report(counts)


if __name__ == "__main__":
    main(sys.argv[1:])
