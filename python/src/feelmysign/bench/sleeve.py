"""Sleeve latency, timing and continuity, against a real Mosquitto on loopback, in one run.

Baseline: a bare MQTT publish -> receive on the same broker (QoS 1, the same
two accounts). Measured: publish -> the sleeve's first actuator command (from
its ``played`` events), the sleeve's own share (receive -> first command), the
lateness of every actuator write against the plan, and the gap between
consecutive strokes of a drawing, for strokes of 1, 3, 10 and 30 cm (the share at
each length: the sleeve starts a stroke's first burst before planning the rest).

Only a stroke's first command counts for latency, so each measured stroke is
cancelled (the control message) once its ``played`` event is out, instead of
being played to its end: the sleeve receives, checks and plans it as any other
stroke, and its first command takes the same path; only the motors it would have
driven later are switched off early. The next stroke is sent once the sleeve has
reported it cancelled and a short settle has passed, as the baseline's next message
once the last one is received and acknowledged and the same settle has passed (an
idle sleeve, as an idle broker). The gaps between strokes of a drawing need real
back-to-back play, so those strokes play out.
"""

from __future__ import annotations

import itertools
import json
import math
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar

import paho.mqtt.client as mqtt

from feelmysign.backends.sim import SimBackend
from feelmysign.bench._mqtt import close
from feelmysign.broker import Broker, Credentials
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


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q / 100 * (len(ordered) - 1)))]


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


def stroke_latencies(
    c: Credentials, shape: Any, count: int, sender: mqtt.Client | None = None
) -> list[tuple[float, Played]]:
    """One stroke at a time to an idle sleeve: publish time beside the sleeve's played event.

    Each stroke (a drawing of its own) is cancelled once its played event is out, i.e. after
    its first command; the next is sent once the sleeve reports it cancelled, SETTLE_S later.
    ``sender``: the connected client that publishes (closed here); else one over MQTT.
    """
    inbox = _Inbox()
    watcher = _client(c, "sender", inbox, telemetry_topic(c.sleeve_id, "events"))
    sender = sender or _client(c, "sender")
    (start, end, duration_ms) = shape
    results = []
    for _ in range(count):
        drawing = f"lat-{uuid.uuid4()}"
        stroke = Stroke(start, end, duration_ms, None, drawing, 0)
        with inbox.cond:
            inbox.items.clear()  # the earlier strokes' events: each wait reads them all again
        published_ms = time.time_ns() / 1e6
        sender.publish(strokes_topic(c.sleeve_id), format_json(stroke), qos=1)
        event = inbox.wait_played(1)[-1]
        if event.drawing != drawing:
            raise RuntimeError(f"expected a played event of {drawing}, got {event}")
        results.append((published_ms, event))
        sender.publish(control_topic(c.sleeve_id), format_control(Cancel(drawing)), qos=1)
        # Its motors are off once it is reported cancelled; a stroke that ended before the
        # cancel came is not reported: wait no longer than its end. Then the settle.
        end_ms = event.first_command_at_ms + event.duration_ms + 100.0
        inbox.wait_event(Cancelled, drawing, max(0.0, end_ms - time.time_ns() / 1e6) / 1000)
        time.sleep(SETTLE_S)
    close(watcher, sender)
    return results


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
        f"  {name:<48} p50 {statistics.median(values):7.3f} ms"
        f"   p99 {percentile(values, 99):7.3f} ms"
        f"   (n={len(values)})"
    )


def _latency_lines(
    c: Credentials, label: str, shape: Any, count: int, bare: list[float]
) -> list[str]:
    stroke_latencies(c, shape, WARM_UP)
    events = stroke_latencies(c, shape, count)
    end_to_end = [e.first_command_at_ms - published_ms for published_ms, e in events]
    ratio = percentile(end_to_end, 99) / percentile(bare, 99)
    return [
        _figures(f"{label}: publish -> first actuator command", end_to_end)
        + f"   {ratio:.2f}x baseline p99",
        _figures(
            f"{label}: sleeve's share (receive -> first command)",
            [e.latency_ms for _, e in events],
        ),
    ]


def report() -> list[str]:
    lines = ["Sleeve (real Mosquitto on loopback, simulator backend)"]
    with (
        tempfile.TemporaryDirectory() as state,
        Broker(state_dir=Path(state), port=0, ws_port=0) as broker,
    ):
        c = broker.credentials
        bare = bare_latency_ms(c)
        lines.append(_figures("baseline: bare MQTT publish -> receive (paced)", bare))
        lines.append("  the sleeve in a process of its own (30 cm: on a 3 x 12 grid):")
        # One process per grid: each length still starts with warm-up strokes of its own.
        for grid in dict.fromkeys(grid for *_, grid in LENGTHS):
            with _sleeve_process(c, broker.credentials_path, grid):
                for label, shape, count, _ in (length for length in LENGTHS if length[3] == grid):
                    lines += _latency_lines(c, label, shape, count, bare)
                    if not grid:
                        gaps = drawing_gaps(c, shape, DRAWING_STROKES[label])
                        lines.append(_figures(f"{label}: gap between strokes of a drawing", gaps))
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
