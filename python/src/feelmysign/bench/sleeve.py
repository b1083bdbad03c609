"""Sleeve latency, timing and continuity, against a real Mosquitto on loopback, in one run.

Measured: publish -> the sleeve's first actuator command (from its ``played`` events),
the sleeve's own share (receive -> first command), the lateness of every actuator write
against the plan, and the gap between consecutive strokes of a drawing, for strokes of 1, 3,
10 and 30 cm (the share at each length: the sleeve starts a stroke's first burst before
planning the rest).

Baseline, paired with the strokes: a bare MQTT publish -> receive on the same broker (QoS 1,
the same sender client), whose receiver is a process of its own as the sleeve is (an idle
paho client woken by the message, TCP_NODELAY as every client of ours), logged in as a
second sleeve's account added to the broker for it, so that it runs beside the real sleeve
process. It stamps each receipt's wall time as the message arrives and prints it on its
standard output; the bench waits for that line (its own wake-up is not counted) and takes
the time from it. At each length the bare messages and the strokes alternate, one of each
in turn, so that each ratio (p99 of the strokes over p99 of their own bare messages)
compares the same minutes of a shared machine: its load, caches and neighbours then weigh
on both. Pairing takes out what drifts between minutes, not what strikes one sample: a
p99 of 100 samples is the second highest, so each ratio comes with the interval that
chance alone gives it (bootstrap over the pairs), and with the p50 ratio. The former
baseline, 100 bare messages to a receiver in this (warm) process once before the strokes,
is still printed, and each p99 ratio against it too, to show what the pairing changes.

Only a stroke's first command counts for latency, so each measured stroke is
cancelled (the control message) once its ``played`` event is out, instead of
being played to its end: the sleeve receives, checks and plans it as any other
stroke, and its first command takes the same path; only the motors it would have
driven later are switched off early. The next message (a bare one) is sent once the sleeve
has reported it cancelled and a short settle has passed, and the next stroke once that bare
message is received and acknowledged and the same settle has passed (an idle sleeve, as an
idle broker and receiver). The gaps between strokes of a drawing need real back-to-back
play, so those strokes play out.
"""

from __future__ import annotations

import itertools
import json
import math
import queue
import random
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar

import paho.mqtt.client as mqtt

from feelmysign.backends.sim import SimBackend
from feelmysign.bench._mqtt import close
from feelmysign.broker import Account, Broker, Credentials
from feelmysign.broker.sleeves import add_sleeve
from feelmysign.connection import BrokerSettings, new_client
from feelmysign.control import Cancel, format_control
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.events import Cancelled, Event, Played, event_from_json
from feelmysign.layout import Layout
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import control_topic, strokes_topic, telemetry_topic

_E = TypeVar("_E", bound=Event)

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
# 1 cm and 10 cm on the paper's 3 cm grid.
SHORT = ((1.0, 1.0), (1.0 + 1 / 3, 1.0), 120.0)
MEDIUM = ((1.0, 1.0), (2.0, 1.0), 300.0)  # 3 cm: one actuator to the next
LONG = ((0.0, 0.0), (3.0, math.sqrt((10 / 3) ** 2 - 9.0)), 900.0)
# 30 cm does not fit the paper's sleeve (9 x 6 cm): along a sleeve of 12 columns, 33 cm.
WIDE_GRID = ("--rows", "3", "--columns", "12", "--spacing-cm", "3")
LONGEST = ((0.5, 1.0), (10.5, 1.0), 1500.0)
# (label, stroke, how many, grid options of the sleeve process): the sleeve's share at each.
# Enough strokes at each for a p99 (each is cancelled after its first command: see above).
LENGTHS = (
    ("1 cm", SHORT, 100, ()),
    ("3 cm", MEDIUM, 100, ()),
    ("10 cm", LONG, 100, ()),
    ("30 cm", LONGEST, 100, WIDE_GRID),
)
# Every measured publish goes to an idle sleeve and broker: after what says the last one is
# over (the stroke reported cancelled; the baseline's message received and acknowledged),
# this long more, the same for both, so that the threads that handled it are asleep again.
# Back to back they are not, and the figures move (a bare message: 8.7 ms p50 at once, 1.5 ms
# 120 ms later, load average 7). Against 120 ms, in one sitting (200 of each, interleaved,
# load average 11): bare p50 1.30 / 1.96 ms, 3 cm stroke p50 1.43 / 1.53 ms; no rise at 50.
SETTLE_S = 0.05
WARM_UP = 5  # strokes first, unmeasured: first-use costs are not latency
# Strokes of the drawings played back to back (for the gaps between them and the lateness of
# writes): these play out, so the longer ones are fewer.
DRAWING_STROKES = {"1 cm": 20, "3 cm": 20, "10 cm": 10}
# The paired baseline's receiver logs in as a second sleeve, this one (see the docstring).
BARE_SLEEVE_ID = "bench-bare"


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q / 100 * (len(ordered) - 1)))]


def p99(values: Sequence[float]) -> float:
    return percentile(list(values), 99)


def paired_interval(
    measured: Sequence[float],
    baseline: Sequence[float],
    statistic: Callable[[Sequence[float]], float],
    *,
    resamples: int = 1000,
    seed: int = 0,
) -> tuple[float, float]:
    """How far chance alone moves ``statistic(measured) / statistic(baseline)``: the 5th and
    95th percentiles of the ratio over bootstrap resamples of the pairs (the i-th measured
    sample goes with the i-th of the baseline, taken in the same minutes). A p99 of 100
    samples is their second highest, so one or two disturbed samples decide it; the interval
    says when they do."""
    if len(measured) != len(baseline) or not measured:
        raise ValueError("paired samples: as many of each, at least one")
    rng = random.Random(seed)
    n = len(measured)
    ratios = []
    for _ in range(resamples):
        picks = [rng.randrange(n) for _ in range(n)]
        ratios.append(
            statistic([measured[i] for i in picks]) / statistic([baseline[i] for i in picks])
        )
    ratios.sort()
    return ratios[round(0.05 * (resamples - 1))], ratios[round(0.95 * (resamples - 1))]


def _settings(c: Credentials, role: str) -> BrokerSettings:
    return c.settings("sleeve" if role == "sleeve" else "sender")


class _Inbox:
    """Messages of a subscription, waited for one at a time."""

    def __init__(self) -> None:
        self.items: list[tuple[float, bytes]] = []
        self.cond = threading.Condition()

    def __call__(self, client: mqtt.Client, userdata: Any, message: mqtt.MQTTMessage) -> None:
        with self.cond:
            self.items.append((time.time_ns() / 1e6, bytes(message.payload)))
            self.cond.notify_all()

    def wait_played(self, count: int, timeout_s: float = 30.0) -> list[Played]:
        """The first ``count`` played (or adjusted) events; safety events and others skipped."""

        def played() -> list[Played]:
            events = (event_from_json(payload) for _, payload in self.items)
            return [e for e in events if isinstance(e, Played)]

        with self.cond:
            if not self.cond.wait_for(lambda: len(played()) >= count, timeout_s):
                raise TimeoutError(f"{len(played())} of {count} strokes were played")
            return played()[:count]

    def wait_event(self, kind: type[_E], drawing: str, timeout_s: float) -> _E | None:
        """The first event of class ``kind`` about a stroke of ``drawing``; None if none came."""

        def found() -> _E | None:
            for _, payload in self.items:
                event = event_from_json(payload)
                if isinstance(event, kind) and getattr(event, "drawing", None) == drawing:
                    return event
            return None

        with self.cond:
            self.cond.wait_for(lambda: found() is not None, timeout_s)
            return found()

    def wait(self, count: int, timeout_s: float = 30.0) -> list[tuple[float, bytes]]:
        with self.cond:
            if not self.cond.wait_for(lambda: len(self.items) >= count, timeout_s):
                raise TimeoutError(f"{len(self.items)} of {count} messages arrived")
            return list(self.items)


def _client(
    c: Credentials, role: str, inbox: _Inbox | None = None, subscribe: str = ""
) -> mqtt.Client:
    client = new_client(_settings(c, role), client_id=f"bench-{role}-{uuid.uuid4()}")
    connected = threading.Event()
    subscribed = threading.Event()
    client.on_connect = lambda *a: connected.set()
    client.on_subscribe = lambda *a: subscribed.set()
    if inbox is not None:
        client.on_message = inbox
    client.connect(c.mqtt_host, c.mqtt_port)
    client.loop_start()
    connected.wait(10)
    if subscribe:
        client.subscribe(subscribe, qos=1)
        if not subscribed.wait(10):
            raise TimeoutError(f"no SUBACK for {subscribe}")
    return client


def bare_latency_ms(c: Credentials, count: int = 100, settle_s: float = SETTLE_S) -> list[float]:
    """Publish -> receive on the same broker, sender to sleeve account, QoS 1.

    Paced like the strokes measured against it: each message once the one before
    is received and acknowledged, and ``settle_s`` more (see SETTLE_S).
    """
    inbox = _Inbox()
    receiver = _client(c, "sleeve", inbox, strokes_topic(c.sleeve_id))
    sender = _client(c, "sender")
    sent: list[float] = []
    for k in range(count):
        sent.append(time.time_ns() / 1e6)
        info = sender.publish(strokes_topic(c.sleeve_id), b"bench", qos=1)
        inbox.wait(k + 1)
        info.wait_for_publish(10)  # the broker's PUBACK: it is done with this message
        time.sleep(settle_s)
    received = inbox.wait(count)
    close(receiver, sender)
    return [r - s for (r, _), s in zip(received, sent, strict=True)]


@contextmanager
def _sleeve(c: Credentials) -> Iterator[Sleeve]:
    backend = SimBackend(PAPER)
    options = SleeveOptions(sleeve_id=c.sleeve_id, rate_per_s=1e6, burst=10**6)
    sleeve = Sleeve(_settings(c, "sleeve"), PAPER, backend, options)
    thread = threading.Thread(target=sleeve.run, daemon=True)
    thread.start()
    sleeve.connected.wait(10)
    try:
        yield sleeve
    finally:
        sleeve.stop()
        thread.join(10)
        backend.close()


class Strokes:
    """Strokes to an idle sleeve, one at a time, each with the sleeve's played event.

    Each stroke (a drawing of its own) is cancelled once its played event is out, i.e. after
    its first command; :meth:`latency` returns once the sleeve reports it cancelled and
    SETTLE_S more have passed. One watcher of the sleeve's events serves every sender.
    """

    def __init__(self, c: Credentials) -> None:
        self._c = c
        self._inbox = _Inbox()
        self._watcher = _client(c, "sender", self._inbox, telemetry_topic(c.sleeve_id, "events"))

    def latency(self, shape: Any, sender: mqtt.Client) -> tuple[float, Played]:
        """Publish one stroke with ``sender``: its publish time (ms) and its played event."""
        (start, end, duration_ms) = shape
        drawing = f"lat-{uuid.uuid4()}"
        stroke = Stroke(start, end, duration_ms, None, drawing, 0)
        # Made before the clock is read, as a bare message's payload is: the sender's JSON
        # is not the sleeve's latency (formatted after it, 0.1 ms of the 0.8 ms p50 at 1 cm).
        topic, payload = strokes_topic(self._c.sleeve_id), format_json(stroke)
        inbox = self._inbox
        with inbox.cond:
            inbox.items.clear()  # the earlier strokes' events: each wait reads them all again
        published_ms = time.time_ns() / 1e6
        sender.publish(topic, payload, qos=1)
        event = inbox.wait_played(1)[-1]
        if event.drawing != drawing:
            raise RuntimeError(f"expected a played event of {drawing}, got {event}")
        sender.publish(control_topic(self._c.sleeve_id), format_control(Cancel(drawing)), qos=1)
        # Its motors are off once it is reported cancelled; a stroke that ended before the
        # cancel came is not reported: wait no longer than its end. Then the settle.
        end_ms = event.first_command_at_ms + event.duration_ms + 100.0
        inbox.wait_event(Cancelled, drawing, max(0.0, end_ms - time.time_ns() / 1e6) / 1000)
        time.sleep(SETTLE_S)
        return published_ms, event

    def close(self) -> None:
        close(self._watcher)


def end_to_end_ms(events: list[tuple[float, Played]]) -> list[float]:
    """Publish -> first actuator command of each (publish time, played event)."""
    return [e.first_command_at_ms - published_ms for published_ms, e in events]


def add_bare_account(state_dir: Path) -> Account:
    """The paired baseline receiver's account: a second sleeve in ``state_dir``'s
    ``sleeves.json``, so that the broker's ACL lets it read that sleeve's strokes. Before the
    broker starts: it renders its ACL and password file from the state directory then."""
    state_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
    return add_sleeve(state_dir / "sleeves.json", BARE_SLEEVE_ID)


# The paired baseline's receiver: an idle paho client in a process of its own, as the sleeve
# is, woken by each message on its network thread. Its login comes on standard input (one
# JSON line); it prints "subscribed", then each message's payload and the wall time of its
# receipt (ns), one line each, and logs out when its standard input is closed.
_RECEIVE = """
import json, sys, time
from feelmysign.connection import BrokerSettings, new_client
from feelmysign.topics import strokes_topic
login = json.loads(sys.stdin.readline())
settings = BrokerSettings(**login)
client = new_client(settings, client_id="bench-bare-" + settings.sleeve_id)

def on_message(client, userdata, message):
    received_ns = time.time_ns()
    print(message.payload.decode(), received_ns, flush=True)

client.on_connect = lambda c, *a: c.subscribe(strokes_topic(settings.sleeve_id), qos=1)
client.on_subscribe = lambda *a: print("subscribed", flush=True)
client.on_message = on_message
client.connect(settings.host, settings.port)
client.loop_start()
sys.stdin.read()
client.disconnect()
client.loop_stop()
"""


class BareReceiver:
    """Bare publish -> receive, to the receiver process of ``_RECEIVE``."""

    def __init__(self, process: subprocess.Popen[str], sleeve_id: str) -> None:
        self._process = process
        self._topic = strokes_topic(sleeve_id)
        self._lines: queue.Queue[str] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        line = self._lines.get(timeout=20)
        if line != "subscribed":
            raise RuntimeError(f"the bare receiver said {line!r}")

    def _read(self) -> None:
        assert self._process.stdout is not None
        for line in self._process.stdout:
            self._lines.put(line.strip())
        self._lines.put("(its output ended)")

    def latency_ms(self, sender: mqtt.Client) -> float:
        """One message (QoS 1) with ``sender``: publish -> receive, by the receiver's clock.

        Returns once it is received and acknowledged (the broker's PUBACK: it is done with
        it) and SETTLE_S more have passed, as a stroke's (see SETTLE_S).
        """
        tag = f"bare-{uuid.uuid4()}"
        data = tag.encode()  # before the clock is read, as a stroke's payload
        sent_ns = time.time_ns()
        info = sender.publish(self._topic, data, qos=1)
        line = self._lines.get(timeout=10)
        info.wait_for_publish(10)
        payload, received_ns = line.split()
        if payload != tag:
            raise RuntimeError(f"the bare receiver got {payload}, not {tag}")
        time.sleep(SETTLE_S)
        return (int(received_ns) - sent_ns) / 1e6


@contextmanager
def bare_receiver(c: Credentials, account: Account) -> Iterator[BareReceiver]:
    """The paired baseline's receiver, a process of its own, logged in with ``account``
    (from :func:`add_bare_account`)."""
    login = {
        "host": c.mqtt_host,
        "port": c.mqtt_port,
        "username": account.username,
        "password": account.password,
        "sleeve_id": BARE_SLEEVE_ID,
    }
    process = subprocess.Popen(
        [sys.executable, "-c", _RECEIVE],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stdin is not None
        process.stdin.write(json.dumps(login) + "\n")
        process.stdin.flush()
        yield BareReceiver(process, BARE_SLEEVE_ID)
    finally:
        assert process.stdin is not None
        process.stdin.close()  # it logs out and ends
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def sleeve_command(credentials_path: Path, *extra: str) -> list[str]:
    """``feelmysign sleeve`` as its own process, logged in with ``credentials_path``."""
    return [
        sys.executable,
        "-m",
        "feelmysign",
        "sleeve",
        "--credentials",
        str(credentials_path),
        *extra,
    ]


@contextmanager
def _sleeve_process(
    c: Credentials, credentials_path: Path, grid: tuple[str, ...] = ()
) -> Iterator[None]:
    """``feelmysign sleeve`` in a process of its own, as on the Pi, online."""
    inbox = _Inbox()
    watcher = _client(c, "sender", inbox, telemetry_topic(c.sleeve_id, "status"))
    process = subprocess.Popen(
        sleeve_command(credentials_path, "--rate-per-s", "10000", "--log-level", "warning", *grid),
        stdout=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 20
        while not any(json.loads(p).get("online") for _, p in inbox.items):
            if time.monotonic() > deadline or process.poll() is not None:
                raise RuntimeError("the sleeve process did not come online")
            time.sleep(0.05)
        yield
    finally:
        process.send_signal(signal.SIGTERM)
        process.wait(10)
        close(watcher)


def drawing_gaps(c: Credentials, shape: Any, strokes: int) -> list[float]:
    """A drawing sent at once: each stroke should start as the one before it ends."""
    inbox = _Inbox()
    watcher = _client(c, "sender", inbox, telemetry_topic(c.sleeve_id, "events"))
    sender = _client(c, "sender")
    (start, end, duration_ms) = shape
    drawing = f"gap-{uuid.uuid4()}"
    for seq in range(strokes):
        a, b = (start, end) if seq % 2 == 0 else (end, start)
        sender.publish(
            strokes_topic(c.sleeve_id),
            format_json(Stroke(a, b, duration_ms, None, drawing, seq)),
            qos=1,
        )
    events = inbox.wait_played(strokes, timeout_s=60)
    close(watcher, sender)
    return [
        after.first_command_at_ms - (before.first_command_at_ms + before.duration_ms)
        for before, after in itertools.pairwise(events)
        if after.queued_ms > 0
    ]


def _figures(name: str, values: list[float]) -> str:
    return (
        f"  {name:<52} p50 {statistics.median(values):7.3f} ms"
        f"   p99 {percentile(values, 99):7.3f} ms"
        f"   (n={len(values)})"
    )


def paired_latencies(
    shape: Any, count: int, strokes: Strokes, bare: BareReceiver, sender: mqtt.Client
) -> tuple[list[float], list[tuple[float, Played]]]:
    """``count`` bare messages and ``count`` strokes, alternately, after WARM_UP unmeasured
    pairs: both in the same minutes (see the module's docstring)."""
    for _ in range(WARM_UP):
        bare.latency_ms(sender)
        strokes.latency(shape, sender)
    paired: list[float] = []
    events: list[tuple[float, Played]] = []
    for _ in range(count):
        paired.append(bare.latency_ms(sender))
        events.append(strokes.latency(shape, sender))
    return paired, events


def _latency_lines(
    c: Credentials,
    label: str,
    shape: Any,
    count: int,
    bare: BareReceiver,
    in_process: list[float],
) -> list[str]:
    strokes = Strokes(c)
    sender = _client(c, "sender")
    paired, events = paired_latencies(shape, count, strokes, bare, sender)
    close(sender)
    strokes.close()
    end_to_end = end_to_end_ms(events)
    p50_ratio = statistics.median(end_to_end) / statistics.median(paired)
    low, high = paired_interval(end_to_end, paired, p99)
    return [
        _figures(f"{label}: publish -> first actuator command", end_to_end)
        + f"   {p99(end_to_end) / p99(paired):.2f}x (chance: {low:.2f} to {high:.2f}x)"
        + f" / {p50_ratio:.2f}x paired baseline p99 / p50"
        + f"   (p99: {p99(end_to_end) / p99(in_process):.2f}x the former)",
        _figures(f"{label}: paired baseline: bare publish -> receive", paired),
        _figures(
            f"{label}: sleeve's share (receive -> first command)",
            [e.latency_ms for _, e in events],
        ),
    ]


def report() -> list[str]:
    lines = ["Sleeve (real Mosquitto on loopback, simulator backend)"]
    with tempfile.TemporaryDirectory() as state:
        account = add_bare_account(Path(state))
        with Broker(state_dir=Path(state), port=0, ws_port=0) as broker:
            c = broker.credentials
            in_process = bare_latency_ms(c)
            lines.append(
                _figures("former baseline: bare publish -> receive, in this process", in_process)
                + "   (once, before the strokes)"
            )
            lines.append(
                "  the sleeve in a process of its own (30 cm: on a 3 x 12 grid), each length's"
                " strokes alternating with bare messages to a receiver process of their own:"
            )
            with bare_receiver(c, account) as bare:
                # One process per grid: each length still starts with warm-up strokes of its own.
                for grid in dict.fromkeys(grid for *_, grid in LENGTHS):
                    with _sleeve_process(c, broker.credentials_path, grid):
                        for label, shape, count, _ in (x for x in LENGTHS if x[3] == grid):
                            lines += _latency_lines(c, label, shape, count, bare, in_process)
                            if not grid:
                                gaps = drawing_gaps(c, shape, DRAWING_STROKES[label])
                                lines.append(
                                    _figures(f"{label}: gap between strokes of a drawing", gaps)
                                )
            lines.append("  the sleeve in this process (for the player's write times):")
            with _sleeve(c) as sleeve:
                for label, shape in (("1 cm", SHORT), ("10 cm", LONG)):
                    sleeve.player.timing_errors_ms.clear()
                    drawing_gaps(c, shape, DRAWING_STROKES[label])
                    lines.append(
                        _figures(
                            f"{label}: actuator write vs plan (lateness)",
                            list(sleeve.player.timing_errors_ms),
                        )
                    )
    return lines


if __name__ == "__main__":  # python -m feelmysign.bench.sleeve: this group alone
    for line in report():
        print(line, flush=True)
