"""Tactile Brush: from a stroke to a schedule of actuator commands.

Follows A. Israr and I. Poupyrev, "Tactile Brush: Drawing on Skin with a Tactile
Grid Display" (CHI 2011), with the interior-endpoint extension of F. Tang et al.
(IEEE VR 2015) and the fixes listed in ``tactile-brush.md``: endpoints anywhere
inside the grid, every direction, near-duplicate crossings merged, a
feasibility rule (no negative or too-short burst), and overlapping commands on
one actuator merged into one piecewise-constant intensity (``overlaps``).

Time is kept: a stroke plays in the time it was drawn. When the motion model
cannot fit every virtual actuator into that time, it keeps the most crossings
that fit, evenly spread in time (``apparent_motion.thinned``). A stroke is slowed only
when even its simplest rendering, apparent motion between its two end
phantoms, cannot fit: below ``shortest_planned_ms`` (73.7 ms for 20 ms bursts),
whatever its length or direction, so the planned duration is continuous in the
endpoints. And no burst runs on past the stroke's end by more than
``overrun_allowance_ms`` (``_bursts`` cuts it there): the next stroke starts then.

The stroke's path is sampled at *virtual actuators* (its endpoints and every
crossing with a row or column line). Each virtual actuator gets one burst,
timed by the apparent-motion model (``SOA = 0.32 d + 47.3``), and is rendered
by funneling on the physical actuators around it.

Grid (x = column, y = row), the paper's sleeve::

      x=0   x=1   x=2   x=3
  y=0  o-----o-----o-----o
       |     |     |     |
  y=1  o-----o-----o-----o       o = actuator, 3.0 cm apart
       |     |     |     |
  y=2  o-----o-----o-----o
"""

from __future__ import annotations

import itertools
import math
import operator
from collections import defaultdict
from collections.abc import Iterable, Iterator, Sequence

from feelmysign.apparent_motion import (
    Timing,
    each_timing,
    fitting_timings,
    lengths_bound_ms,
    shortest_planned_ms,
    surely_fits,
    thinned,
    timings,
)
from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.overlaps import COLUMN_MASK, ROW_SHIFT, ROW_STEP, Span, commands_from_spans
from feelmysign.protocol import playable
from feelmysign.schedule import Adjustment, Burst, Command, Schedule
from feelmysign.stroke import Point, Stroke

# A burst may run on past the stroke's end (the motion model lets the last
# bursts overlap), but the next stroke of a drawing starts at the end: by at most
# the larger of these. 50 ms is about the least SOA of apparent motion (47.3 ms),
# so a shorter overrun is never felt as a touch of its own.
OVERRUN_MIN_MS = 50.0
OVERRUN_FRACTION = 0.1

# Virtual actuators closer than this (grid units; 1.5 mm on a 3 cm grid, far
# below the forearm's two-point threshold of about 35 mm) are one point to the
# skin: a stroke passing a hair beside an actuator crosses its row and its
# column a hair apart, and is felt crossing once.
MERGE_DISTANCE = 0.05

# Coordinates within this of a grid line are on it (float noise, not geometry).
ON_LINE_EPSILON = 1e-9

_OFF_LINE = 1 - ON_LINE_EPSILON  # a coordinate this far into a cell is on its next line

TOO_FAST = "too_fast"

# Strokes of at least this many virtual actuators are timed when asked for when they surely
# fit (``apparent_motion.surely_fits``); for fewer, timing them all costs less than the test.
_TIMED_LATER = 4

# One burst: a Burst (x, y in grid units, peak_ms, start_ms, duration_ms, intensity), made
# as a plain tuple of the same six fields (tuple.__new__, in C) on the planning path.
RawBurst = Burst

# Planning runs on the sleeve before a stroke's first motor command, so the code
# below works on plain tuples and builds the public dataclasses only for its
# result. Every float that reaches a schedule is computed with the same
# operations in the same order as the published formulas (and the TypeScript
# and Java ports): the shared vectors in testdata/planner are compared bit for bit.


def plan(
    stroke: Stroke,
    layout: Layout,
    *,
    min_command_ms: float | None = None,
    merge_distance: float = MERGE_DISTANCE,
    strict: bool = False,
) -> Schedule:
    """Plan one stroke on ``layout``'s grid, in the time it was drawn.

    ``min_command_ms`` (default: the layout's ``shortest_burst_ms``) is the
    shortest burst. Virtual actuators that do not fit the stroke's duration are
    left out (counted in ``thinned``). A stroke shorter than
    ``shortest_planned_ms`` is slowed to it and the schedule says so in
    ``adjusted``; with ``strict`` it is rejected instead. Raises StrokeError
    for a stroke that cannot be rendered at all (non-finite, outside the grid,
    bad duration).
    """
    return outline(
        stroke, layout, min_command_ms=min_command_ms, merge_distance=merge_distance, strict=strict
    ).schedule()


def outline(
    stroke: Stroke,
    layout: Layout,
    *,
    min_command_ms: float | None = None,
    merge_distance: float = MERGE_DISTANCE,
    strict: bool = False,
) -> Outline:
    """The stroke planned up to its bursts (``plan`` without the commands yet).

    Every check ``plan`` makes is made here, so a stroke with an outline plans;
    its ``schedule()`` is the one ``plan`` returns, and ``head()`` the first of
    its commands, computed without the rest (see ``Outline``).
    """
    given = _plain_stroke(stroke, layout)
    if given is None:  # clamped onto the grid, or the sleeve's StrokeError saying what is wrong
        stroke = playable(stroke, layout)
        start, end = stroke.start, stroke.end
    else:
        start, end = given
    intensity = stroke.intensity
    if intensity is None:
        intensity = layout.default_intensity
    min_ms = layout.shortest_burst_ms if min_command_ms is None else min_command_ms
    duration_ms = stroke.duration_ms
    adjusted = None
    if not duration_ms >= shortest_planned_ms(min_ms):  # _kept_duration's first test, inline
        duration_ms, adjusted = _kept_duration(stroke, start, end, min_ms, strict=strict)
    if duration_ms > layout.max_stroke_duration_ms:
        if adjusted is None:  # too long as sent: the protocol's refusal, as the sleeve words it
            playable(stroke, layout)
        raise StrokeError(  # too long once slowed: the layout's shortest burst made it so
            "duration_too_long",
            f"stroke needs {duration_ms:.3f} ms, more than the sleeve's maximum of "
            f"{layout.max_stroke_duration_ms:g} ms; send a slower, shorter stroke",
        )
    # The fractions and timings of every burst: whether they all fit decides which are
    # kept. Their points and bursts are made when asked for (``Outline.bursts``), or only
    # the first few of them (``Outline.head``). A stroke of many crossings whose closest
    # peaks are far enough apart surely fits: its timings too are computed when asked for,
    # so that its first motors start in the same time whatever its length.
    fractions = _fractions(start, end, merge_distance)
    left_out = 0
    burst_timings: list[Timing] | None = None  # None: they surely fit, timed when asked for
    if len(fractions) < _TIMED_LATER or not surely_fits(fractions, duration_ms, min_ms):
        burst_timings = fitting_timings(fractions, duration_ms, min_ms)
        if burst_timings is None:
            kept = thinned(fractions, duration_ms, min_ms)
            left_out = len(fractions) - len(kept)
            fractions = [fractions[i] for i in kept]
            burst_timings = timings(fractions)
    return Outline(
        stroke,
        layout,
        duration_ms,
        adjusted,
        intensity,
        min_ms,
        (start, end, fractions, burst_timings),
        left_out,
    )


class Outline:
    """A stroke planned up to its bursts, each ``(x, y, peak_ms, start_ms, duration_ms)``.

    What admitting a stroke needs (its duration, whether it was slowed) is
    here; the commands are not yet, nor the bursts: only each burst's fraction
    of the way and timing. ``schedule()`` makes all of them (what ``plan``
    returns); ``head(before_ms)`` only the commands that start before
    ``before_ms``, exactly as ``schedule()`` has them, from the few first
    bursts around the actuators they drive: a sleeve starts a long stroke's
    first motors without planning the rest first.
    """

    __slots__ = (
        "_bursts",
        "_schedule",
        "_way",
        "adjusted",
        "duration_ms",
        "intensity",
        "layout",
        "min_command_ms",
        "stroke",
        "thinned",
    )

    def __init__(
        self,
        stroke: Stroke,
        layout: Layout,
        duration_ms: float,
        adjusted: Adjustment | None,
        intensity: float,
        min_command_ms: float,
        way: tuple[Point, Point, list[float], list[Timing] | None],
        thinned: int,
    ) -> None:
        self.stroke = stroke
        self.layout = layout
        self.duration_ms = duration_ms
        self.adjusted = adjusted
        self.intensity = intensity
        self.min_command_ms = min_command_ms
        # Start, end, and each burst's fraction of the way and timing (apparent_motion.Timing;
        # None until asked for, for a stroke that surely fits: see ``outline``).
        self._way = way
        self.thinned = thinned
        self._bursts: tuple[RawBurst, ...] | None = None
        self._schedule: Schedule | None = None

    @property
    def bursts(self) -> tuple[RawBurst, ...]:
        """Every burst, in stroke order (made once)."""
        if self._bursts is None:
            start, end, fractions, burst_timings = self._timed_way()
            self._bursts = _bursts(
                start, end, fractions, burst_timings, self.duration_ms, self.intensity
            )
        return self._bursts

    def schedule(self) -> Schedule:
        """The whole schedule (made once)."""
        if self._schedule is None:
            intensity = self.intensity
            bursts = self.bursts
            spans = _spans_by_actuator(bursts, intensity, self.layout)
            self._schedule = Schedule(
                self.stroke,
                commands_from_spans(spans, self.min_command_ms),
                self.duration_ms,
                self.adjusted,
                bursts,
                self.thinned,
            )
        return self._schedule

    def head(self, before_ms: float) -> tuple[Command, ...]:
        """The schedule's commands that start before ``before_ms``, in its order.

        Only an actuator a burst starting before ``before_ms`` drives can have
        such a command; its commands depend on every burst that drives it (an
        overlap merges them) and on nothing else. A burst drives an actuator
        only from less than one grid unit away along each axis, and the stroke
        moves monotonically along each axis: once a burst lies one grid unit or
        more from an actuator along an axis, having started nearer, it has passed
        it there for good. So the bursts are read in order until one lies so
        from each of these actuators: no burst after it drives any of them.
        Bursts start in order (each at least an SOA, 35.8 ms, after the one
        before), so those starting before ``before_ms`` come first; only the
        bursts read are made.
        """
        if self._schedule is not None:
            return tuple(c for c in self._schedule.commands if c.start_ms < before_ms)
        intensity, layout = self.intensity, self.layout
        read: list[RawBurst] = []  # the bursts that start before before_ms, in order
        # The spans of those bursts per actuator they drive (by key), once they are all read.
        spans: dict[int, list[Span]] | None = None
        later: list[RawBurst] = []  # the bursts read after them, in order
        for burst in self._each_burst():
            if spans is None:
                if burst[3] < before_ms:
                    read.append(burst)
                    continue
                spans = _spans_by_actuator(read, intensity, layout)
            if _far_from(burst, spans):
                break
            later.append(burst)
        if spans is None:  # every burst starts before before_ms
            spans = _spans_by_actuator(read, intensity, layout)
        elif later:
            # The later bursts' spans on those actuators follow theirs (per actuator in stroke
            # order, as one burst at a time would gather them); other actuators are left out.
            more = _spans_by_actuator(later, intensity, layout)
            for key, actuator_spans in spans.items():
                if key in more:
                    actuator_spans += more[key]
        return tuple(
            c for c in commands_from_spans(spans, self.min_command_ms) if c.start_ms < before_ms
        )

    def _each_burst(self) -> Iterator[RawBurst]:
        """The bursts in order, each made as ``bursts`` makes it, as they are asked for."""
        if self._bursts is not None:
            yield from self._bursts
            return
        start, end, fractions, burst_timings = self._way
        timed = each_timing(fractions) if burst_timings is None else iter(burst_timings)
        t = self.duration_ms
        intensity = self.intensity
        new = tuple.__new__
        latest_end = t + overrun_allowance_ms(t)
        last = len(fractions) - 1
        (x0, y0), (x1, y1) = start, end
        dx, dy = x1 - x0, y1 - y0
        for (i, f), timing in zip(enumerate(fractions), timed, strict=True):
            if f == 0.0:  # _points, for one fraction
                x, y = start
            elif f == 1.0:
                x, y = end
            else:
                x, y = x0 + dx * f, y0 + dy * f
                nearest = round(x)
                if abs(x - nearest) <= ON_LINE_EPSILON:
                    x = float(nearest)
                nearest = round(y)
                if abs(y - nearest) <= ON_LINE_EPSILON:
                    y = float(nearest)
            onset_a, onset_b, length_a, length_b = timing
            start_ms = onset_a * t + onset_b
            if i < last:  # as _bursts makes them
                length_ms = length_a * t + length_b
                if start_ms + length_ms > latest_end:
                    length_ms = latest_end - start_ms
            else:
                length_ms = t - start_ms
            yield new(Burst, (x, y, f * t, start_ms, length_ms, intensity))

    def energy_bound_ms(self) -> float:
        """At least the energy (intensity squared x ms) any one actuator gets from the stroke.

        Funneling splits a burst's energy among its actuators, overlaps add
        energies (capped at full drive) and a join keeps them: so no actuator
        gets more than the bursts' energy together. Before the bursts are made
        (a stroke's first motors start before that), from their timings: the
        sum of their lengths before any is cut at the overrun allowance (a cut
        only shortens a burst), as ``T * sum(a) + sum(b)`` (summed in C, not per
        burst), with a margin far above its rounding; before they are timed, from
        the motion model's bound on that sum (``apparent_motion.lengths_bound_ms``).
        """
        energy = self.intensity**2
        if self._bursts is not None:
            return sum(energy * d for _, _, _, _, d, _ in self._bursts if d > 0)
        _, _, fractions, burst_timings = self._way
        if burst_timings is None:
            total_ms = lengths_bound_ms(fractions, self.duration_ms)
        else:
            slopes: float = sum(map(_LENGTH_A, burst_timings))
            intercepts_ms: float = sum(map(_LENGTH_B, burst_timings))
            total_ms = self.duration_ms * slopes + intercepts_ms
        margin_ms = _BOUND_MARGIN_MS * len(fractions)
        return energy * (total_ms * (1 + _BOUND_MARGIN) + margin_ms)

    def _timed_way(self) -> tuple[Point, Point, list[float], list[Timing]]:
        """``_way`` with every burst timed (now, if it was not)."""
        start, end, fractions, burst_timings = self._way
        if burst_timings is None:
            burst_timings = timings(fractions)
            self._way = (start, end, fractions, burst_timings)
        return start, end, fractions, burst_timings


# Of a burst's timing (apparent_motion.Timing): its length's coefficients, length = a T + b.
_LENGTH_A, _LENGTH_B = operator.itemgetter(2), operator.itemgetter(3)
# The rounding of a sum of lengths computed two ways is about 1e-16 of it: far below these.
# A length may also fall short of 0 by a rounding when the shortest burst is 0 ms.
_BOUND_MARGIN = 1e-9
_BOUND_MARGIN_MS = 1e-6


def overrun_allowance_ms(duration_ms: float) -> float:
    """How long after a stroke of ``duration_ms`` its bursts may still run."""
    return max(OVERRUN_MIN_MS, OVERRUN_FRACTION * duration_ms)


def _kept_duration(
    stroke: Stroke, start: Point, end: Point, min_command_ms: float, *, strict: bool
) -> tuple[float, Adjustment | None]:
    """The stroke's own duration, or the shortest plannable one (or StrokeError if strict)."""
    needed_ms = shortest_planned_ms(min_command_ms)
    if stroke.duration_ms >= needed_ms:
        return stroke.duration_ms, None
    if strict:
        raise StrokeError(
            TOO_FAST,
            f"stroke too fast: {stroke.duration_ms:g} ms over {math.dist(start, end):.4g} grid "
            f"units; the least a stroke can be felt in is {needed_ms:.3f} ms (apparent motion "
            f"between its two ends, bursts of {min_command_ms:g} ms); send it slower or plan "
            "without --strict to slow it automatically",
        )
    return needed_ms, Adjustment(TOO_FAST, stroke.duration_ms, needed_ms)


def _plain_stroke(stroke: Stroke, layout: Layout) -> tuple[Point, Point] | None:
    """The stroke's endpoints when it is plainly valid as it is, else None.

    Plainly valid: float coordinates on the grid, a finite positive float
    duration, an intensity in [0, 1] or none; ``protocol.playable`` would pass
    it and its clamping keep its values. Anything else (None) goes through
    ``playable``, for the clamping or the sleeve's error (the duration cap is
    checked once the duration is known, after any slowing). Most strokes,
    parsed from the protocol, are plain, and this costs a fraction of those checks.
    """
    try:
        (x0, y0), (x1, y1) = start, end = stroke.start, stroke.end
    except (TypeError, ValueError):
        return None  # playable says what is wrong
    x_max, y_max = layout.columns - 1, layout.rows - 1
    duration_ms = stroke.duration_ms
    if not (
        type(x0) is float
        and type(y0) is float
        and type(x1) is float
        and type(y1) is float
        and type(duration_ms) is float
        # Comparisons fail for NaN, so these also say every number is finite.
        and 0.0 <= x0 <= x_max
        and 0.0 <= x1 <= x_max
        and 0.0 <= y0 <= y_max
        and 0.0 <= y1 <= y_max
        and 0.0 < duration_ms < math.inf
    ):
        return None
    intensity = stroke.intensity
    # Last, as playable tests it after the numbers (a TypeError for a string
    # here is the one it would raise).
    if intensity is not None and not 0.0 <= intensity <= 1.0:
        return None
    return start, end


def virtual_actuators(
    start: Point, end: Point, *, merge_distance: float = MERGE_DISTANCE
) -> tuple[list[Point], list[float]]:
    """The stroke's virtual actuators, in order, and their fractions of the way (0 .. 1).

    The endpoints and every crossing with a grid line; points closer than
    ``merge_distance`` become one (an endpoint wins; otherwise their midpoint,
    which still lies on the stroke). A stroke of zero length has one point.
    """
    fractions = _fractions(start, end, merge_distance)
    return _points(start, end, fractions), fractions


def _fractions(start: Point, end: Point, merge_distance: float) -> list[float]:
    """The fractions of the way of ``virtual_actuators``."""
    length = math.dist(start, end)
    if length <= ON_LINE_EPSILON:
        return [0.0]
    (x0, y0), (x1, y1) = start, end
    # The fractions in (0, 1) where x, then y, goes through an integer: inline, with no call
    # and no list comprehension's frame per axis.
    crossings = []
    step = x1 - x0
    if abs(step) > ON_LINE_EPSILON:
        low, high = (x0, x1) if x0 < x1 else (x1, x0)
        for k in range(math.ceil(low - ON_LINE_EPSILON), math.floor(high + ON_LINE_EPSILON) + 1):
            if 0.0 < (f := (k - x0) / step) < 1.0:
                crossings.append(f)
    step = y1 - y0
    if abs(step) > ON_LINE_EPSILON:
        low, high = (y0, y1) if y0 < y1 else (y1, y0)
        for k in range(math.ceil(low - ON_LINE_EPSILON), math.floor(high + ON_LINE_EPSILON) + 1):
            if 0.0 < (f := (k - y0) / step) < 1.0:
                crossings.append(f)
    if not crossings:  # within one cell (most strokes of a drawing): what merging leaves
        return [0.0, 1.0]
    if len(crossings) > 1:
        crossings = sorted(set(crossings))  # a stroke through an actuator crosses both lines there
    return _merged_fractions([0.0, *crossings, 1.0], merge_distance / length)


def _points(start: Point, end: Point, fractions: Iterable[float]) -> list[Point]:
    """The points of the way at these fractions: the endpoints themselves at 0 and 1, each
    crossing snapped onto the grid line it crosses."""
    points: list[Point] = []
    append = points.append
    (x0, y0), (x1, y1) = start, end
    dx, dy = x1 - x0, y1 - y0
    for f in fractions:
        if f == 0.0:
            append(start)
        elif f == 1.0:
            append(end)
        else:
            # _snap of each coordinate, inline: a stroke's every crossing is snapped.
            x, y = x0 + dx * f, y0 + dy * f
            nearest = round(x)
            if abs(x - nearest) <= ON_LINE_EPSILON:
                x = float(nearest)
            nearest = round(y)
            if abs(y - nearest) <= ON_LINE_EPSILON:
                y = float(nearest)
            append((x, y))
    return points


def _merged_fractions(fractions: list[float], merge_fraction: float) -> list[float]:
    """Group sorted fractions closer than ``merge_fraction``; keep 0 and 1 exactly.

    A group is represented by its midpoint, unless it holds an endpoint, which wins.
    """
    merged: list[float] = []
    append = merged.append
    first = last = fractions[0]  # of the group being gathered; only they decide its point
    for f in itertools.islice(fractions, 1, None):
        if f - first < merge_fraction:
            last = f
        elif first == last:  # a group of one: its own point (what the midpoint gives)
            append(first)
            first = last = f
        else:
            append(0.0 if first == 0.0 else 1.0 if last == 1.0 else (first + last) / 2)
            first = last = f
    if not merged:
        return [0.0, 1.0]  # shorter than the merge distance: just its two endpoints
    append(0.0 if first == 0.0 else 1.0 if last == 1.0 else (first + last) / 2)
    return merged


def _snap(value: float) -> float:
    nearest = round(value)
    return float(nearest) if abs(value - nearest) <= ON_LINE_EPSILON else value


def _bursts(
    start: Point,
    end: Point,
    fractions: Sequence[float],
    timings: Sequence[Timing],
    duration_ms: float,
    intensity: float,
) -> tuple[Burst, ...]:
    """The bursts at stroke duration ``duration_ms``, the last ending exactly there, each
    at its point of the way (``_points``, made here in the same pass).

    A burst that would run on past the end by more than the allowance is cut
    there: the motion has reached the stroke's end, and its actuator still
    buzzing would pull the felt point back, into the next stroke's time.
    Each ``Burst`` is made in C as ``commands_from_spans`` makes its commands
    (the named tuple's __new__ is Python).
    """
    t = duration_ms
    allowance_ms = OVERRUN_FRACTION * t  # overrun_allowance_ms, inline
    latest_end = t + (allowance_ms if allowance_ms > OVERRUN_MIN_MS else OVERRUN_MIN_MS)
    last = len(fractions) - 1
    new = tuple.__new__
    bursts: list[Burst] = []
    append = bursts.append
    (x0, y0), (x1, y1) = start, end
    dx, dy = x1 - x0, y1 - y0
    for i, f in enumerate(fractions):
        # The point of the way at f, as _points makes it (made here: no list of points).
        if f == 0.0:
            x, y = start
        elif f == 1.0:
            x, y = end
        else:
            x, y = x0 + dx * f, y0 + dy * f
            nearest = round(x)
            if abs(x - nearest) <= ON_LINE_EPSILON:
                x = float(nearest)
            nearest = round(y)
            if abs(y - nearest) <= ON_LINE_EPSILON:
                y = float(nearest)
        onset_a, onset_b, length_a, length_b = timings[i]
        start_ms = onset_a * t + onset_b
        if i < last:
            length_ms = length_a * t + length_b
            if start_ms + length_ms > latest_end:
                length_ms = latest_end - start_ms
        else:
            # The model's last duration is T - S too, but evaluated as a T + b it would
            # leave a float residue after the stroke's end.
            length_ms = t - start_ms
        append(new(Burst, (x, y, f * t, start_ms, length_ms, intensity)))
    return tuple(bursts)


def _far_from(burst: RawBurst, actuators: Iterable[int]) -> bool:
    """Whether the burst lies one grid unit or more from each actuator (by its
    ``overlaps.actuator_key``) along some axis: it does not drive any of them."""
    x, y = burst[0], burst[1]
    for key in actuators:  # a loop, not all() over a generator: read before a first command
        if abs(x - (key & COLUMN_MASK)) < 1 and abs(y - (key >> ROW_SHIFT)) < 1:
            return False
    return True


def render_point(burst: Burst, layout: Layout) -> list[Command]:
    """Funneling: the physical commands that make one virtual actuator felt.

    A point on an actuator drives it alone; on a grid line, the two actuators
    around it (``A1 = sqrt(1 - beta) A``, ``A2 = sqrt(beta) A``); strictly inside
    a cell, the four corners with ``A sqrt(wx wy)`` (Tang et al.: funneling
    applied twice, which factorises). The squares always sum to ``A**2``.
    """
    return [
        Command(row, column, burst.start_ms, burst.duration_ms, intensity)
        for row, column, intensity in _funneled(burst, layout)
    ]


def _funneled(burst: Burst, layout: Layout) -> list[tuple[int, int, float]]:
    """(row, column, intensity) of each physical actuator rendering ``burst``."""
    column_weights = _axis_weights(burst.x, layout.columns)
    row_weights = _axis_weights(burst.y, layout.rows)
    return [
        (row, column, burst.intensity * math.sqrt(wx * wy))
        for row, wy in row_weights
        for column, wx in column_weights
    ]


def _axis_weights(coordinate: float, count: int) -> list[tuple[int, float]]:
    """(index, weight) of the one or two actuators around a coordinate; weights sum to 1."""
    # The last line belongs to the cell before it (no cell starts there). As
    # min(floor, count - 1) without a builtin call, which shows on the hot path.
    floor = math.floor(coordinate)
    low = floor if floor < count - 1 else count - 1
    fraction = coordinate - low
    if fraction <= ON_LINE_EPSILON:
        return [(low, 1.0)]
    if fraction >= _OFF_LINE:
        return [(low + 1, 1.0)]
    return [(low, 1.0 - fraction), (low + 1, fraction)]


def _spans_by_actuator(
    bursts: Iterable[RawBurst], intensity: float, layout: Layout
) -> dict[int, list[Span]]:
    """The rendered commands of the bursts, in stroke order, per actuator (by its
    ``overlaps.actuator_key``); none empty."""
    if not intensity >= _LEAST_SAFE_INTENSITY:
        return _spans_by_actuator_checked(bursts, intensity, layout)
    by_actuator: defaultdict[int, list[Span]] = defaultdict(list)
    last_column, last_row = layout.columns - 1, layout.rows - 1
    sqrt, floor = math.sqrt, math.floor
    below = ROW_STEP  # the key of the actuator below another, less that actuator's
    for x, y, _, span_start, length_ms, _ in bursts:
        if length_ms <= 0:
            continue
        span_end = span_start + length_ms  # as Command.end_ms computes it
        # _funneled, unrolled for each case of _axis_weights of x and of y: no call,
        # no list and no loop per burst on the planning path. A weight of 1.0 leaves
        # intensity * sqrt(wx * wy) as it is (times 1.0 and sqrt(1.0) are exact).
        column = floor(x)
        if column > last_column:
            column = last_column
        fx = x - column
        row = floor(y)
        if row > last_row:
            row = last_row
        fy = y - row
        if fx <= ON_LINE_EPSILON or fx >= _OFF_LINE:  # on a column line
            if fx > ON_LINE_EPSILON:
                column += 1
            if fy <= ON_LINE_EPSILON or fy >= _OFF_LINE:  # on an actuator
                if fy > ON_LINE_EPSILON:
                    row += 1
                by_actuator[row << ROW_SHIFT | column].append((span_start, span_end, intensity))
            else:  # between two rows
                key = row << ROW_SHIFT | column
                by_actuator[key].append((span_start, span_end, intensity * sqrt(1.0 - fy)))
                by_actuator[key + below].append((span_start, span_end, intensity * sqrt(fy)))
        elif fy <= ON_LINE_EPSILON or fy >= _OFF_LINE:  # on a row line, between two columns
            if fy > ON_LINE_EPSILON:
                row += 1
            key = row << ROW_SHIFT | column
            by_actuator[key].append((span_start, span_end, intensity * sqrt(1.0 - fx)))
            by_actuator[key + 1].append((span_start, span_end, intensity * sqrt(fx)))
        else:  # inside a cell: its four corners
            wx = 1.0 - fx
            wy = 1.0 - fy
            key = row << ROW_SHIFT | column
            by_actuator[key].append((span_start, span_end, intensity * sqrt(wx * wy)))
            by_actuator[key + 1].append((span_start, span_end, intensity * sqrt(fx * wy)))
            by_actuator[key + below].append((span_start, span_end, intensity * sqrt(wx * fy)))
            by_actuator[key + below + 1].append((span_start, span_end, intensity * sqrt(fx * fy)))
    return by_actuator


# Above this, intensity times a funneling weight (at least 1e-9, see
# ON_LINE_EPSILON) is never 0: no span of a stroke so intense is empty.
_LEAST_SAFE_INTENSITY = 1e-280


def _spans_by_actuator_checked(
    bursts: Iterable[RawBurst], intensity: float, layout: Layout
) -> dict[int, list[Span]]:
    """``_spans_by_actuator`` for a stroke so faint (or off) that a span may be 0: left out."""
    by_actuator: dict[int, list[Span]] = {}
    for x, y, _, span_start, length_ms, _ in bursts:
        if length_ms <= 0:
            continue
        burst = Burst(x, y, 0.0, span_start, length_ms, intensity)
        for row, column, value in _funneled(burst, layout):
            if value > 0:
                by_actuator.setdefault(row << ROW_SHIFT | column, []).append(
                    (span_start, span_start + length_ms, value)
                )
    return by_actuator
