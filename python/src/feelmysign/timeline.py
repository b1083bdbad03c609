"""The timeline: planned strokes at absolute times, turned into intensity changes per actuator.

Pure (no clock, no thread): the player asks it what is due at a time and
writes what it answers. Commands of consecutive strokes may overlap on one
actuator (a burst that ends after its stroke, under the next stroke's first
burst); energies add, as within a stroke, capped at 1 and then at the layout's
maximum intensity. An actuator on for longer than the layout's maximum
continuous on-time is switched off and kept off until its commands stop; an
off shorter than ``MIN_REST_MS`` does not end an on-period (back-to-back
strokes a few ms apart keep a motor running just the same).
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

from feelmysign.layout import Layout
from feelmysign.schedule import Schedule

Actuator = tuple[int, int]

# A motor must be off this long before a new on-period (and a new on-time
# budget) starts: a stroke that reaches an idle sleeve a few ms after the last
# one ended gives the motor no rest at all.
MIN_REST_MS = 1000.0


@dataclass(frozen=True)
class Change:
    """Set an actuator's intensity at a planned time (ms on the player's clock)."""

    t_ms: float
    row: int
    column: int
    intensity: float


@dataclass(frozen=True)
class Due:
    """What became due: intensity changes, strokes that started, actuators cut by the cap."""

    changes: list[Change] = field(default_factory=list)
    started: list[object] = field(default_factory=list)
    tripped: list[Actuator] = field(default_factory=list)


@dataclass(frozen=True)
class Cut:
    """What cancelling strokes did: the changes to write now, the strokes cut short while
    playing and those that had not started (their tags, in planned order)."""

    changes: list[Change] = field(default_factory=list)
    started: list[object] = field(default_factory=list)
    unstarted: list[object] = field(default_factory=list)


_Kind = Literal["on", "off", "start", "cap"]


@dataclass(order=True)
class _Event:
    t_ms: float
    order: int
    kind: _Kind = field(compare=False)
    actuator: Actuator = field(compare=False, default=(0, 0))
    command: int = field(compare=False, default=0)
    energy: float = field(compare=False, default=0.0)
    since_ms: float = field(compare=False, default=0.0)
    tag: object = field(compare=False, default=None)


class Timeline:
    def __init__(self, layout: Layout) -> None:
        self._layout = layout
        self._events: list[_Event] = []
        self._order = itertools.count()
        self._commands = itertools.count()
        self._active: dict[Actuator, dict[int, float]] = {}
        self._output: dict[Actuator, float] = {}
        self._on_since: dict[Actuator, float] = {}
        self._off_at: dict[Actuator, float] = {}
        self._tripped: set[Actuator] = set()

    def add(self, schedule: Schedule, start_ms: float, tag: object = None) -> None:
        """Play ``schedule`` from ``start_ms``; ``tag`` comes back in ``Due.started`` then."""
        self._push(_Event(start_ms, 0, "start", tag=tag))
        for command in schedule.commands:
            ident = next(self._commands)
            actuator = (command.row, command.column)
            energy = command.intensity**2
            on_ms, off_ms = start_ms + command.start_ms, start_ms + command.end_ms
            self._push(_Event(on_ms, 0, "on", actuator, ident, energy, tag=tag))
            self._push(_Event(off_ms, 0, "off", actuator, ident, tag=tag))

    def next_ms(self) -> float | None:
        """When the next thing is due, or None when nothing is planned."""
        self._drop_stale_caps()
        return self._events[0].t_ms if self._events else None

    @property
    def busy(self) -> bool:
        """Whether anything is planned or any actuator is on (reads only: any thread may ask)."""
        live = (e for e in list(self._events) if e.kind != "cap" or self._is_live_cap(e))
        return any(self._output.values()) or any(True for _ in live)

    def _drop_stale_caps(self) -> None:
        """Forget on-time caps of on-periods that have ended (they would only wake us up)."""
        while (
            self._events
            and self._events[0].kind == "cap"
            and not self._is_live_cap(self._events[0])
        ):
            heapq.heappop(self._events)

    def _is_live_cap(self, event: _Event) -> bool:
        """A cap still matters while its on-period runs and the motor is on."""
        actuator = event.actuator
        return self._on_since.get(actuator) == event.since_ms and bool(self._output.get(actuator))

    def pop_due(self, now_ms: float) -> Due:
        """Everything due at or before ``now_ms``, in time order; only real changes are listed."""
        due = Due()
        while self._events and self._events[0].t_ms <= now_ms:
            t_ms = self._events[0].t_ms
            touched: set[Actuator] = set()
            while self._events and self._events[0].t_ms == t_ms:
                self._apply(heapq.heappop(self._events), touched, due)
            for actuator in sorted(touched):
                self._settle(actuator, t_ms, due)
        return due

    def cancel(self, match: Callable[[object], bool], now_ms: float) -> Cut:
        """Drop everything still planned for the strokes whose tag ``match``es; their motors go
        off at ``now_ms`` (a motor another stroke also drives keeps that stroke's intensity)."""
        dropped = [
            e for e in self._events if e.kind != "cap" and e.tag is not None and match(e.tag)
        ]
        if not dropped:
            return Cut()
        gone = {id(e) for e in dropped}
        self._events = [e for e in self._events if id(e) not in gone]
        heapq.heapify(self._events)
        dropped.sort()
        unstarted = [e.tag for e in dropped if e.kind == "start"]
        started: list[object] = []
        for tag in (e.tag for e in dropped):
            if all(tag is not t for t in unstarted) and all(tag is not t for t in started):
                started.append(tag)
        touched: set[Actuator] = set()
        for event in dropped:
            # An "off" still planned whose "on" has happened: that command is running now.
            running = self._active.get(event.actuator)
            if event.kind == "off" and running is not None and event.command in running:
                del running[event.command]
                touched.add(event.actuator)
        due = Due()
        for actuator in sorted(touched):
            self._settle(actuator, now_ms, due)
        return Cut(due.changes, started, unstarted)

    def tags(self) -> list[object]:
        """The tags of strokes with anything still planned, each once."""
        seen: dict[int, object] = {}
        for event in self._events:
            if event.tag is not None:
                seen.setdefault(id(event.tag), event.tag)
        return list(seen.values())

    def unstarted(self) -> list[object]:
        """The tags of strokes added but not yet started."""
        return [e.tag for e in sorted(self._events) if e.kind == "start"]

    def clear(self) -> list[Change]:
        """Drop everything planned; the changes that switch every running actuator off."""
        self._events.clear()
        self._active.clear()
        self._tripped.clear()
        self._on_since.clear()
        self._off_at.clear()
        off = [Change(0.0, r, c, 0.0) for (r, c), value in sorted(self._output.items()) if value]
        self._output.clear()
        return off

    def _push(self, event: _Event) -> None:
        event.order = next(self._order)  # ties at one time keep the order they were added in
        heapq.heappush(self._events, event)

    def _apply(self, event: _Event, touched: set[Actuator], due: Due) -> None:
        if event.kind == "start":
            due.started.append(event.tag)
        elif event.kind == "on":
            self._active.setdefault(event.actuator, {})[event.command] = event.energy
            touched.add(event.actuator)
        elif event.kind == "off":
            self._active.get(event.actuator, {}).pop(event.command, None)
            touched.add(event.actuator)
        elif self._is_live_cap(event) and event.actuator not in self._tripped:
            # Still the on-period this cap was set for: it has lasted the
            # maximum continuous on-time.
            self._tripped.add(event.actuator)
            due.tripped.append(event.actuator)
            touched.add(event.actuator)

    def _settle(self, actuator: Actuator, t_ms: float, due: Due) -> None:
        active = self._active.get(actuator)
        if not active:
            self._active.pop(actuator, None)
            self._tripped.discard(actuator)
        energy = sum(active.values()) if active else 0.0
        wanted = min(1.0, math.sqrt(energy), self._layout.max_intensity)
        if actuator in self._tripped:
            wanted = 0.0
        if wanted == self._output.get(actuator, 0.0):
            return
        was_on = bool(self._output.get(actuator))
        if wanted and not was_on and self._over_on_time(actuator, t_ms):
            self._tripped.add(actuator)
            due.tripped.append(actuator)
            wanted = 0.0
            if not self._output.get(actuator):
                return
        self._output[actuator] = wanted
        due.changes.append(Change(t_ms, actuator[0], actuator[1], wanted))
        if wanted and not was_on:
            since_ms = self._on_since[actuator]
            cap_ms = since_ms + self._layout.max_on_time_ms
            self._push(_Event(cap_ms, 0, "cap", actuator, since_ms=since_ms))
        elif not wanted:
            self._off_at[actuator] = t_ms

    def _over_on_time(self, actuator: Actuator, t_ms: float) -> bool:
        """Start or continue the on-period of a motor switching on; True if it is used up."""
        off_at = self._off_at.get(actuator)
        if actuator not in self._on_since or off_at is None or t_ms - off_at >= MIN_REST_MS:
            self._on_since[actuator] = t_ms  # rested: a new on-period
            return False
        return t_ms - self._on_since[actuator] >= self._layout.max_on_time_ms
