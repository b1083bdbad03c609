"""Tactile Brush: from a stroke to a schedule of actuator commands.

Follows A. Israr and I. Poupyrev, "Tactile Brush: Drawing on Skin with a Tactile
Grid Display" (CHI 2011), with the interior-endpoint extension of F. Tang et al.
(IEEE VR 2015) and the fixes listed in ``tactile-brush.md``: endpoints anywhere
inside the grid, every direction, near-duplicate crossings merged, a
feasibility rule (no negative or too-short burst), and overlapping commands on
one actuator merged into one piecewise-constant intensity.

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
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace

from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.schedule import Adjustment, Burst, Command, Schedule
from feelmysign.stroke import Point, Stroke

SOA_SLOPE = 0.32  # Israr & Poupyrev 2011, eq. 1: SOA = 0.32 d + 47.3 (ms)
SOA_INTERCEPT_MS = 47.3  # ibid.; also the least time between two peaks of a moving touch

# An ERM motor needs about 20 ms from rest to a felt vibration; a shorter burst
# is not felt as part of the motion. Configurable per call.
MIN_COMMAND_MS = 20.0

# Virtual actuators closer than this (grid units; 1.5 mm on a 3 cm grid, far
# below the forearm's two-point threshold of about 35 mm) are one point to the
# skin. Merging them matters: the motion model needs more than 47.3 ms between
# consecutive peaks, so two crossings a hair apart (a stroke passing next to an
# actuator) would otherwise force the stroke to be slowed to many seconds.
MERGE_DISTANCE = 0.05

# Coordinates within this of a grid line are on it (float noise, not geometry).
ON_LINE_EPSILON = 1e-9

TOO_FAST = "too_fast"


@dataclass(frozen=True)
class _Affine:
    """``a * T + b``: every time in the motion model is affine in the stroke duration T."""

    a: float
    b: float

    def at(self, duration_ms: float) -> float:
        return self.a * duration_ms + self.b

    def __add__(self, other: _Affine) -> _Affine:
        return _Affine(self.a + other.a, self.b + other.b)

    def __sub__(self, other: _Affine) -> _Affine:
        return _Affine(self.a - other.a, self.b - other.b)

    def scaled(self, k: float) -> _Affine:
        return _Affine(self.a * k, self.b * k)


def plan(
    stroke: Stroke,
    layout: Layout,
    *,
    min_command_ms: float = MIN_COMMAND_MS,
    merge_distance: float = MERGE_DISTANCE,
    strict: bool = False,
) -> Schedule:
    """Plan one stroke on ``layout``'s grid.

    A stroke too fast for every burst to last ``min_command_ms`` is slowed to
    the fastest feasible duration and the schedule says so in ``adjusted``;
    with ``strict`` it is rejected instead. Raises StrokeError for a stroke that
    cannot be rendered at all (non-finite, outside the grid, bad duration).
    """
    start, end = _checked_stroke(stroke, layout)
    intensity = layout.default_intensity if stroke.intensity is None else stroke.intensity
    points, fractions = virtual_actuators(start, end, merge_distance=merge_distance)
    timings = _timings(fractions)
    needed_ms = _fastest_feasible_ms(timings, min_command_ms)
    duration_ms = stroke.duration_ms
    adjusted = None
    if duration_ms < needed_ms:
        message = (
            f"stroke too fast: {duration_ms:g} ms over {math.dist(start, end):.4g} grid units "
            f"needs at least {needed_ms:.3f} ms so that every burst lasts {min_command_ms:g} ms "
            f"or more; send it slower or plan without --strict to slow it automatically"
        )
        if strict:
            raise StrokeError(TOO_FAST, message)
        adjusted = Adjustment(TOO_FAST, stroke.duration_ms, needed_ms)
        duration_ms = needed_ms
    if duration_ms > layout.max_stroke_duration_ms:
        raise StrokeError(
            "duration_too_long",
            f"stroke needs {duration_ms:.3f} ms, more than the sleeve's maximum of "
            f"{layout.max_stroke_duration_ms:g} ms; send a slower, shorter stroke",
        )
    bursts = tuple(
        Burst(
            x=p[0],
            y=p[1],
            peak_ms=f * duration_ms,
            start_ms=on.at(duration_ms),
            duration_ms=d.at(duration_ms),
            intensity=intensity,
        )
        for p, f, (on, d) in zip(points, fractions, timings, strict=True)
    )
    bursts = _pin_last_end(bursts, duration_ms)
    raw = [c for b in bursts for c in render_point(b, layout)]
    commands = merge_commands(raw, min_command_ms=min_command_ms)
    canonical = replace(stroke, start=start, end=end)
    return Schedule(canonical, commands, duration_ms, adjusted, bursts)


def _checked_stroke(stroke: Stroke, layout: Layout) -> tuple[Point, Point]:
    """The stroke's endpoints clamped onto the grid, or StrokeError saying what is wrong."""
    values = (*stroke.start, *stroke.end, stroke.duration_ms)
    if not all(math.isfinite(v) for v in values):
        raise StrokeError("not_finite", f"stroke has a non-finite number: {values}")
    if stroke.duration_ms <= 0:
        raise StrokeError(
            "duration_not_positive",
            f"duration_ms must be more than 0, got {stroke.duration_ms:g}",
        )
    if stroke.intensity is not None and not 0.0 <= stroke.intensity <= 1.0:
        raise StrokeError(
            "intensity_out_of_range", f"intensity must be in [0, 1], got {stroke.intensity:g}"
        )
    return _on_grid(stroke.start, "start", layout), _on_grid(stroke.end, "end", layout)


def _on_grid(point: Point, name: str, layout: Layout) -> Point:
    x_max, y_max = layout.columns - 1, layout.rows - 1
    x, y = point
    tolerance = 1e-6
    if not (-tolerance <= x <= x_max + tolerance and -tolerance <= y <= y_max + tolerance):
        raise StrokeError(
            "outside_grid",
            f"{name} point ({x:g}, {y:g}) is outside the {layout.rows} x {layout.columns} grid: "
            f"x (column) must be in [0, {x_max}] and y (row) in [0, {y_max}]",
        )
    return (min(max(float(x), 0.0), float(x_max)), min(max(float(y), 0.0), float(y_max)))


def virtual_actuators(
    start: Point, end: Point, *, merge_distance: float = MERGE_DISTANCE
) -> tuple[list[Point], list[float]]:
    """The stroke's virtual actuators, in order, and their fractions of the way (0 .. 1).

    The endpoints and every crossing with a grid line; points closer than
    ``merge_distance`` become one (an endpoint wins; otherwise their midpoint,
    which still lies on the stroke). A stroke of zero length has one point.
    """
    length = math.dist(start, end)
    if length <= ON_LINE_EPSILON:
        return [start], [0.0]
    crossings = sorted({*_line_crossings(start[0], end[0]), *_line_crossings(start[1], end[1])})
    fractions = _merged([0.0, *crossings, 1.0], merge_distance / length)
    points = [_lerp(start, end, f) for f in fractions]
    return points, fractions


def _line_crossings(a: float, b: float) -> list[float]:
    """Fractions in (0, 1) where the coordinate goes from a to b through an integer."""
    if abs(b - a) <= ON_LINE_EPSILON:
        return []
    low, high = min(a, b), max(a, b)
    first, last = math.ceil(low - ON_LINE_EPSILON), math.floor(high + ON_LINE_EPSILON)
    fractions = ((k - a) / (b - a) for k in range(first, last + 1))
    return [f for f in fractions if 0.0 < f < 1.0]


def _merged(fractions: list[float], merge_fraction: float) -> list[float]:
    """Group sorted fractions closer than ``merge_fraction``; keep 0 and 1 exactly."""
    groups: list[list[float]] = []
    for f in fractions:
        if groups and f - groups[-1][0] < merge_fraction:
            groups[-1].append(f)
        else:
            groups.append([f])
    if len(groups) == 1:
        return [0.0, 1.0]  # shorter than the merge distance: just its two endpoints
    return [_representative(group) for group in groups]


def _representative(group: list[float]) -> float:
    if group[0] == 0.0:
        return 0.0
    if group[-1] == 1.0:
        return 1.0
    return (group[0] + group[-1]) / 2


def _lerp(start: Point, end: Point, fraction: float) -> Point:
    if fraction == 0.0:
        return start
    if fraction == 1.0:
        return end
    x = start[0] + (end[0] - start[0]) * fraction
    y = start[1] + (end[1] - start[1]) * fraction
    return (_snap(x), _snap(y))


def _snap(value: float) -> float:
    nearest = round(value)
    return float(nearest) if abs(value - nearest) <= ON_LINE_EPSILON else value


def _timings(fractions: Sequence[float]) -> list[tuple[_Affine, _Affine]]:
    """(onset, duration) of each burst, as affine functions of the stroke duration T.

    The Tactile Brush recursion (``tactile-brush.md``, "Durations and onsets"):
    ``SOA_i = (0.32 (d_i- + tau_{i+1} - S) + 47.3) / 1.32``, ``S += SOA_i``,
    ``d_{i+1}- = d_i+ = tau_{i+1} - S``, and finally ``d_n- = T - S``.
    """
    taus = [_Affine(f, 0.0) for f in fractions]
    if len(taus) == 1:
        return [(_Affine(0.0, 0.0), _Affine(1.0, 0.0))]
    onset = _Affine(0.0, 0.0)
    before_peak = _Affine(0.0, 0.0)  # d_i minus
    result: list[tuple[_Affine, _Affine]] = []
    for tau_next in taus[1:]:
        soa = (before_peak + tau_next - onset).scaled(SOA_SLOPE) + _Affine(0.0, SOA_INTERCEPT_MS)
        soa = soa.scaled(1.0 / (1.0 + SOA_SLOPE))
        next_onset = onset + soa
        after_peak = tau_next - next_onset  # d_i plus, which is d_{i+1} minus
        result.append((onset, before_peak + after_peak))
        onset, before_peak = next_onset, after_peak
    result.append((onset, _Affine(1.0, 0.0) - onset))
    return result


def _fastest_feasible_ms(
    timings: Iterable[tuple[_Affine, _Affine]], min_command_ms: float
) -> float:
    """The least T for which every burst lasts at least ``min_command_ms``.

    Every duration grows with T (its slope is positive: each onset is a
    weighted mean of earlier peaks, so it trails its own peak), hence the
    feasible durations are one interval [T_min, inf).
    """
    needed = 0.0
    for _, duration in timings:
        if duration.a > 0:
            needed = max(needed, (min_command_ms - duration.b) / duration.a)
    # Rounded up to the microsecond: every burst reaches the minimum despite
    # float rounding, and the adjusted duration reads well.
    return math.ceil(needed * 1000.0 * (1 + 1e-12)) / 1000.0


def _pin_last_end(bursts: tuple[Burst, ...], duration_ms: float) -> tuple[Burst, ...]:
    """Make the last burst end exactly at the stroke's duration (no float residue)."""
    last = bursts[-1]
    return (*bursts[:-1], replace(last, duration_ms=duration_ms - last.start_ms))


def render_point(burst: Burst, layout: Layout) -> list[Command]:
    """Funneling: the physical commands that make one virtual actuator felt.

    A point on an actuator drives it alone; on a grid line, the two actuators
    around it (``A1 = sqrt(1 - beta) A``, ``A2 = sqrt(beta) A``); strictly inside
    a cell, the four corners with ``A sqrt(wx wy)`` (Tang et al.: funneling
    applied twice, which factorises). The squares always sum to ``A**2``.
    """
    column_weights = _axis_weights(burst.x, layout.columns)
    row_weights = _axis_weights(burst.y, layout.rows)
    return [
        Command(
            row, column, burst.start_ms, burst.duration_ms, burst.intensity * math.sqrt(wx * wy)
        )
        for row, wy in row_weights
        for column, wx in column_weights
    ]


def _axis_weights(coordinate: float, count: int) -> list[tuple[int, float]]:
    """(index, weight) of the one or two actuators around a coordinate; weights sum to 1."""
    low = min(math.floor(coordinate), count - 1)
    fraction = coordinate - low
    if fraction <= ON_LINE_EPSILON:
        return [(low, 1.0)]
    if fraction >= 1 - ON_LINE_EPSILON:
        return [(low + 1, 1.0)]
    return [(low, 1.0 - fraction), (low + 1, fraction)]


def merge_commands(
    commands: Iterable[Command], *, min_command_ms: float = MIN_COMMAND_MS
) -> tuple[Command, ...]:
    """One actuator, one intensity at a time.

    Overlapping commands on an actuator add their energies (intensity squared),
    capped at 1. A piece shorter than ``min_command_ms`` left by the overlap
    joins its neighbour with the energy-weighted intensity, so no command is
    shorter than the minimum unless the whole on-period is.
    """
    by_actuator: dict[tuple[int, int], list[Command]] = {}
    for command in commands:
        if command.intensity > 0 and command.duration_ms > 0:
            by_actuator.setdefault((command.row, command.column), []).append(command)
    merged: list[Command] = []
    for (row, column), group in by_actuator.items():
        for piece in _join_short(_energy_pieces(group), min_command_ms):
            start, end, intensity = piece
            merged.append(Command(row, column, start, end - start, intensity))
    merged.sort(key=lambda c: (c.start_ms, c.row, c.column))
    return tuple(merged)


_Piece = tuple[float, float, float]  # start_ms, end_ms, intensity


def _energy_pieces(group: list[Command]) -> list[_Piece]:
    """Piecewise-constant intensity of one actuator: energies summed, capped at 1."""
    bounds = sorted({t for c in group for t in (c.start_ms, c.end_ms)})
    pieces: list[_Piece] = []
    for start, end in itertools.pairwise(bounds):
        energy = sum(c.intensity**2 for c in group if c.start_ms < end and c.end_ms > start)
        if energy <= 0:
            continue
        intensity = min(1.0, math.sqrt(energy))
        if pieces and pieces[-1][1] == start and math.isclose(pieces[-1][2], intensity):
            pieces[-1] = (pieces[-1][0], end, pieces[-1][2])
        else:
            pieces.append((start, end, intensity))
    return pieces


def _join_short(pieces: list[_Piece], min_command_ms: float) -> list[_Piece]:
    """Join pieces shorter than the minimum to an adjacent piece of the same on-period."""
    pieces = list(pieces)
    while True:
        short = [
            i
            for i, (s, e, _) in enumerate(pieces)
            if e - s < min_command_ms and _neighbour(pieces, i) is not None
        ]
        if not short:
            return pieces
        i = min(short, key=lambda k: pieces[k][1] - pieces[k][0])
        j = _neighbour(pieces, i)
        assert j is not None
        a, b = sorted((i, j))
        pieces[a : b + 1] = [_joined(pieces[a], pieces[b])]


def _neighbour(pieces: list[_Piece], i: int) -> int | None:
    """The adjacent piece touching piece i (previous preferred), or None if it stands alone."""
    if i > 0 and pieces[i - 1][1] == pieces[i][0]:
        return i - 1
    if i + 1 < len(pieces) and pieces[i + 1][0] == pieces[i][1]:
        return i + 1
    return None


def _joined(first: _Piece, second: _Piece) -> _Piece:
    """Two touching pieces as one, keeping the energy (intensity squared x time)."""
    d1, d2 = first[1] - first[0], second[1] - second[0]
    energy = first[2] ** 2 * d1 + second[2] ** 2 * d2
    return (first[0], second[1], min(1.0, math.sqrt(energy / (d1 + d2))))
