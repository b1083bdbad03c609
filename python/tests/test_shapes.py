"""The shape library: properties over every shape, resolution and grid, plus worked examples."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from feelmysign.errors import ParameterError
from feelmysign.layout import PAPER_SLEEVE, Layout, grid_layout
from feelmysign.protocol import Accepted, format_json, format_legacy, parse
from feelmysign.shapes import DRAWING_SPEED_CM_S, SHAPE_NAMES, SHAPES, ShapeSpec, shape_strokes
from feelmysign.stroke import Stroke

CLOSED = ("circle", "square", "triangle", "star", "heart")
COORDINATE_TOLERANCE = 1e-6  # vertices are rounded to 6 decimals
DURATION_TOLERANCE_MS = 1e-3  # per stroke: durations are rounded to 3 decimals


@st.composite
def cases(draw: st.DrawFn) -> tuple[str, int, Layout, float]:
    """A shape, a valid number of segments, a grid with room for it, and a margin."""
    name = draw(st.sampled_from(SHAPE_NAMES))
    spec = SHAPES[name]
    segments = draw(st.sampled_from(range(spec.min_segments, spec.max_segments + 1, spec.step)))
    rows = draw(st.integers(1 if name == "line" else 2, 12))
    columns = draw(st.integers(2, 12))
    spacing_cm = draw(st.floats(0.5, 5.0))
    layout = grid_layout(
        rows,
        columns,
        spacing_cm,
        max_stroke_duration_ms=60_000,
        max_on_time_ms=60_000,
        max_duty_cycle=1.0,
    )
    smaller_span = min(columns - 1, rows - 1) if name != "line" else columns - 1
    margin = draw(st.floats(0.0, smaller_span / 2 * 0.9))
    return name, segments, layout, margin


def _vertices(strokes: list[Stroke]) -> list[tuple[float, float]]:
    return [strokes[0].start, *(s.end for s in strokes)]


@settings(max_examples=300, deadline=None)
@given(cases(), st.one_of(st.none(), st.floats(100.0, 60_000.0)))
def test_every_shape_is_one_joined_line_inside_the_grid(
    case: tuple[str, int, Layout, float], duration_ms: float | None
) -> None:
    name, segments, layout, margin = case
    strokes = shape_strokes(
        name, layout=layout, segments=segments, duration_ms=duration_ms, margin=margin
    )
    assert len(strokes) == segments
    assert [s.seq for s in strokes] == list(range(segments))
    assert len({s.drawing for s in strokes}) == 1 and strokes[0].drawing
    for before, after in itertools.pairwise(strokes):
        assert before.end == after.start  # joined exactly, not just nearly
    if name in CLOSED:
        assert strokes[-1].end == strokes[0].start
    for x, y in _vertices(strokes):
        assert (
            margin - COORDINATE_TOLERANCE <= x <= layout.columns - 1 - margin + COORDINATE_TOLERANCE
        )
        assert 0.0 <= x <= layout.columns - 1 and 0.0 <= y <= layout.rows - 1
        if name != "line":
            assert (
                margin - COORDINATE_TOLERANCE
                <= y
                <= layout.rows - 1 - margin + COORDINATE_TOLERANCE
            )


@settings(max_examples=300, deadline=None)
@given(cases(), st.floats(100.0, 60_000.0))
def test_duration_is_the_total_shared_at_constant_speed(
    case: tuple[str, int, Layout, float], duration_ms: float
) -> None:
    name, segments, layout, margin = case
    strokes = shape_strokes(
        name, layout=layout, segments=segments, duration_ms=duration_ms, margin=margin
    )
    total_ms = sum(s.duration_ms for s in strokes)
    assert total_ms == pytest.approx(duration_ms, abs=DURATION_TOLERANCE_MS * segments)
    length = sum(s.length for s in strokes)
    for stroke in strokes:
        assert stroke.duration_ms > 0
        expected_ms = duration_ms * stroke.length / length
        # Lengths are of rounded vertices: allow for that rounding too.
        assert stroke.duration_ms == pytest.approx(expected_ms, rel=1e-4, abs=1e-2)


@settings(max_examples=200, deadline=None)
@given(cases())
def test_the_sleeve_accepts_every_stroke_in_both_formats(
    case: tuple[str, int, Layout, float],
) -> None:
    name, segments, layout, margin = case
    strokes = shape_strokes(name, layout=layout, segments=segments, margin=margin)
    for stroke in strokes:
        for text in (format_json(stroke), format_legacy(stroke)):
            assert isinstance(parse(text, layout), Accepted), text


@settings(max_examples=100, deadline=None)
@given(st.integers(3, 64), st.integers(2, 12), st.integers(2, 12))
def test_a_circle_stays_a_circle_centred_on_any_grid(
    segments: int, rows: int, columns: int
) -> None:
    layout = grid_layout(rows, columns, 3.0)
    strokes = shape_strokes("circle", layout=layout, segments=segments, duration_ms=1000)
    centre = ((columns - 1) / 2, (rows - 1) / 2)
    radius = min(columns - 1, rows - 1) / 2  # equal scale on x and y: the smaller side decides
    for vertex in _vertices(strokes):
        assert math.dist(vertex, centre) == pytest.approx(radius, abs=2 * COORDINATE_TOLERANCE)


def test_paper_sleeve_circle_starts_at_the_top_and_goes_left() -> None:
    strokes = shape_strokes("circle", layout=PAPER_SLEEVE, drawing="d")
    assert len(strokes) == SHAPES["circle"].default_segments == 16
    assert strokes[0].start == (1.5, 0.0)
    assert strokes[0].end[0] < 1.5  # counter-clockwise on the screen: leftwards first
    assert strokes[8].start == (1.5, 2.0)  # half way round: the bottom


def test_paper_sleeve_square_fills_the_height_centred() -> None:
    strokes = shape_strokes("square", layout=PAPER_SLEEVE, duration_ms=4000, drawing="d")
    assert _vertices(strokes) == [(0.5, 0.0), (0.5, 2.0), (2.5, 2.0), (2.5, 0.0), (0.5, 0.0)]
    assert [s.duration_ms for s in strokes] == [1000.0] * 4


def test_polygon_segments_split_every_side_equally() -> None:
    strokes = shape_strokes("square", layout=PAPER_SLEEVE, segments=8, duration_ms=800)
    assert _vertices(strokes)[:3] == [(0.5, 0.0), (0.5, 1.0), (0.5, 2.0)]
    assert {s.duration_ms for s in strokes} == {100.0}


def test_star_is_five_strokes_from_the_top_point() -> None:
    strokes = shape_strokes("star", layout=PAPER_SLEEVE)
    assert len(strokes) == 5
    assert strokes[0].start == (1.5, 0.0)
    # A pentagram: every stroke as long as the others, and it crosses itself.
    assert len({round(s.length, 5) for s in strokes}) == 1


def test_heart_starts_at_its_dip_and_has_its_tip_with_an_even_count() -> None:
    strokes = shape_strokes("heart", layout=PAPER_SLEEVE, segments=4, drawing="d")
    dip, left, tip, right = (s.start for s in strokes)
    assert dip[0] == tip[0] == 1.5
    assert tip[1] == 2.0  # the tip touches the bottom row
    assert left[0] < 1.5 < right[0] and left[1] == right[1]  # symmetric, left lobe first


def test_line_goes_left_to_right_through_the_middle_even_on_one_row() -> None:
    (stroke,) = shape_strokes("line", layout=PAPER_SLEEVE)
    assert (stroke.start, stroke.end) == ((0.0, 1.0), (3.0, 1.0))
    one_row = grid_layout(1, 4, 3.0)
    strokes = shape_strokes("line", layout=one_row, segments=3, duration_ms=900)
    assert _vertices(strokes) == [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0)]


def test_default_duration_draws_at_the_default_speed() -> None:
    strokes = shape_strokes("line", layout=PAPER_SLEEVE)  # 3 grid units = 9 cm
    assert strokes[0].duration_ms == pytest.approx(9.0 / DRAWING_SPEED_CM_S * 1000)


def test_intensity_and_drawing_are_carried_by_every_stroke() -> None:
    strokes = shape_strokes("triangle", layout=PAPER_SLEEVE, intensity=0.4, drawing="abc")
    assert {(s.intensity, s.drawing) for s in strokes} == {(0.4, "abc")}
    fresh = shape_strokes("triangle", layout=PAPER_SLEEVE)
    assert fresh[0].drawing != shape_strokes("triangle", layout=PAPER_SLEEVE)[0].drawing


@pytest.mark.parametrize(
    ("name", "segments", "allowed"),
    [
        ("circle", 2, "a whole number from 3 to 64"),
        ("circle", 65, "a whole number from 3 to 64"),
        ("heart", 0, "a whole number from 3 to 64"),
        ("square", 6, "a multiple of 4 from 4 to 64"),
        ("triangle", 66, "a multiple of 3 from 3 to 63"),
        ("star", 12, "a multiple of 5 from 5 to 60"),
        ("line", 0, "a whole number from 1 to 64"),
    ],
)
def test_segments_outside_the_range_name_the_range(name: str, segments: int, allowed: str) -> None:
    with pytest.raises(ParameterError, match=allowed) as caught:
        shape_strokes(name, layout=PAPER_SLEEVE, segments=segments)
    assert caught.value.value == segments
    assert f"segments of a {name}" in str(caught.value)


def test_every_shape_has_a_default_inside_its_range() -> None:
    for spec in SHAPES.values():
        assert isinstance(spec, ShapeSpec) and spec.accepts(spec.default_segments)
    assert SHAPES["circle"].accepts(3) and SHAPES["heart"].accepts(3)  # the study's lowest


def test_unknown_shape_lists_the_shapes() -> None:
    with pytest.raises(ParameterError, match="one of circle, square, triangle, star, heart, line"):
        shape_strokes("hexagon", layout=PAPER_SLEEVE)


def test_a_duration_too_long_for_the_sleeve_says_how_long_it_may_be() -> None:
    with pytest.raises(ParameterError, match=r"at most 10000 ms.*max_stroke_duration_ms 10000"):
        shape_strokes("line", layout=PAPER_SLEEVE, duration_ms=20_000)
    # More segments share the same duration: then it fits.
    assert len(shape_strokes("line", layout=PAPER_SLEEVE, segments=2, duration_ms=20_000)) == 2


@pytest.mark.parametrize("duration_ms", [0.0, -5.0, math.nan, math.inf])
def test_a_duration_must_be_positive_and_finite(duration_ms: float) -> None:
    with pytest.raises(ParameterError, match="above 0"):
        shape_strokes("circle", layout=PAPER_SLEEVE, duration_ms=duration_ms)


def test_a_margin_that_leaves_no_room_says_the_largest() -> None:
    with pytest.raises(ParameterError, match=r"less than 1 \(grid units\) on this 3 x 4 grid"):
        shape_strokes("circle", layout=PAPER_SLEEVE, margin=1.0)
    with pytest.raises(ParameterError, match="0 or more grid units"):
        shape_strokes("circle", layout=PAPER_SLEEVE, margin=-0.1)


def test_a_shape_with_height_needs_two_rows() -> None:
    with pytest.raises(ParameterError, match=r"at least 2 rows.*only 'line'"):
        shape_strokes("circle", layout=grid_layout(1, 6, 3.0))


@pytest.mark.parametrize("intensity", [-0.1, 1.5, math.nan])
def test_intensity_must_be_in_zero_one(intensity: float) -> None:
    with pytest.raises(ParameterError, match=r"in \[0, 1\]"):
        shape_strokes("circle", layout=PAPER_SLEEVE, intensity=intensity)
