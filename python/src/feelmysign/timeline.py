"""The timeline: planned strokes at absolute times, turned into intensity changes per actuator.

Pure (no clock, no thread): the player asks it what is due at a time and
writes what it answers. Commands of consecutive strokes may overlap on one
actuator (a burst that ends after its stroke, under the next stroke's first
burst); energies add, as within a stroke, capped at 1 and then at the layout's
maximum intensity.

Each stroke is checked against the duty-cycle cap when it is due to start
(:mod:`feelmysign.duty_cycle`): it plays whole, or, when one of its motors
would exceed its budget, not at all (``Due.capped``). A stroke is never cut
half-way, so "started" means "felt".
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Literal

from feelmysign.duty_cycle import Drive, DutyCycle, Refusal
from feelmysign.frozen_init import dict_init
from feelmysign.layout import Layout
from feelmysign.planner import Outline
from feelmysign.schedule import Command, Schedule

Actuator = tuple[int, int]

# A stroke added by its outline starts with its commands that start within this (ms after
# its start), the rest added when it is completed: at least as long as float rounding of a
# clock reading, so that no later command lands on the start time itself.
FIRST_COMMANDS_MS = 1.0


@dict_init
@dataclass(frozen=True)
class Change:
    """Set an actuator's intensity at a planned time (ms on the player's clock).

    ``tag`` is the stroke whose command made this change (for records; not compared).
    Made with one dict update (``dict_init``): a stroke's first motor command is one.
    """

    t_ms: float
    row: int
    column: int
    intensity: float
    tag: object = field(default=None, compare=False)


@dataclass(frozen=True)
class Capped:
    """A stroke (its ``tag``) the duty-cycle cap kept from playing, and why."""

    tag: object
    refusal: Refusal


@dataclass(frozen=True)
class Due:
    """What became due: intensity changes, strokes that started, strokes the cap refused."""

    changes: list[Change] = field(default_factory=list)
    started: list[object] = field(default_factory=list)
    capped: list[Capped] = field(default_factory=list)

    def __init__(
        self,
        changes: list[Change] | None = None,
        started: list[object] | None = None,
        capped: list[Capped] | None = None,
    ) -> None:
        # One dict update, not object.__setattr__ and a factory per field: the player asks
        # for what is due before every stroke's first motor command.
        self.__dict__.update(
            changes=[] if changes is None else changes,
            started=[] if started is None else started,
            capped=[] if capped is None else capped,
        )


@dataclass(frozen=True)
class Cut:
    """What cancelling strokes did: the changes to write now, the strokes cut short while
    playing and those that had not started (their tags, in planned order)."""

    changes: list[Change] = field(default_factory=list)
    started: list[object] = field(default_factory=list)
    unstarted: list[object] = field(default_factory=list)


class _Stroke:
    """What the start event needs to admit a stroke or drop it: its drive and its commands.

    A stroke added by its outline carries only its first commands until it is
    completed: ``outline`` is then set, and ``started_ms`` once it started.
    """

    __slots__ = ("commands", "drives", "outline", "start_ms", "started_ms", "tag")

    def __init__(
        self,
        tag: object,
        drives: dict[Actuator, list[Drive]],
        commands: set[int],
        start_ms: float,
        outline: Outline | None = None,
    ) -> None:
        self.tag = tag
        self.drives = drives
        self.commands = commands
        self.start_ms = start_ms
        self.outline = outline
        self.started_ms: float | None = None


_Kind = Literal["on", "off", "start"]


@dataclass(slots=True)
class _Event:
    t_ms: float
    order: int
    kind: _Kind
    actuator: Actuator = (0, 0)
    command: int = 0
    energy: float = 0.0
    tag: object = None
    stroke: _Stroke | None = None  # on a start event only


# The heap holds (t_ms, order, event): tuples compare in C, where a dataclass's ordering
# would run Python code for every comparison of the heap, on the way to a stroke's first command.
_Entry = tuple[float, int, _Event]


def _when(event: _Event) -> tuple[float, int]:
    return (event.t_ms, event.order)


class Timeline:
    def __init__(self, layout: Layout) -> None:
        self._layout = layout
        self._events: list[_Entry] = []
        self._order = itertools.count()
        self._commands = itertools.count()
        self._active: dict[Actuator, dict[int, float]] = {}
        self._output: dict[Actuator, float] = {}
        self._dropped: set[int] = set()  # commands of strokes the cap refused
        self._incomplete: list[_Stroke] = []  # added by their outline, in the order added
        self._duty_cycle = DutyCycle(layout.duty_cycle_window_ms, layout.max_duty_cycle)
        # Outputs changed and not yet told to the duty cycle, in order: told after the
        # changes are written (``complete``), or as soon as the duty cycle is read.
        self._outputs: list[tuple[Actuator, float, float]] = []
        # No motor is driven above this: the layout's max_intensity, lowered by the wearer's
        # ceiling (set_ceiling). Read at every change, so a ceiling lowered mid-stroke holds
        # from the stroke's next change on.
        self.max_intensity = layout.max_intensity

    @property
    def duty_cycle(self) -> DutyCycle:
        """Each motor's drive (``feelmysign.duty_cycle``), every output change so far in it."""
        if self._outputs:
            self._record_outputs()
        return self._duty_cycle

    def _record_outputs(self) -> None:
        outputs, self._outputs = self._outputs, []
        output = self._duty_cycle.output
        for actuator, t_ms, intensity in outputs:
            output(actuator, t_ms, intensity)

    def set_ceiling(self, ceiling: float | None) -> None:
        """The wearer's intensity ceiling (None: none): it only ever lowers the layout's cap."""
        cap = self._layout.max_intensity
        self.max_intensity = cap if ceiling is None else min(cap, ceiling)

    def add(self, schedule: Schedule, start_ms: float, tag: object = None) -> None:
        """Play ``schedule`` from ``start_ms``; ``tag`` comes back in ``Due.started`` then
        (or in ``Due.capped``, when the duty-cycle cap keeps it from playing)."""
        self.complete()
        stroke = _Stroke(tag, {}, set(), start_ms)
        # First, so that it is admitted (or refused) before any of its commands.
        self._push(_Event(start_ms, 0, "start", tag=tag, stroke=stroke))
        self._push_commands(stroke, schedule.commands)

    def add_outline(self, outline: Outline, start_ms: float, tag: object = None) -> None:
        """Play a stroke from its outline: as ``add(outline.schedule(), ...)`` plays it.

        Only its first commands (those within ``FIRST_COMMANDS_MS``) are added now;
        the rest when ``complete`` is called, at the latest before anything after its
        start is due. Its start admits it at once when the duty-cycle cap surely lets
        it play (from an upper bound of its drive); otherwise it is completed there and
        checked as any other stroke.
        """
        self.complete()
        stroke = _Stroke(tag, {}, set(), start_ms, outline)
        self._push(_Event(start_ms, 0, "start", tag=tag, stroke=stroke))
        self._push_commands(stroke, outline.head(FIRST_COMMANDS_MS))
        self._incomplete.append(stroke)

    def complete(self) -> None:
        """Add the rest of every stroke added by its outline (a stroke already admitted is
        committed to the duty cycle now, as at its start), and tell the duty cycle the output
        changes made since it was last told (the player calls this once the changes due are
        written: a stroke's first motor command waits for none of this)."""
        if self._outputs:
            self._record_outputs()
        while self._incomplete:
            stroke = self._incomplete.pop(0)
            outline = stroke.outline
            assert outline is not None
            commands = outline.schedule().commands
            self._push_commands(stroke, [c for c in commands if not c.start_ms < FIRST_COMMANDS_MS])
            stroke.outline = None
            # The drives in the schedule's order, as ``add`` keeps them.
            drives: dict[Actuator, list[Drive]] = {}
            start_ms = stroke.start_ms
            for command in commands:
                on_ms, off_ms = start_ms + command.start_ms, start_ms + command.end_ms
                drive = Drive(on_ms, off_ms, self._driven_energy(command.intensity))
                drives.setdefault((command.row, command.column), []).append(drive)
            stroke.drives = drives
            if stroke.started_ms is not None:
                self.duty_cycle.commit(drives, stroke.started_ms)

    def _push_commands(self, stroke: _Stroke, commands: Iterable[Command]) -> None:
        start_ms, tag = stroke.start_ms, stroke.tag
        for command in commands:
            ident = next(self._commands)
            actuator = (command.row, command.column)
            energy = command.intensity**2
            on_ms, off_ms = start_ms + command.start_ms, start_ms + command.end_ms
            if stroke.outline is None:
                drive = Drive(on_ms, off_ms, self._driven_energy(command.intensity))
                stroke.drives.setdefault(actuator, []).append(drive)
            stroke.commands.add(ident)
            self._push(_Event(on_ms, 0, "on", actuator, ident, energy, tag=tag))
            self._push(_Event(off_ms, 0, "off", actuator, ident, tag=tag))

    def next_ms(self) -> float | None:
        """When the next thing is due, or None when nothing is planned."""
        if self._incomplete and (
            not self._events or self._events[0][0] > self._incomplete[0].start_ms
        ):
            self.complete()  # started: its rest may be due first
        return self._events[0][0] if self._events else None

    @property
    def busy(self) -> bool:
        """Whether anything is planned or any actuator is on (reads only: any thread may ask)."""
        return bool(self._events) or any(self._output.values())

    def pop_due(self, now_ms: float) -> Due:
        """Everything due at or before ``now_ms``, in time order; only real changes are listed."""
        due = Due()
        while self._events and self._events[0][0] <= now_ms:
            t_ms = self._events[0][0]
            if self._incomplete and t_ms > self._incomplete[0].start_ms:
                self.complete()  # its rest may be due before this
                continue
            touched: dict[Actuator, object] = {}  # each actuator, and the stroke that last moved it
            while self._events and self._events[0][0] == t_ms:
                self._apply(heapq.heappop(self._events)[2], touched, due)
            for actuator in sorted(touched):
                self._settle(actuator, t_ms, due, touched[actuator])
        return due

    def cancel(self, match: Callable[[object], bool], now_ms: float) -> Cut:
        """Drop everything still planned for the strokes whose tag ``match``es; their motors go
        off at ``now_ms`` (a motor another stroke also drives keeps that stroke's intensity)."""
        self.complete()
        dropped = [e for _, _, e in self._events if e.tag is not None and match(e.tag)]
        if not dropped:
            return Cut()
        gone = {id(e) for e in dropped}
        # A stroke the duty-cycle cap refused was never played (and was reported): not "cut".
        refused = [e.tag for e in dropped if e.kind != "start" and e.command in self._dropped]
        self._dropped -= {e.command for e in dropped}
        self._events = [entry for entry in self._events if id(entry[2]) not in gone]
        heapq.heapify(self._events)
        dropped.sort(key=_when)
        unstarted = [e.tag for e in dropped if e.kind == "start"]
        started: list[object] = []
        for tag in (e.tag for e in dropped):
            if all(tag is not t for t in [*unstarted, *started, *refused]):
                started.append(tag)
        touched: dict[Actuator, object] = {}
        for event in dropped:
            # An "off" still planned whose "on" has happened: that command is running now.
            running = self._active.get(event.actuator)
            if event.kind == "off" and running is not None and event.command in running:
                del running[event.command]
                touched[event.actuator] = event.tag
        due = Due()
        for actuator in sorted(touched):
            self._settle(actuator, now_ms, due, touched[actuator])
        return Cut(due.changes, started, unstarted)

    def tags(self) -> list[object]:
        """The tags of strokes with anything still planned, each once."""
        self.complete()
        seen: dict[int, object] = {}
        for _, _, event in self._events:
            if event.tag is not None:
                seen.setdefault(id(event.tag), event.tag)
        return list(seen.values())

    def unstarted(self) -> list[object]:
        """The tags of strokes added but not yet started."""
        return [e.stroke.tag for _, _, e in sorted(self._events) if e.stroke is not None]

    def clear(self) -> list[Change]:
        """Drop everything planned; the changes that switch every running actuator off."""
        self._events.clear()
        self._incomplete.clear()
        self._active.clear()
        self._dropped.clear()
        self.duty_cycle.clear()
        off = [Change(0.0, r, c, 0.0) for (r, c), value in sorted(self._output.items()) if value]
        self._output.clear()
        return off

    def _push(self, event: _Event) -> None:
        event.order = next(self._order)  # ties at one time keep the order they were added in
        heapq.heappush(self._events, (event.t_ms, event.order, event))

    def _apply(self, event: _Event, touched: dict[Actuator, object], due: Due) -> None:
        if event.stroke is not None:
            self._start(event.stroke, event.t_ms, due)
        elif event.command in self._dropped:
            if event.kind == "off":
                self._dropped.discard(event.command)
        elif event.kind == "on":
            self._active.setdefault(event.actuator, {})[event.command] = event.energy
            touched[event.actuator] = event.tag
        else:
            self._active.get(event.actuator, {}).pop(event.command, None)
            touched[event.actuator] = event.tag

    def _start(self, stroke: _Stroke, t_ms: float, due: Due) -> None:
        if stroke.outline is not None:
            outline = stroke.outline
            # No command drives above the cap, so the bound scales down with it.
            capped = self._driven_energy(outline.intensity) / max(outline.intensity**2, 1e-300)
            bound_ms = outline.energy_bound_ms() * min(1.0, capped)
            if self.duty_cycle.surely_fits(bound_ms, t_ms):
                stroke.started_ms = t_ms  # committed when completed, before anything else
                due.started.append(stroke.tag)
                return
            self.complete()  # its whole drive decides, as for any stroke
        refusal = self.duty_cycle.check(stroke.drives, t_ms)
        if refusal is None:
            self.duty_cycle.commit(stroke.drives, t_ms)
            due.started.append(stroke.tag)
        else:
            self._dropped.update(stroke.commands)
            due.capped.append(Capped(stroke.tag, refusal))

    def _driven_energy(self, intensity: float) -> float:
        """The energy a command asking ``intensity`` drives its motor with, alone: as
        ``_settle`` drives it, capped at full drive and the layout's ``max_intensity``. What
        the duty-cycle cap counts: the drive that heats the motor, not the drive asked for.
        (Commands overlapping on one motor add energies and are capped once; counted each
        capped, they are counted at least at what is driven.)"""
        driven = min(1.0, intensity, self.max_intensity)
        return driven * driven

    def _settle(self, actuator: Actuator, t_ms: float, due: Due, tag: object = None) -> None:
        active = self._active.get(actuator)
        if not active:
            self._active.pop(actuator, None)
        energy = sum(active.values()) if active else 0.0
        wanted = min(1.0, math.sqrt(energy), self.max_intensity)
        if wanted == self._output.get(actuator, 0.0):
            return
        self._output[actuator] = wanted
        self._outputs.append((actuator, t_ms, wanted))  # for the duty cycle (see complete)
        due.changes.append(Change(t_ms, actuator[0], actuator[1], wanted, tag))
