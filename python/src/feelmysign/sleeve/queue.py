"""The sleeve's queue: when each stroke starts, the seqs seen per drawing, and cancels.

The start-time rule: strokes play back to back, in the order they arrive. A
stroke starts when it arrives, or when the stroke before it ends if that is
later::

    start = max(arrival, tail)      tail = start + duration

so the strokes of a drawing sent faster than they play feel like one continuous
touch, and a stroke that arrives to an idle sleeve starts at once. The pace rule
(:mod:`feelmysign.pace`) times the sender's own time line by the same rule, on
``sent_at_ms``: :func:`start_ms` is the one place it is written.

The catch-up rule: a stroke that arrives while the sleeve is behind its own
drawing (the tail is a stroke of the same drawing, ``behind = tail - arrival >
0``) is played faster, by as much as the sleeve is behind, but never below the
sleeve's floor (the shortest stroke it plays without slowing it) and never
slower than it came::

    duration = max(floor, duration - behind)   (only when behind > 0 and duration > floor)

so a drawing that queues (fast drawing, short strokes slowed to the floor, a
slow network) gets back to the pen within a stroke or two, keeping its shape:
only durations change, never where a stroke goes. Only the strokes of one
drawing are caught up: a stroke waiting behind another drawing (another sender,
or a new drawing after a pen lift) is not behind its own pen, and the strokes
without a drawing (the legacy format) play as they came. :func:`catch_up_ms` is
the one place it is written; ``Queue.catch_up_ms`` applies it to the queue's
tail. Skipping (``late``, :mod:`feelmysign.pace`) stays the last resort, for a
sleeve so far behind that even strokes at the floor cannot catch up.

A cancel drops the strokes of its drawing (or all) accepted before it: one not
yet started is dropped, one playing is cut where the cancel came. The tail is
then the end of the latest stroke still planned (none: the next stroke starts
when it arrives). A stroke of a cancelled drawing that comes later is refused
as ``cancelled``.

Each ``seq`` of a drawing plays once: a copy of one accepted before is
``held`` while the original waits to play (its acknowledgement waits for it)
and a ``duplicate`` after. A gap never waits for the missing seq, and a
missing one that comes after later ones still plays. The queue also keeps
which seqs started playing (``mark_started``), so that a duplicate's refusal
can say whether its original was felt: a copy of a played stroke is no news
to its sender, a copy of a refused one is.

Pure (numbers in, numbers out; no clock, no thread, no I/O): the player keeps
one :class:`Queue` under its lock, and :func:`replay` runs a whole sequence of
arrivals and cancels at once, for the simulations and the vectors in
``testdata/queue/`` (which the page's ``web/src/sleeve-queue.ts`` reproduces).
"""

from __future__ import annotations

import bisect
from collections import OrderedDict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from feelmysign import protocol

NEVER_MS = float("-inf")  # the tail of an empty queue: the next stroke starts when it arrives
REMEMBERED_DRAWINGS = 64  # drawings whose seqs are kept, for dropping redeliveries
REMEMBERED_CANCELS = 64  # cancelled drawings kept, for refusing their later strokes

# Outcomes of replay: played whole, cut short by a cancel, or one of admission's reasons
# (cancelled, held, duplicate).
PLAYED = "played"
CUT = "cut"
CANCELLED, HELD, DUPLICATE = protocol.CANCELLED, protocol.HELD, protocol.DUPLICATE


def start_ms(arrival_ms: float, tail_ms: float) -> float:
    """When a stroke that arrives at ``arrival_ms`` starts behind a queue ending at ``tail_ms``."""
    return max(arrival_ms, tail_ms)


def catch_up_ms(arrival_ms: float, tail_ms: float, duration_ms: float, floor_ms: float) -> float:
    """The duration to play a stroke of ``duration_ms`` with, arriving at ``arrival_ms`` behind
    strokes of its drawing that end at ``tail_ms``: shorter by how far the sleeve is behind,
    down to ``floor_ms`` and never longer than it came (a stroke at or below the floor, or one
    that does not wait, keeps its duration)."""
    behind_ms = tail_ms - arrival_ms
    if behind_ms <= 0.0 or duration_ms <= floor_ms:
        return duration_ms
    return max(floor_ms, duration_ms - behind_ms)


class SeenSeqs:
    """The seqs of one drawing seen so far, as sorted disjoint ranges [low, high): a drawing
    sent in order is one range whatever its length, each gap adds one."""

    def __init__(self) -> None:
        self._lows: list[int] = []
        self._highs: list[int] = []

    def __contains__(self, seq: int) -> bool:
        i = bisect.bisect_right(self._lows, seq) - 1
        return i >= 0 and seq < self._highs[i]

    def add(self, seq: int) -> None:
        if seq in self:
            return
        i = bisect.bisect_right(self._lows, seq)  # the range after seq, if any
        joins_before = i > 0 and self._highs[i - 1] == seq
        joins_after = i < len(self._lows) and self._lows[i] == seq + 1
        if joins_before and joins_after:
            self._highs[i - 1] = self._highs[i]
            del self._lows[i], self._highs[i]
        elif joins_before:
            self._highs[i - 1] = seq + 1
        elif joins_after:
            self._lows[i] = seq
        else:
            self._lows.insert(i, seq)
            self._highs.insert(i, seq + 1)

    @property
    def ranges(self) -> int:
        return len(self._lows)


class Queue:
    """The tail of the strokes accepted so far and the seqs seen per drawing.

    Not thread-safe: the player calls it under its lock.
    """

    __slots__ = ("_seen", "_started", "tail_drawing", "tail_ms")

    def __init__(self) -> None:
        self.tail_ms = NEVER_MS
        self.tail_drawing: str | None = None  # the drawing of the stroke that ends at the tail
        self._seen: OrderedDict[str, SeenSeqs] = OrderedDict()
        # Of the seen seqs, those that started playing (kept for the same drawings).
        self._started: dict[str, SeenSeqs] = {}

    def place(
        self, arrival_ms: float, duration_ms: float, drawing: str | None = None, seq: int = 0
    ) -> float:
        """Queue a stroke: when it starts (and the tail moves to its end). With a ``drawing``,
        its ``seq`` is remembered (written out here, not a call to :meth:`remember`: this is
        on the path from a stroke's message to its first command)."""
        if drawing is not None:
            seqs = self._seen.get(drawing)
            if seqs is None:
                seqs = self._new_drawing(drawing)
            else:
                self._seen.move_to_end(drawing)
            seqs.add(seq)
        start = max(arrival_ms, self.tail_ms)  # start_ms(), written out: one call less
        self.tail_ms = start + duration_ms
        self.tail_drawing = drawing
        return start

    def catch_up_ms(
        self, arrival_ms: float, duration_ms: float, floor_ms: float, drawing: str | None
    ) -> float:
        """The duration to place a stroke of ``drawing`` with (:func:`catch_up_ms`): shorter
        only when it waits behind a stroke of the same drawing."""
        if drawing is None or drawing != self.tail_drawing:
            return duration_ms
        return catch_up_ms(arrival_ms, self.tail_ms, duration_ms, floor_ms)

    def wait_ms(self, now_ms: float) -> float:
        """How long a stroke arriving at ``now_ms`` would wait for the strokes before it."""
        return max(0.0, self.tail_ms - now_ms)

    def replan(self, ends: Iterable[tuple[float, str | None]]) -> None:
        """After a cancel: the tail is the end of the latest stroke still planned, each given
        as ``(end_ms, drawing)``."""
        self.tail_ms, self.tail_drawing = max(ends, default=(NEVER_MS, None), key=_end_ms)

    def seen(self, drawing: object, seq: object) -> bool:
        """Whether this seq of this drawing was accepted or settled before."""
        if not isinstance(drawing, str) or not isinstance(seq, int):
            return False
        seqs = self._seen.get(drawing)
        return seqs is not None and seq in seqs

    def mark_started(self, drawing: object, seq: object) -> None:
        """A seen seq of a drawing started playing (its ``played`` event went out)."""
        if not isinstance(drawing, str) or not isinstance(seq, int) or drawing not in self._seen:
            return
        self._started.setdefault(drawing, SeenSeqs()).add(seq)

    def started(self, drawing: object, seq: object) -> bool:
        """Whether this seq of this drawing started playing (cut short later or not)."""
        if not isinstance(drawing, str) or not isinstance(seq, int):
            return False
        seqs = self._started.get(drawing)
        return seqs is not None and seq in seqs

    def remember(self, drawing: str, seq: int) -> None:
        """A seq of a drawing settled without being placed: a copy of it is seen too. Placed
        as a stroke of no duration at the tail, which leaves the tail where it is."""
        self.place(self.tail_ms, 0.0, drawing, seq)

    def _new_drawing(self, drawing: str) -> SeenSeqs:
        seqs = self._seen[drawing] = SeenSeqs()
        while len(self._seen) > REMEMBERED_DRAWINGS:
            forgotten, _ = self._seen.popitem(last=False)
            self._started.pop(forgotten, None)
        return seqs


def _end_ms(end: tuple[float, str | None]) -> float:
    return end[0]


class CancelledDrawings(OrderedDict[str, float]):
    """The drawings cancelled lately, each with when its cancel came: a stroke of one that
    comes later (the broker held it, or it was sent just after) is ``cancelled`` too.

    A dict, so that the check on every stroke (``drawing in cancelled``) stays one lookup.
    """

    def cancel(self, drawing: str, at_ms: float) -> None:
        self[drawing] = at_ms
        self.move_to_end(drawing)
        while len(self) > REMEMBERED_CANCELS:
            self.popitem(last=False)


@dataclass(frozen=True)
class Arrival:
    """A stroke reaching the sleeve at ``arrival_ms`` (``drawing`` and ``seq`` may be None)."""

    arrival_ms: float
    duration_ms: float
    drawing: str | None = None
    seq: int | None = None


@dataclass(frozen=True)
class CancelAt:
    """A cancel of ``drawing`` (None: every drawing) reaching the sleeve at ``at_ms``."""

    at_ms: float
    drawing: str | None = None


@dataclass(frozen=True)
class Outcome:
    """What became of one arrival. ``start_ms`` and ``played_ms`` are None unless it started
    (``played`` or ``cut``); ``played_ms`` is how long it played before a cancel cut it."""

    outcome: str
    start_ms: float | None = None
    played_ms: float | None = None


class Simulation:
    """A sleeve's queue played out at once, with no player thread: the strokes placed and not
    cancelled, each with its start. It answers admission's questions
    (:class:`feelmysign.sleeve.admission.QueueState`) for an arrival at any time."""

    def __init__(self, floor_ms: float | None = None) -> None:
        self.queue = Queue()
        # The sleeve's floor: strokes behind their own drawing catch up down to it (None: not).
        self.floor_ms = floor_ms
        # Placed and not cancelled: key -> (start, duration, drawing, seq).
        self.planned: dict[int, tuple[float, float, str | None, int | None]] = {}

    def place(
        self, key: int, arrival_ms: float, duration_ms: float, drawing: str | None, seq: int | None
    ) -> float:
        """Queue a stroke under ``key``: when it starts."""
        if self.floor_ms is not None:
            duration_ms = self.queue.catch_up_ms(arrival_ms, duration_ms, self.floor_ms, drawing)
        if drawing is not None and seq is not None:
            start = self.queue.place(arrival_ms, duration_ms, drawing, seq)
        else:
            start = self.queue.place(arrival_ms, duration_ms)
        self.planned[key] = (start, duration_ms, drawing, seq)
        return start

    def cancel(self, cancel: CancelAt) -> dict[int, Outcome]:
        """The strokes ``cancel`` cuts or drops, by key: each leaves the queue."""
        now = cancel.at_ms
        cut: dict[int, Outcome] = {}
        for key, (start, duration, drawing, _) in list(self.planned.items()):
            over = start + duration <= now
            if over or (cancel.drawing is not None and drawing != cancel.drawing):
                continue  # over already, or another drawing's
            del self.planned[key]
            cut[key] = Outcome(CUT, start, now - start) if start <= now else Outcome(CANCELLED)
        # What still plays (and what played already, ending before now) sets the tail.
        self.queue.replan(
            (start + duration, drawing) for start, duration, drawing, _ in self.planned.values()
        )
        return cut

    def waiting(self, drawing: object, seq: object, now_ms: float) -> bool:
        if drawing is None or seq is None:
            return False  # a legacy stroke has no identity: never a copy (as the player)
        return any(
            d == drawing and s == seq and start > now_ms for start, _, d, s in self.planned.values()
        )

    def seen(self, drawing: object, seq: object) -> bool:
        return self.queue.seen(drawing, seq)

    def wait_ms(self, now_ms: float) -> float:
        return self.queue.wait_ms(now_ms)


def replay(steps: Sequence[Arrival | CancelAt], floor_ms: float) -> list[Outcome]:
    """The sleeve's queue over a whole sequence, in the order the steps reach it (their
    times never decrease): one outcome per arrival, in order. Copies and strokes of a
    cancelled drawing meet admission's rules; every other stroke plays (no planner, no
    pace, rate or duty-cycle rules here). Strokes behind their own drawing are caught up
    down to ``floor_ms`` (the sleeve's shortest unslowed stroke), as the player does; a
    ``played`` outcome's ``played_ms`` is then below its duration."""
    # Here, not at the top: admission keeps its cancelled drawings in this module.
    from feelmysign.sleeve.admission import copy_of

    simulation = Simulation(floor_ms)
    outcomes: list[Outcome | None] = []
    cancelled = CancelledDrawings()
    for step in steps:
        if isinstance(step, CancelAt):
            for index, outcome in simulation.cancel(step).items():
                outcomes[index] = outcome
            if step.drawing is not None:
                cancelled.cancel(step.drawing, step.at_ms)
            continue
        copy = copy_of(step.drawing, step.seq, step.arrival_ms, True, cancelled, simulation)
        if copy is not None:
            outcomes.append(Outcome(copy))
            continue
        simulation.place(len(outcomes), step.arrival_ms, step.duration_ms, step.drawing, step.seq)
        outcomes.append(None)
    for index, (start, duration, _, _) in simulation.planned.items():
        outcomes[index] = Outcome(PLAYED, start, duration)
    return [o for o in outcomes if o is not None]
