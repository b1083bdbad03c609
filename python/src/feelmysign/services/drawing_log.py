"""One line per drawing in the terminal of ``feelmysign up``, from the sleeve's own events.

``up`` listens on ``feelmysign/<id>/events`` like any page does (with the
sender's account) and prints one line per drawing id once that drawing is over::

    Drawing 3f2a9c1e: 12 strokes played (3 faster to catch up, 210 ms shorter in all;
    1 slowed to the sleeve's floor), 1 delayed on the way (by 1.6 s), 2 skipped as late,
    1 rejected (outside_grid); start delay median 3 ms, max 9 ms   (on one line)

In brackets after the strokes played: those the sleeve played faster to catch up with the
pen, and by how much in all, and those it slowed to its floor (``fates.CatchUp``, in the
words the page's card and ``send --wait`` use).

A stroke delayed on the way was felt more than ``events.DELAYED_MS`` after its
sender drew it (its ``sent_at_ms``), not counting its wait behind the strokes before
it (``events.is_delayed``; the page marks the same ones): it was held on the way, by
its sender while the broker was out of reach, at the broker while the sleeve was
offline, or by a slow network. It was played; a stroke the
sleeve skipped for being too far behind is a ``late`` refusal, said as "skipped as late",
apart from the other refusals (it is counted once, as rejected is).

The start delay of a stroke is the time from its turn (its arrival, or the end
of the strokes queued before it) to its first motor: the sleeve's own lateness,
not the wait behind a drawing sent all at once. What became of each stroke
(played, cut short, cancelled, rejected) is :mod:`feelmysign.fates`, the rule the
page and the study report from too: each stroke is counted once, under one fate,
so the counts add up to the strokes the sleeve answered. A stroke cut short by a
stop counts as cut short, not played; a copy the broker delivered again after a
restart (a ``duplicate``) leaves its stroke as it was, played once. A stroke the
duty-cycle cap kept from playing counts as rejected (``duty_cycle``), like any
refusal.
A drawing is over when it has been quiet for ``QUIET_S`` and an event of another
drawing has come since (the next drawing started), or once it has been quiet for ``IDLE_S``,
or when ``up`` stops. A pen that rests a few seconds therefore does not split a
drawing in two lines. A drawing that goes on after its line was printed (a rest
longer than ``IDLE_S``) is printed again, marked ``(updated)``, with the totals of
the whole drawing: the last line about a drawing id is always all of it, and
replaces the earlier one rather than adding to it. Strokes without a drawing id (the legacy text
format, JSON that leaves it out, a message the sleeve could not read) cannot be
told apart: they count as one drawing per quiet spell of ``QUIET_S``. The summary is
built by ``DrawingSummaries`` (pure: events and a clock in, lines out);
``DrawingLog`` is its MQTT listener.
"""

from __future__ import annotations

import statistics
import threading
from collections import Counter, OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from feelmysign.connection import BrokerSettings, connect_client
from feelmysign.events import (
    Cancelled,
    Event,
    EventCopies,
    EventError,
    Played,
    Rejected,
    Safety,
    delivery_delay_ms,
    event_from_json,
    is_delayed,
)
from feelmysign.fates import FATES, DrawingFates, Fate
from feelmysign.protocol import LATE
from feelmysign.topics import telemetry_topic

if TYPE_CHECKING:  # paho is imported where a client is made, not by 'feelmysign --help'
    import paho.mqtt.client as mqtt

QUIET_S = 1.5  # a pen lifted: the drawing is over if another one has started since
IDLE_S = 10.0  # a drawing quiet this long is over, even if no other one started
UPDATABLE_DRAWINGS = 256  # printed drawings whose later strokes are added to their totals
CHECK_INTERVAL_S = 0.25
NO_DRAWING = "Strokes without a drawing id"
SHOWN_ID_CHARS = 8  # a uuid's first 8 characters tell drawings apart in one session


@dataclass
class _Drawing:
    last_event_s: float
    last_event_index: int = 0  # the summaries' event count at its last event
    printed: bool = False  # its line was printed: the next one says "(updated)"
    fates: DrawingFates = field(default_factory=DrawingFates)
    delays_ms: list[float] = field(default_factory=list)
    delays_on_the_way_ms: list[float] = field(default_factory=list)  # of the delayed ones

    def line(self, name: str) -> str:
        shown = name if name == NO_DRAWING else f"Drawing {name[:SHOWN_ID_CHARS]}"
        if self.printed:
            shown += " (updated)"
        counts = self.fates.counts()
        played = counts["played"]
        parts = [f"{played} stroke{'s' if played != 1 else ''} played"]
        if pace := self.fates.catch_up().played_words():
            parts[0] += f" ({pace})"
        if counts["cut"]:
            parts.append(f"{counts['cut']} cut short")
        if delayed := self.delays_on_the_way_ms:
            parts.append(f"{len(delayed)} delayed on the way (by {_seconds(max(delayed))}")
            parts[-1] += " at most)" if len(delayed) > 1 else ")"
        rejected = self.fates.refusals()
        if late := rejected.pop(LATE, 0):
            parts.append(f"{late} skipped as late")
        if rejected:
            reasons = ", ".join(f"{n} {r}" if n > 1 else r for r, n in rejected.items())
            parts.append(f"{sum(rejected.values())} rejected ({reasons})")
        if counts["cancelled"]:
            parts.append(f"{counts['cancelled']} cancelled")
        text = f"{shown}: " + ", ".join(parts)
        if self.delays_ms:
            text += (
                f"; start delay median {statistics.median(self.delays_ms):.0f} ms, "
                f"max {max(self.delays_ms):.0f} ms"
            )
        return text


def _seconds(ms: float) -> str:
    """As the page writes a delay: ms below a second, else seconds to a tenth."""
    return f"{ms / 1000:.1f} s" if ms >= 1000 else f"{ms:.0f} ms"


class DrawingSummaries:
    """Events in, one summary line per drawing out once it is over (see the module)."""

    def __init__(self, *, quiet_s: float = QUIET_S, idle_s: float = IDLE_S) -> None:
        self._quiet_s = quiet_s
        self._idle_s = idle_s
        self._drawings: dict[str, _Drawing] = {}
        self._printed: OrderedDict[str, _Drawing] = OrderedDict()  # oldest first
        self._events = 0  # counted: "another drawing sent since" compares these
        self._copies = EventCopies()  # a broker restart may deliver an event again
        # Every stroke seen, by its fate now: what the sleeve's stop line says.
        self._totals: Counter[Fate] = Counter()

    def add(self, event: Event, now_s: float) -> None:
        if self._copies.is_copy(event):
            return
        if isinstance(event, Safety) and event.received_at_ms is None:
            return  # about a chip, outside any stroke (chip_lost, chip_back): the sleeve logs it
        if not isinstance(event, Played | Rejected | Cancelled | Safety):
            return  # error events are logged by the sleeve itself
        name = event.drawing or NO_DRAWING
        if name not in self._drawings and name in self._printed:
            self._drawings[name] = self._printed.pop(name)  # goes on: its totals go on too
        drawing = self._drawings.setdefault(name, _Drawing(now_s))
        self._events += 1
        drawing.last_event_s = now_s
        drawing.last_event_index = self._events
        seq = getattr(event, "seq", None)
        before = drawing.fates.fate(seq) if seq is not None else None
        after = drawing.fates.add(event)
        if after is not None and after != before:
            if before is not None:
                self._totals[before] -= 1
            self._totals[after] += 1
        if isinstance(event, Played):
            drawing.delays_ms.append(max(0.0, event.latency_ms - event.queued_ms))
            delay_ms = delivery_delay_ms(event)
            if delay_ms is not None and is_delayed(event):
                drawing.delays_on_the_way_ms.append(delay_ms)

    def totals(self) -> dict[Fate, int]:
        """Every stroke seen, of every drawing, by its fate (feelmysign.fates), 0 included."""
        return {fate: self._totals[fate] for fate in FATES}

    def _is_over(self, name: str, drawing: _Drawing, now_s: float) -> bool:
        quiet_s = now_s - drawing.last_event_s
        if quiet_s >= self._idle_s:
            return True
        # Without an id, drawings cannot be told apart: a quiet spell ends one.
        next_started = name == NO_DRAWING or self._events > drawing.last_event_index
        return quiet_s >= self._quiet_s and next_started

    def finished(self, now_s: float, *, all_of_them: bool = False) -> list[str]:
        """The lines of the drawings that are over (or of every one), oldest first."""
        done = [
            name
            for name, drawing in self._drawings.items()
            if all_of_them or self._is_over(name, drawing, now_s)
        ]
        lines = []
        for name in done:
            drawing = self._drawings.pop(name)
            lines.append(drawing.line(name))
            if name != NO_DRAWING:
                drawing.printed = True
                self._printed[name] = drawing
                if len(self._printed) > UPDATABLE_DRAWINGS:
                    self._printed.popitem(last=False)
        return lines


class DrawingLog:
    """Listens to one sleeve's events and prints a line per finished drawing.

    ``with DrawingLog(settings, sleeve_id): ...``; leaving it prints what is left.
    Best effort: a log line must never stop ``up``, so a failure to listen is
    said once and the rest of ``up`` goes on.
    """

    def __init__(
        self,
        settings: BrokerSettings,
        sleeve_id: str,
        *,
        emit: Callable[[str], None] = lambda line: print(line, flush=True),
        clock: Callable[[], float] | None = None,
    ) -> None:
        import time

        self._settings = settings
        self._topic = telemetry_topic(sleeve_id, "events")
        self._sleeve_id = sleeve_id
        self._emit = emit
        self._clock = clock or time.monotonic
        self._summaries = DrawingSummaries()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._client: mqtt.Client | None = None
        self._subscribed = threading.Event()  # the broker acknowledged the subscription
        self._ticker = threading.Thread(
            target=self._tick, name="feelmysign-drawing-log", daemon=True
        )

    def __enter__(self) -> DrawingLog:
        from feelmysign.errors import FeelMySignError

        try:
            # A persistent session: the broker keeps the log's subscription and the events
            # published while it reconnects (a broker restarted from its saved state too), so
            # a drawing's line has all of its strokes. One session per sleeve: up runs the
            # broker and the sleeve with it, so nothing is queued for it between two runs.
            client = connect_client(
                self._settings, f"feelmysign-up-log-{self._sleeve_id}", persistent_session=True
            )
        except FeelMySignError as error:
            self._emit(f"No per-drawing log: cannot listen to the sleeve's events ({error}).")
            return self
        client.on_message = self._on_message
        client.on_subscribe = lambda *_: self._subscribed.set()
        client.on_disconnect = lambda *_: self._subscribed.clear()
        # Subscribed again on every reconnection: a clean session (and a broker started
        # again) forgets subscriptions, and the log would go silent after a broker restart.
        client.on_connect = self._on_connect
        client.subscribe(self._topic, qos=1)
        self._client = client
        self._ticker.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        if self._client is not None:
            self._ticker.join(timeout=2 * CHECK_INTERVAL_S + 1)
            self._client.disconnect()
            self._client.loop_stop()
        with self._lock:
            lines = self._summaries.finished(self._clock(), all_of_them=True)
        for line in lines:
            self._emit(line)

    def listening(self) -> bool:
        """Whether events reach the log now; True when it never could (said once already)."""
        return self._client is None or self._subscribed.is_set()

    def _on_connect(
        self, client: mqtt.Client, _userdata: Any, _flags: Any, code: Any, _props: Any
    ) -> None:
        if not code.is_failure:
            client.subscribe(self._topic, qos=1)

    def _on_message(self, _client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        try:
            event = event_from_json(message.payload)
        except EventError:
            return  # not ours to judge: the page shows it, the sleeve logged it
        with self._lock:
            self._summaries.add(event, self._clock())

    def _tick(self) -> None:
        while not self._stop.wait(CHECK_INTERVAL_S):
            with self._lock:
                lines = self._summaries.finished(self._clock())
            for line in lines:
                self._emit(line)
