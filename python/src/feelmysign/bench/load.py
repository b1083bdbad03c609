"""Load: N sleeves and N senders drawing at once, on Mosquitto and on a 3-node NATS cluster.

``python -m feelmysign.bench.load [N ...]`` (``make load``, or ``make load N='20 100'``;
N = 20 100 200 by default, each 1 to 1000).

For each broker and each N, in one run, on a broker started anew:

- baseline: N bare receivers (each logged in as its sleeve) and N senders, each
  sender publishing ``STROKES`` strokes to its own sleeve at a hand's pace (QoS 1);
  publish -> receive, p50 and p99, and the messages that never arrived;
- sleeves: N sleeve daemons (the simulator backend) and N senders drawing the same
  way; publish -> first actuator command (``sent_at_ms`` of the stroke to
  ``first_command_at_ms`` of its ``played`` event), p50 and p99, as ratios to the
  baseline; every stroke's outcome: played, refused (by reason: the sleeve reports
  each), played twice, or lost (neither played nor reported).

Sleeves, senders and receivers run in worker processes of ``load_hosts.PER_PROCESS``
clients each (``load_hosts``), so the figures measure the broker path rather than one
Python process. On the cluster, client i starts on server i mod 3 (its sender on the
next one), and has the others to fail over to. Every sleeve has its own account, and
the ACL (or the NATS permissions) gives each only its own topics, as ``feelmysign
broker add-sleeve`` does. Latencies are wall clock on one machine.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import queue
import resource
import sys
import tempfile
import threading
import time
import uuid
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.bench import load_hosts
from feelmysign.bench.load_hosts import PER_PROCESS, PUBACK_S, STROKE_MS, STROKES, stroke_key
from feelmysign.broker import Broker
from feelmysign.broker.credentials import Account, Credentials, reuse_or_create
from feelmysign.broker.nats_cluster import NatsCluster
from feelmysign.broker.sleeves import add_sleeve
from feelmysign.cli.options.parser import CliParser
from feelmysign.cli.options.values import whole_number
from feelmysign.connection import new_client, parse_broker_url
from feelmysign.events import Cancelled, EventError, Played, Rejected, Safety, event_from_json
from feelmysign.player import SPIN_MS
from feelmysign.topics import telemetry_topic

DEFAULT_COUNTS = (20, 100, 200)
# Each N is 3 N clients and 2 N worker-process threads on one machine: beyond this the
# figures measure the machine's limits, not the broker path.
MAX_COUNT = 1000
# A sleeve refuses, and reports, a stroke it would play more than 1 s behind its sender
# (or 10 s after it was sent). When the sleeves did, the run is repeated with room for a
# minute, as a cluster's sleeves may run (docs/deploy.md): is every stroke played then?
OUT_OF_TIME = {"late", "stale"}
RELAXED_PACE = (120_000.0, 60_000.0)  # max_age_ms, max_lag_ms
# A sleeve busy-waits the last SPIN_MS before each motor command, for sub-millisecond timing
# on a Pi of its own. N sleeves on 2 cores cannot all spin: at N = 100 on Mosquitto,
# without it their processor time fell from 1.1 to 0.9-1.1 ms a stroke and publish ->
# played from 2.0-7.5x the baseline's p50 to 1.5-1.9x (two runs each). Their commands
# then go out a few tenths of a millisecond later than planned: nothing beside these
# latencies.
SLEEVE_SPIN_MS = 0.0
SETTLE_S = 60.0  # longest wait for the last stroke of a run, once all were sent
START_S = 240.0  # longest wait for a kind of host to have all its clients logged in


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q / 100 * (len(ordered) - 1)))]


@dataclass(frozen=True)
class Target:
    """A broker under load: its servers, the sender's account and the accounts of N sleeves."""

    name: str
    urls: tuple[str, ...]
    sender: Account
    sleeves: dict[str, Account]

    def url_for(self, index: int) -> str:
        """Client ``index``'s servers, comma separated, starting at server index mod count."""
        first = index % len(self.urls)
        return ",".join(self.urls[first:] + self.urls[:first])


def _ids(count: int) -> list[str]:
    return [f"load{i}" for i in range(count)]


@contextlib.contextmanager
def mosquitto(count: int, state: Path) -> Iterator[Target]:
    ids = _ids(count)
    for sleeve_id in ids[1:]:
        add_sleeve(state / "sleeves.json", sleeve_id)
    with Broker(state_dir=state, port=0, ws_port=0, sleeve_id=ids[0]) as broker:
        c = broker.credentials
        yield Target("Mosquitto", (c.mqtt_url,), c.sender, _accounts(c, state, ids))


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
            tuple(node.mqtt_url for node in cluster.nodes),
            credentials.sender,
            _accounts(credentials, state, ids),
        )


def _accounts(c: Credentials, state: Path, ids: list[str]) -> dict[str, Account]:
    return {ids[0]: c.sleeve} | {i: add_sleeve(state / "sleeves.json", i) for i in ids[1:]}


class _Hosts:
    """Worker processes of one kind (``load_hosts``), each with a share of the clients."""

    def __init__(self, what: str) -> None:
        self.what = what
        self._context = multiprocessing.get_context("spawn")  # no inherited threads, sockets
        self.reports: Any = self._context.Queue()
        self.flag: Any = self._context.Event()  # "stop" or "go", by kind
        self._processes: list[Any] = []

    def start(self, function: Callable[..., None], shares: list[tuple[Any, ...]]) -> None:
        for args in shares:
            process = self._context.Process(
                target=function, args=(*args, self.reports, self.flag), daemon=True
            )
            process.start()
            self._processes.append(process)
        self.expect("ready", len(self._processes), START_S)

    def expect(self, kind: str, count: int, timeout_s: float) -> list[tuple[Any, ...]]:
        """``count`` reports of ``kind``; RuntimeError with a host's own error if one fails."""
        found: list[tuple[Any, ...]] = []
        deadline = time.monotonic() + timeout_s
        while len(found) < count:
            try:
                report = self.reports.get(timeout=max(0.1, deadline - time.monotonic()))
            except queue.Empty:
                raise RuntimeError(
                    f"{count - len(found)} {self.what} processes did not report {kind!r} "
                    f"within {timeout_s:g} s"
                ) from None
            if report[0] == "error":
                raise RuntimeError(f"a {self.what} process failed: {report[1]}")
            if report[0] == kind:
                found.append(report)
            else:
                self.other(report)
        return found

    def other(self, report: tuple[Any, ...]) -> None:
        """A report of another kind than expected (receivers: arrivals while starting)."""

    def stop(self, report: str | None = None) -> list[tuple[Any, ...]]:
        """Stop every process, and collect its last ``report`` when one is named."""
        self.flag.set()
        found = []
        if report is not None:
            with contextlib.suppress(RuntimeError):
                found = self.expect(report, len(self._processes), 60.0)
        for process in self._processes:
            process.join(30)
            if process.is_alive():
                process.kill()
                process.join()
        self._processes = []
        return found


def _shares(target: Target, offset: int) -> list[tuple[list[str], list[tuple[str, Account]]]]:
    """(server lists, [(sleeve id, account)]) per process, ``PER_PROCESS`` clients each."""
    items = list(target.sleeves.items())
    return [
        (
            [target.url_for(i + offset) for i in range(start, start + len(chunk))],
            chunk,
        )
        for start in range(0, len(items), PER_PROCESS)
        for chunk in [items[start : start + PER_PROCESS]]
    ]


def _draw(target: Target) -> tuple[dict[str, float], set[str]]:
    """N senders (in processes) draw at once: sent_at (wall ms), and what the broker never
    acknowledged."""
    senders = _Hosts("sender")
    shares = [
        (urls, target.sender, [sleeve_id for sleeve_id, _ in chunk])
        for urls, chunk in _shares(target, offset=1)
    ]
    try:
        senders.start(load_hosts.sender_host, shares)
        senders.flag.set()  # go
        drawing_s = STROKES * STROKE_MS / 1000
        reports = senders.expect("sent", len(shares), drawing_s + PUBACK_S + 30)
    finally:
        senders.stop()
    sent: dict[str, float] = {}
    unacknowledged: set[str] = set()
    for _kind, times, missing in reports:
        sent |= times
        unacknowledged |= set(missing)
    return sent, unacknowledged


def _wait(done: Callable[[], int], total: int, poll: Callable[[], None] = lambda: None) -> None:
    deadline = time.monotonic() + SETTLE_S
    while done() < total and time.monotonic() < deadline:
        poll()
        time.sleep(0.1)


@dataclass
class Outcome:
    """What became of every stroke of a run."""

    latencies_ms: list[float]
    sent: int
    lost: int  # neither played nor reported: the one thing that must never happen
    unacknowledged: int = 0  # publishes the broker never acknowledged to the sender
    refused: Counter[str] = field(default_factory=Counter)  # reported, by reason
    twice: int = 0  # strokes played more than once
    cpu_s: float = 0.0  # processor time the sleeves used, all of them together


class _Receivers(_Hosts):
    def __init__(self) -> None:
        super().__init__("receiver")
        self.arrived: dict[str, float] = {}

    def other(self, report: tuple[Any, ...]) -> None:
        if report[0] == "arrived":
            for key, at_ms in report[1].items():
                self.arrived.setdefault(key, at_ms)

    def poll(self) -> None:
        with contextlib.suppress(queue.Empty):
            while True:
                self.other(self.reports.get_nowait())


def baseline(target: Target) -> Outcome:
    """Publish -> receive for N senders to N bare receivers."""
    receivers = _Receivers()
    try:
        receivers.start(load_hosts.receiver_host, _shares(target, offset=0))
        sent, unacknowledged = _draw(target)
        _wait(lambda: len(receivers.arrived.keys() & sent.keys()), len(sent), receivers.poll)
    finally:
        receivers.stop()
    receivers.poll()
    arrived = receivers.arrived
    latencies = [arrived[k] - sent[k] for k in sent if k in arrived]
    return Outcome(latencies, len(sent), len(sent) - len(latencies), len(unacknowledged))


class _Watcher:
    """The sleeves' events, as the sender's account sees them: each stroke's outcome."""

    def __init__(self, target: Target) -> None:
        self.played: dict[str, set[bytes]] = {}
        self.first_command_ms: dict[str, float] = {}
        self.refused: dict[str, str] = {}
        self._lock = threading.Lock()
        settings = parse_broker_url(
            target.url_for(0), username=target.sender.username, password=target.sender.password
        )
        self.client = new_client(settings, client_id=f"watcher-{uuid.uuid4()}")
        subscribed = threading.Event()
        self.client.on_connect = lambda c, *_args: c.subscribe(
            telemetry_topic("+", "events"), qos=1
        )
        self.client.on_subscribe = lambda *_args: subscribed.set()
        self.client.on_message = self._on_message
        self.client.connect_async(settings.host, settings.port)
        self.client.loop_start()
        if not subscribed.wait(START_S):
            raise RuntimeError(f"the events watcher could not subscribe on {settings.url}")

    def _on_message(self, _client: Any, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        payload = bytes(message.payload)
        key = stroke_key(payload)
        if key is None:
            return
        try:
            event = event_from_json(payload)
        except EventError:
            return  # not a sleeve event: its stroke stays unsettled, and is counted lost
        with self._lock:
            if isinstance(event, Played):  # adjusted ones too
                self.played.setdefault(key, set()).add(payload)
                self.first_command_ms.setdefault(key, float(event.first_command_at_ms))
            elif isinstance(event, Rejected | Cancelled | Safety):
                self.refused.setdefault(key, event.reason)

    def settled(self, keys: dict[str, float]) -> int:
        with self._lock:
            return len((self.played.keys() | self.refused.keys()) & keys.keys())

    def outcome(self, sent: dict[str, float], unacknowledged: set[str]) -> Outcome:
        with self._lock:
            latencies = [self.first_command_ms[k] - sent[k] for k in sent if k in self.played]
            refused = Counter(
                self.refused[k] for k in sent if k in self.refused and k not in self.played
            )
            lost = sum(1 for k in sent if k not in self.played and k not in self.refused)
            twice = sum(1 for k in sent if len(self.played.get(k, ())) > 1)
        return Outcome(latencies, len(sent), lost, len(unacknowledged), refused, twice)

    def close(self) -> None:
        self.client.loop_stop()
        self.client.disconnect()


def sleeves(
    target: Target, pace: tuple[float, float] | None = None, *, spin_ms: float = SLEEVE_SPIN_MS
) -> Outcome:
    """Publish -> first actuator command for N sleeve daemons, and every stroke's outcome.

    ``pace``: the sleeves' (max_age_ms, max_lag_ms), instead of their defaults.
    """
    hosts = _Hosts("sleeve")
    watcher: _Watcher | None = None
    tuning = {"spin_ms": spin_ms}
    if pace is not None:
        tuning |= {"max_age_ms": pace[0], "max_lag_ms": pace[1]}
    try:
        shares = [(urls, chunk, tuning) for urls, chunk in _shares(target, offset=0)]
        hosts.start(load_hosts.sleeve_host, shares)
        watcher = _Watcher(target)
        sent, unacknowledged = _draw(target)
        _wait(lambda: watcher.settled(sent) if watcher else 0, len(sent))
        outcome = watcher.outcome(sent, unacknowledged)
    finally:
        if watcher is not None:
            watcher.close()
        cpu = hosts.stop("cpu")
    return replace(outcome, cpu_s=sum(seconds for _kind, seconds in cpu))


def _line(what: str, outcome: Outcome, base: Outcome | None) -> str:
    if not outcome.latencies_ms:
        return f"  {what:<28} nothing arrived of {outcome.sent} ({outcome.lost} lost)"
    p50 = percentile(outcome.latencies_ms, 50)
    p99 = percentile(outcome.latencies_ms, 99)
    text = f"  {what:<28} p50 {p50:7.1f} ms"
    if base is not None and base.latencies_ms:
        text += f" ({p50 / percentile(base.latencies_ms, 50):5.1f}x)"
    text += f", p99 {p99:7.1f} ms"
    if base is not None and base.latencies_ms:
        text += f" ({p99 / percentile(base.latencies_ms, 99):5.1f}x)"
    counted = "played" if base is not None else "received"
    text += f"; {counted} {len(outcome.latencies_ms)}/{outcome.sent}, lost {outcome.lost}"
    if outcome.refused:
        text += ", refused " + ", ".join(f"{n} {r}" for r, n in sorted(outcome.refused.items()))
    if base is not None:
        text += f", played twice {outcome.twice}"
    if outcome.unacknowledged:
        text += f", not acknowledged by the broker {outcome.unacknowledged}"
    if outcome.cpu_s:
        text += f"; sleeves' CPU {1000 * outcome.cpu_s / outcome.sent:.1f} ms a stroke"
    return text


def report(counts: tuple[int, ...] = DEFAULT_COUNTS) -> list[str]:
    lines = [
        f"Load: N sleeves and N senders drawing at once ({STROKES} strokes of {STROKE_MS:g} ms "
        f"per sender, QoS 1; {PER_PROCESS} clients per process; sleeves without the "
        f"{SPIN_MS:g} ms busy-wait) on {os.cpu_count()} cores, "
        f"load average {os.getloadavg()[0]:.1f} at the start. Ratios: to the bare "
        "publish -> receive of the same broker and N, this run"
    ]
    print(lines[0], flush=True)
    began_s = time.monotonic()
    for start in (mosquitto, nats):
        for count in counts:
            run_s = time.monotonic()
            relaxed = None
            with tempfile.TemporaryDirectory() as state, start(count, Path(state)) as target:
                base = baseline(target)
                played = sleeves(target)
                if played.refused.keys() & OUT_OF_TIME:
                    relaxed = sleeves(target, RELAXED_PACE)
            lines.append(
                f"{target.name}, N = {count}: {played.sent} strokes "
                f"(load average {os.getloadavg()[0]:.1f}; {time.monotonic() - run_s:.0f} s)"
            )
            lines.append(_line("bare publish -> receive", base, None))
            lines.append(_line("publish -> played (sleeve)", played, base))
            if relaxed is not None:
                lines.append(_line("  the same, late allowed", relaxed, base))
            print("\n".join(lines[-4 if relaxed else -3 :]), flush=True)
    lines.append(f"({time.monotonic() - began_s:.0f} s in all)")
    print(lines[-1], flush=True)
    return lines


def parse_counts(argv: list[str]) -> tuple[int, ...]:
    """The N of each run, from the command line; one ``Error:`` line and exit 2 if bad."""
    parser = CliParser(
        prog="python -m feelmysign.bench.load",
        description="N sleeves and N senders drawing at once, on Mosquitto and on a 3-node "
        "NATS cluster (make load N='20 100').",
    )
    parser.add_argument(
        "counts",
        nargs="*",
        type=whole_number(1, MAX_COUNT),
        metavar="N",
        help=f"sleeves (and senders) at once, 1 to {MAX_COUNT}; default "
        + " ".join(map(str, DEFAULT_COUNTS)),
    )
    return tuple(parser.parse_args(argv).counts) or DEFAULT_COUNTS


def main(argv: list[str]) -> None:
    counts = parse_counts(argv)
    # Each paho client holds a socket and a wake-up pair; a broker under load holds
    # thousands: raised to the hard limit, as a broker's service would be.
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, hard), hard))
    logging.getLogger("feelmysign").setLevel(logging.ERROR)
    report(counts)


if __name__ == "__main__":
    main(sys.argv[1:])
