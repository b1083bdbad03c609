"""The paper's angle simplifier: shared vectors, then invariants over random paths."""

from __future__ import annotations

import itertools
import math
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from simplifier_checks import (
    assert_four_strokes_on_the_corners,
    assert_joined_from_press_to_release,
    check_vector,
    random_walk,
    run,
    square_path,
)
from vectors import load

from feelmysign.errors import ParameterError
from feelmysign.simplify import (
    AngleParams,
    CanvasMapping,
    Sample,
    frames_from_samples,
)

VECTORS = [(n, c) for n, c in load("angle") if n != "params"]
PARAMS_TABLE = dict(load("angle"))["params"]


@pytest.mark.parametrize(("name", "case"), VECTORS, ids=[n for n, _ in VECTORS])
def test_vector(name: str, case: dict[str, Any]) -> None:
    params = AngleParams(**case["params"])
    paths = [[Sample(*s) for s in path] for path in case["paths"]]
    assert [len(frames_from_samples(p, params.fps)) for p in paths] == case["expected"]["inputs"]
    check_vector(name, case, params, paths)


def test_parameter_table_matches_the_defaults() -> None:
    defaults = AngleParams()
    for entry in PARAMS_TABLE["parameters"]:
        assert getattr(defaults, entry["name"]) == entry["default"]


def test_paper_defaults() -> None:
    p = AngleParams()
    assert (p.check_frames, p.max_angle_deg, p.frame_max, p.fps) == (5, 20.0, 0, 60.0)
    assert (p.recover, p.clear_on_press, p.min_duration_ms, p.min_length) == (True, True, 6.1, 0.1)
    assert (p.rows, p.columns) == (3, 4)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("check_frames", 1),
        ("check_frames", 2.5),
        ("max_angle_deg", 0),
        ("fps", math.nan),
        ("frame_max", -1),
        ("min_length", -0.1),
        ("recover", 1),
        ("rows", True),
    ],
)
def test_out_of_range_parameters_are_refused_with_the_range(field: str, value: object) -> None:
    with pytest.raises(ParameterError) as error:
        AngleParams(**{field: value})  # type: ignore[arg-type]
    assert error.value.name == field and "must be" in str(error.value)


def test_square_is_four_strokes_with_its_corners() -> None:
    params = AngleParams(canvas_width_px=900, canvas_height_px=600)
    # One sample per frame, 40 frames a side: every corner falls on a check.
    segments = [s for _, s in run(params, [square_path(1000 / 60)])]
    assert_four_strokes_on_the_corners(params, segments)


@pytest.mark.parametrize("gap_px", [0.0, 1.0])
def test_a_line_flicked_back_onto_its_start_is_two_strokes(gap_px: float) -> None:
    # Out 2 grid units in 600 ms, back in 40 ms to within gap_px of the start.
    params = AngleParams(canvas_width_px=1200, canvas_height_px=800)
    out = [Sample(k * 8.0, 300.0 + 800.0 * k / 75, 400.0) for k in range(76)]
    back = [Sample(600.0 + 8.0 * k, 1100.0 - (800.0 - gap_px) * k / 5, 400.0) for k in range(1, 6)]
    segments = [s for _, s in run(params, [out + back])]
    assert [s.dropped for s in segments] == [None, None]
    assert segments[0].length > 1.5 and segments[1].length > 1.5


def test_mapping_keeps_a_circle_round() -> None:
    mapping = CanvasMapping(1000, 1000, columns=4, rows=3)
    left, right = mapping.to_grid(0, 500), mapping.to_grid(1000, 500)
    top, bottom = mapping.to_grid(500, 0), mapping.to_grid(500, 1000)
    assert right[0] - left[0] == pytest.approx(bottom[1] - top[1]) == pytest.approx(2.0)
    stretched = CanvasMapping(1000, 1000, columns=4, rows=3, stretch=True)
    assert stretched.to_grid(1000, 1000) == (3.0, 2.0)


# --- properties over random paths ---------------------------------------------


@st.composite
def paths(draw: st.DrawFn) -> tuple[AngleParams, list[Sample]]:
    params = AngleParams(
        check_frames=draw(st.integers(2, 12)),
        max_angle_deg=draw(st.floats(5, 90)),
        frame_max=draw(st.sampled_from([0, 0, 3, 20, 90])),
        fps=draw(st.sampled_from([30.0, 60.0, 120.0])),
        min_length=draw(st.sampled_from([0.0, 0.1, 0.4])),
        min_duration_ms=draw(st.sampled_from([0.0, 6.1, 80.0])),
        canvas_width_px=800,
        canvas_height_px=600,
    )
    samples = random_walk(draw, margin_px=0)
    return params, samples


@settings(max_examples=150, deadline=None)
@given(paths())
def test_segments_join_and_keep_the_path_ends(case: tuple[AngleParams, list[Sample]]) -> None:
    params, samples = case
    assert_joined_from_press_to_release(params, samples)


@settings(max_examples=100, deadline=None)
@given(paths())
def test_without_recover_strokes_still_start_and_end_on_the_path(
    case: tuple[AngleParams, list[Sample]],
) -> None:
    params, samples = case
    params = AngleParams(**{**params.__dict__, "recover": False})
    segments = [s for _, s in run(params, [samples])]
    on_path = {params.mapping.to_grid(s.x, s.y) for s in samples}
    assert all(s.start in on_path and s.end in on_path for s in segments)
    assert all(a.end_ms <= b.start_ms for a, b in itertools.pairwise(segments))
