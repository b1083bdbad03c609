"""A library of shapes drawn as strokes: circle, square, triangle, star, heart, line.

For the sender (``feelmysign send --shape circle``) and for the study the
paper designed but could not run ("Can You Feel My Sign?", section 6:
SQ2.3 "at what resolution can the user no longer accurately determine the
figure they feel?", SQ2.4 "what is the difference between various shapes in
the needed resolution?"). The resolution is the number of strokes,
``segments``: a circle of 3 segments is a triangle, of 64 a smooth circle.

Every shape is drawn the way a hand draws it on a screen (x right, y down,
which the sleeve maps onto the arm): one continuous line, each stroke starting
where the previous one ended, closed shapes ending where they started. Closed
shapes start at their top and go counter-clockwise as seen on the screen
(leftwards first: how most people draw a circle and a heart); the star is the
five-stroke star drawn without lifting the pen; the line goes left to right
through the middle of the grid.

Sizing: the shape fills the grid, less ``margin`` on every side, with equal
scale on x and y so that a circle stays a circle on the skin (grid units are
the same distance, ``spacing_cm``, along rows and columns), centred. A curved
shape is scaled by its ideal outline, so its polygons at every resolution are
inscribed in the same curve (a 3-segment circle is smaller than its circle,
as it should be when comparing resolutions).

Timing: ``duration_ms`` is the whole shape's; each stroke gets the share of
its length (a constant speed, like a steady hand). By default the shape is
drawn at ``DRAWING_SPEED_CM_S``. Everything here is pure, except that a
missing ``drawing`` id is made up with ``uuid4`` (pass one to be repeatable).
"""

from __future__ import annotations

import itertools
import math
import uuid
from collections.abc import Callable
from dataclasses import dataclass

from feelmysign.errors import ParameterError
from feelmysign.layout import Layout
from feelmysign.stroke import Point, Stroke

# Pleasant stroking on the forearm is about 1 to 10 cm/s (C-tactile afferents; see
# shared reference tactile-brush.md); 5 cm/s sits in the middle and draws the paper's
# 3 x 4 sleeve circle (18.8 cm) in under 4 s.
DRAWING_SPEED_CM_S = 5.0
MAX_SEGMENTS = 64  # finer than any sleeve can render; also bounds the message count
# Vertices are rounded to 1e-6 grid units (0.03 micrometres on a 3 cm grid) and durations
# to 1e-3 ms: far below what skin or the player resolves, and the messages stay readable.
COORDINATE_DECIMALS = 6
DURATION_DECIMALS = 3
# Samples of a curve's ideal outline: its bounding box and arc length, to 1e-6 of its size.
_OUTLINE_SAMPLES = 4096


@dataclass(frozen=True)
class ShapeSpec:
    """How many strokes a shape may have: ``min_segments`` to ``max_segments`` in steps of
    ``step`` (a polygon's sides are split into equal strokes, so its count is a multiple of
    its corners), ``default_segments`` when none is asked for."""

    name: str
    description: str
    default_segments: int
    min_segments: int
    max_segments: int
    step: int = 1

    def allowed(self) -> str:
        if self.step == 1:
            return f"a whole number from {self.min_segments} to {self.max_segments}"
        return (
            f"a multiple of {self.step} from {self.min_segments} to {self.max_segments} "
            f"(each of its {self.step} sides split into equal strokes)"
        )

    def accepts(self, segments: int) -> bool:
        return (
            self.min_segments <= segments <= self.max_segments
            and (segments - self.min_segments) % self.step == 0
        )


def _multiple_below(step: int, limit: int) -> int:
    return limit - limit % step


SHAPES: dict[str, ShapeSpec] = {
    spec.name: spec
    for spec in (
        ShapeSpec("circle", "a circle, from the top, counter-clockwise", 16, 3, MAX_SEGMENTS),
        ShapeSpec(
            "square",
            "a square, from the top-left corner, down first",
            4,
            4,
            _multiple_below(4, MAX_SEGMENTS),
            step=4,
        ),
        ShapeSpec(
            "triangle",
            "an upright equilateral triangle, from its apex",
            3,
            3,
            _multiple_below(3, MAX_SEGMENTS),
            step=3,
        ),
        ShapeSpec(
            "star",
            "a five-pointed star in one line, from the top point",
            5,
            5,
            _multiple_below(5, MAX_SEGMENTS),
            step=5,
        ),
        ShapeSpec(
            "heart", "a heart, from the dip at the top, left lobe first", 16, 3, MAX_SEGMENTS
        ),
        ShapeSpec(
            "line", "a horizontal line through the middle, left to right", 1, 1, MAX_SEGMENTS
        ),
    )
}
SHAPE_NAMES = tuple(SHAPES)


def shape_strokes(
    name: str,
    *,
    layout: Layout,
    segments: int | None = None,
    duration_ms: float | None = None,
    intensity: float | None = None,
    margin: float = 0.0,
    drawing: str | None = None,
) -> list[Stroke]:
    """The strokes of shape ``name`` on ``layout``'s grid, ``seq`` 0..n-1 of one drawing.

    ``segments``: number of strokes (default and range per shape in ``SHAPES``).
    ``duration_ms``: the whole shape's duration (default: drawn at
    ``DRAWING_SPEED_CM_S``). ``intensity``: 0..1, None for the sleeve's default.
    ``margin``: grid units kept free on every side. ``drawing``: the drawing id
    (default: a fresh UUID). Raises ParameterError naming the value and its range.
    """
    spec = shape_spec(name)
    count = _check_segments(spec, segments)
    if intensity is not None and not (math.isfinite(intensity) and 0.0 <= intensity <= 1.0):
        raise ParameterError("intensity", intensity, "a number in [0, 1], or None for the default")
    vertices = fit_to_grid(_OUTLINES[spec.name](count), _IDEAL_BOXES[spec.name], layout, margin)
    lengths = [math.dist(a, b) for a, b in itertools.pairwise(vertices)]
    total_ms = _total_duration_ms(duration_ms, sum(lengths), layout)
    durations = [round(total_ms * length / sum(lengths), DURATION_DECIMALS) for length in lengths]
    _check_longest(spec, durations, total_ms, layout)
    drawing_id = drawing if drawing is not None else str(uuid.uuid4())
    return [
        Stroke(
            start=vertices[i],
            end=vertices[i + 1],
            duration_ms=durations[i],
            intensity=intensity,
            drawing=drawing_id,
            seq=i,
        )
        for i in range(count)
    ]


def shape_spec(name: str) -> ShapeSpec:
    """The ShapeSpec of ``name``; ParameterError listing the shapes for an unknown one."""
    spec = SHAPES.get(name)
    if spec is None:
        raise ParameterError("shape", name, f"one of {', '.join(SHAPE_NAMES)}")
    return spec


def _check_segments(spec: ShapeSpec, segments: int | None) -> int:
    if segments is None:
        return spec.default_segments
    if isinstance(segments, bool) or not isinstance(segments, int) or not spec.accepts(segments):
        raise ParameterError(f"segments of a {spec.name}", segments, spec.allowed())
    return segments


def _total_duration_ms(duration_ms: float | None, length: float, layout: Layout) -> float:
    if duration_ms is None:
        return length * layout.spacing_cm / DRAWING_SPEED_CM_S * 1000.0
    if not (math.isfinite(duration_ms) and duration_ms > 0):
        raise ParameterError("duration_ms", duration_ms, "a number of milliseconds above 0")
    return float(duration_ms)


def _check_longest(
    spec: ShapeSpec, durations: list[float], total_ms: float, layout: Layout
) -> None:
    """Every stroke must pass the sleeve's max_stroke_duration_ms, or the sleeve drops it."""
    longest_ms = max(durations)
    cap_ms = layout.max_stroke_duration_ms
    if longest_ms <= cap_ms:
        return
    most_ms = total_ms / longest_ms * cap_ms  # this order cannot overflow to infinity
    raise ParameterError(
        f"duration_ms of this {spec.name}",
        round(total_ms, 3),
        f"at most {math.floor(most_ms)} ms: its longest stroke would last {longest_ms:.0f} ms, "
        f"above the layout's max_stroke_duration_ms {cap_ms:g}; shorten it or use more segments",
    )


# --- outlines: vertices in a unit frame, x right, y down -----------------------------------

Box = tuple[float, float, float, float]  # x_min, y_min, x_max, y_max


def _around(count: int, start_deg: float, step_deg: float) -> list[Point]:
    """``count`` points on the unit circle, then the first again (closed).

    Angles are clockwise from the top as on a clock; a negative step goes counter-clockwise.
    """
    points = []
    for k in range(count):
        angle = math.radians(start_deg + k * step_deg)
        points.append((math.sin(angle), -math.cos(angle)))
    return [*points, points[0]]


def _subdivide(corners: list[Point], per_side: int) -> list[Point]:
    """Split each side of the closed polyline ``corners`` into ``per_side`` equal strokes."""
    points: list[Point] = []
    for (x0, y0), (x1, y1) in itertools.pairwise(corners):
        for k in range(per_side):
            t = k / per_side
            points.append((x0 + (x1 - x0) * t, y0 + (y1 - y0) * t))
    return [*points, corners[-1]]


def _circle(count: int) -> list[Point]:
    return _around(count, 0.0, -360.0 / count)


def _square(count: int) -> list[Point]:
    corners: list[Point] = [(-1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
    return _subdivide(corners, count // 4)


def _triangle(count: int) -> list[Point]:
    return _subdivide(_around(3, 0.0, -120.0), count // 3)


def _star(count: int) -> list[Point]:
    # Every second corner of a pentagon: the pentagram drawn without lifting the pen.
    return _subdivide(_around(5, 0.0, -144.0), count // 5)


def _line(count: int) -> list[Point]:
    return [(-1.0 + 2.0 * k / count, 0.0) for k in range(count + 1)]


def _heart_curve(t: float) -> Point:
    """The classic heart curve (x = 16 sin^3 t, ...), mirrored so t > 0 draws the left lobe."""
    x = -16.0 * math.sin(t) ** 3
    y_up = 13.0 * math.cos(t) - 5.0 * math.cos(2 * t) - 2.0 * math.cos(3 * t) - math.cos(4 * t)
    return (x, -y_up)


def _heart_outline() -> list[Point]:
    return [_heart_curve(2.0 * math.pi * j / _OUTLINE_SAMPLES) for j in range(_OUTLINE_SAMPLES + 1)]


def _heart(count: int) -> list[Point]:
    """``count`` strokes of equal length along the heart, from the dip at the top.

    Equal arc length, not equal t: the curve's parameter crawls near the dip and
    the tip, so equal t would waste strokes there. With an even count the tip
    is a vertex (it lies at half the length, by symmetry).
    """
    outline = _heart_outline()
    cumulative = [0.0]
    for a, b in itertools.pairwise(outline):
        cumulative.append(cumulative[-1] + math.dist(a, b))
    total = cumulative[-1]
    points: list[Point] = []
    j = 0
    for k in range(count):
        target = total * k / count
        while cumulative[j + 1] < target:
            j += 1
        span = cumulative[j + 1] - cumulative[j]
        t = (target - cumulative[j]) / span if span > 0 else 0.0
        (x0, y0), (x1, y1) = outline[j], outline[j + 1]
        points.append((x0 + (x1 - x0) * t, y0 + (y1 - y0) * t))
    return [*points, points[0]]


def _bounding_box(points: list[Point]) -> Box:
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    return (min(xs), min(ys), max(xs), max(ys))


_OUTLINES: dict[str, Callable[[int], list[Point]]] = {
    "circle": _circle,
    "square": _square,
    "triangle": _triangle,
    "star": _star,
    "heart": _heart,
    "line": _line,
}
# The box of each shape's ideal outline: a curve's polygons are scaled as the curve is.
_IDEAL_BOXES: dict[str, Box] = {
    "circle": (-1.0, -1.0, 1.0, 1.0),
    "square": (-1.0, -1.0, 1.0, 1.0),
    "triangle": _bounding_box(_triangle(3)),
    "star": _bounding_box(_star(5)),
    "heart": _bounding_box(_heart_outline()),
    "line": (-1.0, 0.0, 1.0, 0.0),
}


# --- fitting to the grid ------------------------------------------------------------------


def fit_to_grid(points: list[Point], box: Box, layout: Layout, margin: float = 0.0) -> list[Point]:
    """``points`` scaled equally on x and y so that ``box`` fills the grid less ``margin``
    (grid units) on every side, centred; a flat box (a line) only needs the width."""
    x_min, y_min, x_max, y_max = box
    width, height = x_max - x_min, y_max - y_min
    room_x, room_y = _room(layout, margin, needs_height=height > 0)
    scale = min(room_x / width, room_y / height) if height > 0 else room_x / width
    centre_x, centre_y = (layout.columns - 1) / 2, (layout.rows - 1) / 2
    mid_x, mid_y = (x_min + x_max) / 2, (y_min + y_max) / 2
    # Clamped: float rounding must not put a vertex 1e-16 outside the grid.
    return [
        (
            round(
                min(max(centre_x + (x - mid_x) * scale, 0.0), layout.columns - 1.0),
                COORDINATE_DECIMALS,
            ),
            round(
                min(max(centre_y + (y - mid_y) * scale, 0.0), layout.rows - 1.0),
                COORDINATE_DECIMALS,
            ),
        )
        for x, y in points
    ]


def _room(layout: Layout, margin: float, *, needs_height: bool) -> tuple[float, float]:
    """The width and height left to draw in, in grid units; ParameterError when none is left."""
    if not (math.isfinite(margin) and margin >= 0):
        raise ParameterError("margin", margin, "0 or more grid units")
    spans = {"columns": layout.columns - 1.0, "rows": layout.rows - 1.0}
    for what, span in spans.items():
        if what == "rows" and not needs_height:
            continue
        if span <= 0:
            raise ParameterError(
                "layout",
                f"{layout.rows} x {layout.columns}",
                f"a grid of at least 2 {what} for this shape (only 'line' needs no height)",
            )
        if span - 2 * margin <= 0:
            raise ParameterError(
                "margin",
                margin,
                f"less than {span / 2:g} (grid units) on this {layout.rows} x {layout.columns} "
                "grid, or nothing is left to draw in",
            )
    return spans["columns"] - 2 * margin, spans["rows"] - 2 * margin
