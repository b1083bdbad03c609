"""The window simplifier: shared vectors, the CLI, then invariants over random paths."""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from simplifier_checks import (
    assert_four_strokes_on_the_corners,
    assert_joined_from_press_to_release,
    check_vector,
    random_walk,
    run,
    simplify_flags,
    square_path,
    write_recording,
)
from vectors import load
from window_reference import ReferenceWindowSimplifier

from feelmysign.cli import main
from feelmysign.errors import ParameterError
from feelmysign.simplify import (
    Sample,
    Segment,
    WindowParams,
    WindowSimplifier,
)
from feelmysign.simplify.segment import NOT_ENOUGH_DISTANCE
from feelmysign.simplify.window import (
    LINE_SHARE,
    WINDOW_PARAMS,
    WindowCore,
    rest_radius,
    taken_samples,
)
from feelmysign.stroke import Point

WINDOW = dict(load("window"))
VECTORS = [(n, c) for n, c in WINDOW.items() if n != "params"]
PARAMS_TABLE = WINDOW["params"]
# The bound is tested on the reference's own float arithmetic; a different
# formula for the same distance may differ in the last bits.
FLOAT_TOLERANCE = 1e-12
# Nothing too short to send and no bend rule: each piece the window cuts is sent as it is, when
# it is cut, so the tests of the window's own cuts see them as cut.
UNMERGED: dict[str, Any] = {"min_length": 0.0, "min_duration_ms": 0.0, "floor_ms": 0.0}


def _distance(point: Point, start: Point, end: Point) -> float:
    """Distance from a point to the segment start -> end (not its line)."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    qx, qy = point[0] - start[0], point[1] - start[1]
    length_sq = dx * dx + dy * dy
    t = 0.0 if length_sq == 0 else min(max((qx * dx + qy * dy) / length_sq, 0.0), 1.0)
    return math.hypot(qx - t * dx, qy - t * dy)


@pytest.mark.parametrize(("name", "case"), VECTORS, ids=[n for n, _ in VECTORS])
def test_vector(name: str, case: dict[str, Any]) -> None:
    params = WindowParams(**case["params"])
    paths = [[Sample(*s) for s in path] for path in case["paths"]]
    assert [len(p) for p in paths] == case["expected"]["inputs"]
    check_vector(name, case, params, paths)
    assert _merged_back(params, paths) == case["expected"]["merged_back"], name


def _merged_back(params: WindowParams, paths: list[list[Sample]]) -> list[int]:
    """Per path, the pieces merged at release into the stroke sent before them."""
    simplifier = WindowSimplifier(params)
    counts = []
    for path in paths:
        before = simplifier.merged_back
        for sample in path:
            simplifier.push(sample)
        simplifier.end()
        counts.append(simplifier.merged_back - before)
    return counts


def test_parameter_table_matches_the_defaults() -> None:
    defaults = WindowParams()
    names = [entry["name"] for entry in PARAMS_TABLE["parameters"]]
    assert names == list(asdict(defaults))
    for entry in PARAMS_TABLE["parameters"]:
        assert getattr(defaults, entry["name"]) == entry["default"]


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("max_error", 0),
        ("max_error", math.inf),
        ("max_window", 0),
        ("max_window", 2.5),
        ("max_stroke_ms", math.nan),
        ("max_stroke_ms", -1),
        ("min_length", -0.1),
        ("stretch", 1),
    ],
)
def test_out_of_range_parameters_are_refused_with_the_range(field: str, value: object) -> None:
    with pytest.raises(ParameterError) as error:
        WindowParams(**{field: value})  # type: ignore[arg-type]
    assert error.value.name == field and "must be" in str(error.value)


def test_square_is_four_strokes_with_its_corners() -> None:
    # 10 px a sample is 0.033 grid units: above the error, so a corner shows at once.
    params = WindowParams(
        least_squares=False,
        canvas_width_px=900,
        canvas_height_px=600,
        max_error=0.01,
        max_window=1000,
        max_stroke_ms=0,
        **UNMERGED,
    )
    segments = [s for _, s in run(params, [square_path(8.0)])]
    assert_four_strokes_on_the_corners(params, segments)
    # Each corner is found one sample later, when the next sample leaves the line.
    assert [s.emitted_at_ms - s.end_ms for s in segments[:3]] == pytest.approx([8.0] * 3)


def test_a_straight_line_the_latency_cap_cuts_stays_one_straight_line() -> None:
    # A level line drawn in 1 s at 125 Hz, each sample 0.6 px (0.0025 grid units) above or below
    # it: the cap cuts it into strokes of at most 300 ms, and their ends are not the noisy
    # samples but points on the line of the first, so the felt line does not bend.
    params = WindowParams(least_squares=False, max_stroke_ms=300.0)
    path = [Sample(i * 8.0, 100 + 12.0 * i, 540 + (0.6 if i % 2 else -0.6)) for i in range(126)]
    segments = [s for _, s in run(params, [path]) if s.dropped is None]
    assert len(segments) >= 4
    (x0, y0), (x1, y1) = segments[0].start, segments[0].end
    for segment in segments[1:]:
        for x, y in (segment.start, segment.end):
            assert abs((x1 - x0) * (y - y0) - (y1 - y0) * (x - x0)) < 1e-9, segment
    # The bound holds on every sample: each lies within max_error of the chain of strokes.
    mapping = params.mapping
    for sample in path:
        point = mapping.to_grid(sample.x, sample.y)
        nearest = min(_distance(point, s.start, s.end) for s in segments)
        assert nearest <= params.max_error + FLOAT_TOLERANCE


def test_the_cut_goes_on_the_feature_not_where_the_bound_first_breaks() -> None:
    # A shallow tent: up 4 px over 20 samples, then down. The bound (0.05 grid units,
    # 5 px here) breaks well past the tip; the stroke still ends on the tip.
    params = WindowParams(
        least_squares=False,
        canvas_width_px=300,
        canvas_height_px=200,
        max_error=0.05,
        min_duration_ms=0,
        max_stroke_ms=0,
    )
    up = [Sample(8.0 * k, 5.0 * k, 100 - 0.6 * k) for k in range(21)]
    down = [Sample(8.0 * (20 + k), 100 + 5.0 * k, 88 + 0.6 * k) for k in range(1, 41)]
    segments = [s for _, s in run(params, [up + down])]
    tip = params.mapping.to_grid(up[-1].x, up[-1].y)
    assert segments[0].end == tip and segments[0].end_ms == up[-1].t_ms
    assert segments[0].emitted_at_ms > up[-1].t_ms + 8.0  # found later, cut back on the tip
    assert [s.dropped for s in segments] == [None, None]


def test_the_latency_cap_cuts_a_long_line_before_it_ends() -> None:
    params = WindowParams(
        least_squares=False, canvas_width_px=300, canvas_height_px=200, max_stroke_ms=100
    )
    line = [Sample(8.0 * k, 1.0 * k, 100) for k in range(76)]  # 600 ms, straight
    cut = [s for _, s in run(replace(params, **UNMERGED), [line])]
    assert all(s.drawn_ms <= 100 for s in cut)
    # Samples 8 ms apart: each stroke covers 12 of them (96 ms), the seventh the rest.
    assert [s.drawn_ms for s in cut] == [96.0] * 6 + [24.0]
    assert cut[0].emitted_at_ms == 104.0  # let go by the sample that would pass 100 ms
    assert cut[-1].end_ms == 600.0
    # With the sleeve's floor (73.7 ms) a stroke the cap ends is merged into nothing before it,
    # and the rest, 24 ms, the last, lies on the sixth stroke's line, 0.03 grid units past its
    # end (max_error 0.25): it merges into it at release, and nothing more is sent.
    assert [s.duration_ms for _, s in run(params, [line])] == [96.0] * 6
    assert _merged_back(params, [line]) == [1]
    # A bound tighter than those 0.03 keeps the rest apart: sent where it was drawn, briefer
    # than the floor, to last the floor (the sleeve would slow it to that).
    tight = replace(params, max_error=0.02)
    sent = [s for _, s in run(tight, [line])]
    assert [s.drawn_ms for s in sent] == [96.0] * 6 + [24.0]
    assert [s.duration_ms for s in sent] == [96.0] * 6 + [params.floor_ms]
    assert _merged_back(tight, [line]) == [0]


def test_pieces_briefer_than_the_floor_merge_into_the_next() -> None:
    # A circle of radius 0.5 grid units drawn in 400 ms: the bend rule (0.1 x the chord) cuts
    # it every 47 degrees, 52 ms, briefer than the sleeve's floor (73.7 ms); two such pieces
    # still lie within max_error (0.25) of one stroke, so they merge, and every stroke sent but
    # the last lasts at least the floor.
    params = WindowParams(
        least_squares=False,
        canvas_width_px=300,
        canvas_height_px=200,
        max_stroke_ms=0,
        max_bend=0.1,
        bend_floor=0.01,
    )
    px = 100.0  # pixels per grid unit on this canvas (a 4 x 3 grid)
    circle = [
        Sample(
            8.0 * k,
            150 + 0.5 * px * math.cos(2 * math.pi * k / 50),
            100 + 0.5 * px * math.sin(2 * math.pi * k / 50),
        )
        for k in range(51)
    ]
    unmerged = [s for _, s in run(replace(params, floor_ms=0.0), [circle])]
    merged = [s for _, s in run(params, [circle])]
    assert all(s.duration_ms < params.floor_ms for s in unmerged)
    assert len(merged) < len(unmerged)
    assert all(s.dropped is None for s in merged)
    assert sum(s.merged for s in merged) == len(unmerged) - len(merged)
    assert all(s.duration_ms >= params.floor_ms for s in merged[:-1])


def test_a_cut_the_bound_makes_leaves_no_piece_briefer_than_the_floor_where_it_can() -> None:
    # A corner drawn 40 ms after the press (40 px right, 8 px a sample), then down 4 px a sample:
    # the bound (0.25 grid units, 25 px here) breaks at 112 ms. At the feature, the corner, the
    # piece would last 40 ms, briefer than the sleeve's floor, and the stroke after it bends away
    # too far to merge with it: it would be sent as it is and the sleeve would slow it. The
    # window holds samples drawn at least the floor after the press whose stroke keeps the
    # bound, so the cut is the feature among those.
    params = WindowParams(
        least_squares=False, canvas_width_px=300, canvas_height_px=200, max_stroke_ms=0
    )
    right = [Sample(8.0 * k, 50.0 + 8.0 * k, 50.0) for k in range(6)]
    down = [Sample(40.0 + 8.0 * k, 90.0, 50.0 + 4.0 * k) for k in range(1, 40)]
    path = right + down
    at_corner = [s for _, s in run(replace(params, floor_ms=0.0), [path])]
    assert at_corner[0].end_ms == 40.0  # without the floor: the corner, a 40 ms piece
    strokes = [s for _, s in run(params, [path])]
    first = strokes[0]
    assert first.end_ms == 80.0  # the first sample drawn at least the floor after the press
    assert all(s.duration_ms >= params.floor_ms and s.dropped is None for s in strokes)
    mapping = params.mapping
    for sample in path:
        stroke = next(s for s in strokes if s.start_ms <= sample.t_ms <= s.end_ms)
        point = mapping.to_grid(sample.x, sample.y)
        assert _distance(point, stroke.start, stroke.end) <= params.max_error + FLOAT_TOLERANCE


def _bumped_line(params: WindowParams, bump_ms: float, height: float) -> list[Sample]:
    """A straight line drawn for 400 ms with a bump ``height`` grid units high at ``bump_ms``."""
    origin, right = params.mapping.to_grid(0, 0), params.mapping.to_grid(100, 0)
    px = 100.0 / (right[0] - origin[0])  # pixels per grid unit
    return [
        Sample(8.0 * k, 1.0 * k, 100.0 - height * px * max(0.0, 1 - abs(8.0 * k - bump_ms) / 24))
        for k in range(51)
    ]


def test_the_latency_cap_cuts_at_a_feature_of_the_strokes_second_half_only() -> None:
    params = WindowParams(
        least_squares=False,
        canvas_width_px=300,
        canvas_height_px=200,
        max_stroke_ms=300,
        max_bend=0.0,
        **UNMERGED,
    )
    # A bump 0.2 high (within the bound) 40 ms in: cutting there would leave a 40 ms
    # stroke, too brief to be felt in its drawn time; the line after it is straight, so
    # the cap cuts at the last sample it allows.
    early = [s for _, s in run(params, [_bumped_line(params, 40.0, 0.2)])]
    assert [s.dropped for s in early] == [None, None]
    assert (early[0].start_ms, early[0].end_ms) == (0.0, 296.0)
    # The same bump 200 ms in lies in the stroke's second half: the cut is on it.
    late = [s for _, s in run(params, [_bumped_line(params, 200.0, 0.2)])]
    assert (late[0].start_ms, late[0].end_ms) == (0.0, 200.0)
    assert late[-1].end_ms == 400.0


def test_a_release_a_rounding_error_after_a_frame_still_reaches_the_end() -> None:
    # A 125 Hz pen; the release comes 0.0003 ms after the 30th 60 fps frame, moved on.
    samples = [Sample(k * 8.0, 200.0 + 6.0 * k, 300.0 + 2.0 * k) for k in range(63)]
    release = Sample(500.0 + 0.0003, 200.0 + 6.0 * 63, 300.0 + 2.0 * 63)
    params = WindowParams(
        least_squares=False, canvas_width_px=1200, canvas_height_px=800, max_stroke_ms=0
    )
    segments = [s for _, s in run(params, [[*samples, release]])]
    assert [s.dropped for s in segments] == [None]
    assert segments[-1].end == params.mapping.to_grid(release.x, release.y)


def test_a_sample_earlier_than_the_one_before_is_taken_at_its_time() -> None:
    simplifier = WindowSimplifier(
        WindowParams(least_squares=False, canvas_width_px=300, canvas_height_px=200)
    )
    simplifier.push(Sample(10.0, 0, 100))
    simplifier.push(Sample(20.0, 100, 100))
    simplifier.push(Sample(19.0, 200, 100))
    (last,) = simplifier.end()
    assert last.end_ms == 20.0 and last.drawn_ms == 10.0


def test_window_cap_cuts_at_the_current_frame() -> None:
    params = WindowParams(
        least_squares=False, canvas_width_px=300, canvas_height_px=200, max_window=3, **UNMERGED
    )
    simplifier = WindowSimplifier(params)
    frames = [Sample(20.0 * k, 10.0 * k, 100) for k in range(7)]
    pushed = [[s.end_ms for s in simplifier.push(frame)] for frame in frames]
    assert pushed == [[], [], [], [60.0], [], [], [120.0]]
    assert simplifier.end() == []  # the last frame already ends a stroke
    assert not simplifier.drawing


def test_a_tap_gives_one_dropped_segment() -> None:
    simplifier = WindowSimplifier(WindowParams(least_squares=False))
    assert simplifier.push(Sample(0.0, 500, 500)) == []
    (tap,) = simplifier.end()
    assert tap.dropped == NOT_ENOUGH_DISTANCE and tap.start == tap.end


# --- the command line ---------------------------------------------------------


def _flags(params: dict[str, Any]) -> list[str]:
    numbers = (
        "max_error",
        "max_window",
        "max_stroke_ms",
        "min_duration_ms",
        "min_length",
    )
    # The lookahead only with the core that reads it (else the CLI refuses it).
    if params["least_squares"]:
        return [*simplify_flags("window", params, (*numbers, "lookahead_ms")), "--least-squares"]
    return [*simplify_flags("window", params, numbers), "--no-least-squares"]


@pytest.mark.parametrize(
    "name",
    ["circle/defaults", "zigzag/max-error-0.02", "pause/max-window-8", "two-paths/defaults"],
)
def test_cli_reproduces_the_vectors(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = WINDOW[name]
    recording = write_recording(case, tmp_path / "drawing.json")
    assert main(["simplify", str(recording), "--json", *_flags(case["params"])]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["algorithm"] == "window" and result["params"] == case["params"]
    expected = case["expected"]["segments"]
    sent = [e for e in expected if e["dropped"] is None]
    dropped = [e for e in expected if e["dropped"] is not None]
    assert len(result["strokes"]) == len(sent) and len(result["dropped"]) == len(dropped)
    for got, want in zip(result["strokes"] + result["dropped"], sent + dropped, strict=True):
        assert got["path"] == want["path"] and got.get("reason") == want["dropped"]
        assert got["start"] == pytest.approx(want["start"])
        assert got["end"] == pytest.approx(want["end"])
        assert got["emitted_at_ms"] == pytest.approx(want["emitted_at_ms"])


def test_cli_summary_and_usage_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    recording = write_recording(WINDOW["right-angle/defaults"], tmp_path / "r.json")
    assert main(["simplify", str(recording), "--algorithm", "window", "--max-error", "0.05"]) == 0
    out = capsys.readouterr().out
    assert "(window, least squares: max error 0.05 grid units, strokes of 73.701 ms or more" in out
    assert "sent 30 ms after their end is drawn, cut after 200 ms of drawing; " in out
    assert main(["simplify", str(recording), "--no-least-squares", "--max-stroke-ms", "0"]) == 0
    out = capsys.readouterr().out
    assert "(window, chord: max error 0.25 grid units, every sample, not cut by time" in out
    with pytest.raises(SystemExit) as exit_:
        main(["simplify", str(recording), "--algorithm", "window", "--max-error", "0"])
    assert exit_.value.code == 2
    assert "--max-error: 0 is out of range; give a number from 0.001" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_:
        main(["simplify", str(recording), "--algorithm", "window", "--check-frames", "5"])
    assert exit_.value.code == 2
    assert "--check-frames only applies to --algorithm angle" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["simplify", str(recording), "--paper", "--max-error", "0.1"])
    assert "--max-error only applies to --algorithm window" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["simplify", str(recording), "--paper", "--algorithm", "window"])
    assert "--paper is the angle simplifier" in capsys.readouterr().err
    # The project's default is the window simplifier at its defaults; --paper is the paper's.
    assert main(["simplify", str(recording), "--json"]) == 0
    default = json.loads(capsys.readouterr().out)
    assert default["algorithm"] == "window" and default["params"]["max_error"] == 0.25
    assert main(["simplify", str(recording), "--paper", "--json"]) == 0
    paper = json.loads(capsys.readouterr().out)
    assert paper["algorithm"] == "angle" and paper["params"]["max_angle_deg"] == 20.0


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (
            ["--max-bend", "0.2"],
            "--max-bend only applies with --no-least-squares; drop it, or add "
            "--no-least-squares (least squares is on by default)",
        ),
        (
            ["--least-squares", "--bend-floor", "0.2"],
            "--bend-floor only applies with --no-least-squares; drop it, or give "
            "--no-least-squares instead of --least-squares",
        ),
        (
            ["--no-least-squares", "--lookahead-ms", "80"],
            "--lookahead-ms only applies with --least-squares; drop it, or give "
            "--least-squares instead of --no-least-squares",
        ),
    ],
)
@pytest.mark.parametrize("command", ["simplify", "replay"])
def test_cli_refuses_an_option_of_the_core_not_run(
    command: str,
    flags: list[str],
    message: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    recording = write_recording(WINDOW["circle/defaults"], tmp_path / "r.json")
    with pytest.raises(SystemExit) as exit_:
        main([command, str(recording), *flags])
    assert exit_.value.code == 2
    assert f"Error: {message}." in capsys.readouterr().err


def test_cli_takes_an_option_of_the_core_the_recording_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The check is on the settings in effect: a recording made with the chord core takes the
    bend rule and refuses the lookahead, unless --least-squares is given too."""
    path = write_recording(WINDOW["circle/defaults"], tmp_path / "r.json")
    document = json.loads(path.read_text())
    chord = {"algorithm": "window", "params": {"least_squares": False, "max_error": 0.5}}
    path.write_text(json.dumps({**document, "simplifier": chord}))
    runs = {}
    for bend in ("0", "0.05"):
        assert main(["simplify", str(path), "--max-bend", bend, "--bend-floor", "0", "--json"]) == 0
        runs[bend] = json.loads(capsys.readouterr().out)
        assert runs[bend]["params"]["least_squares"] is False
    # Taken and read: the bend rule cuts this circle elsewhere.
    assert runs["0.05"]["strokes"] != runs["0"]["strokes"]
    with pytest.raises(SystemExit) as exit_:
        main(["simplify", str(path), "--lookahead-ms", "80"])
    assert exit_.value.code == 2
    assert (
        "--lookahead-ms only applies with --least-squares; drop it, or add --least-squares "
        "(the recording's settings have least squares off)" in capsys.readouterr().err
    )
    assert main(["simplify", str(path), "--least-squares", "--lookahead-ms", "80", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["params"]["lookahead_ms"] == 80


# The parameters one core of the window reads and the other ignores, as declared.
ONE_CORE = {n: s.only_when for n, s in WINDOW_PARAMS.items() if s.only_when is not None}
# Values to try for each: the default and others across its range.
ONE_CORE_VALUES = {"lookahead_ms": [0.0, 80.0, 1000.0], "max_bend": [0.05, 0.3, 1.0]}


def test_the_parameters_of_one_core_are_declared() -> None:
    assert ONE_CORE == {
        "max_bend": ("least_squares", False),
        "bend_floor": ("least_squares", False),
        "lookahead_ms": ("least_squares", True),
    }


@pytest.mark.parametrize("name", sorted(ONE_CORE))
def test_a_parameter_of_one_core_changes_nothing_under_the_other(name: str) -> None:
    """What ``only_when`` declares is what the cores do: under the other core no value of the
    parameter changes a stroke; under its own some value does."""
    switch, needed = ONE_CORE[name]
    values = ONE_CORE_VALUES.get(name, [0.0, 0.5, 5.0])
    paths = [
        [Sample(*s) for s in path]
        for vector in ("circle/defaults", "zigzag/defaults", "two-paths/defaults", "slow/defaults")
        for path in WINDOW[vector]["paths"]
    ]
    # The bend floor acts only while the bend rule is on.
    base: dict[str, Any] = {"max_bend": 0.1} if name == "bend_floor" else {}

    def strokes(value: float, on: bool) -> list[tuple[int, Segment]]:
        return run(WindowParams(**{**base, switch: on, name: value}), paths)

    default = WINDOW_PARAMS[name].default
    assert isinstance(default, float)
    ignored, read = strokes(default, not needed), strokes(default, needed)
    for value in values:
        assert strokes(value, not needed) == ignored, (name, value)
    assert any(strokes(value, needed) != read for value in values), name


def test_cli_uses_the_recordings_algorithm_and_parameters(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_recording(WINDOW["circle/max-error-0.02"], tmp_path / "w.json")
    document = json.loads(path.read_text())
    path.write_text(
        json.dumps(
            {
                **document,
                "simplifier": {
                    "algorithm": "window",
                    "params": {"max_error": 0.02, "least_squares": False},
                },
            }
        )
    )
    assert main(["simplify", str(path), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["algorithm"] == "window" and result["params"]["max_error"] == 0.02
    expected = WINDOW["circle/max-error-0.02"]["expected"]["segments"]
    assert len(result["strokes"]) + len(result["dropped"]) == len(expected)
    path.write_text(json.dumps({**document, "simplifier": {"algorithm": "dp"}}))
    assert main(["simplify", str(path)]) == 1
    assert "'dp' is unknown; choose one with --algorithm angle|window" in capsys.readouterr().err


# --- properties over random paths ---------------------------------------------


@st.composite
def paths(draw: st.DrawFn, min_step_ms: float = 0.0) -> tuple[WindowParams, list[Sample]]:
    params = WindowParams(
        max_error=draw(st.sampled_from([0.001, 0.02, 0.05, 0.2, 1.0])),
        max_window=draw(st.sampled_from([1, 2, 5, 64, 1000])),
        max_stroke_ms=draw(st.sampled_from([0.0, 50.0, 300.0])),
        min_length=draw(st.sampled_from([0.0, 0.1, 0.4])),
        min_duration_ms=draw(st.sampled_from([0.0, 6.1, 80.0])),
        max_bend=draw(st.sampled_from([0.0, 0.1, 0.3])),
        bend_floor=draw(st.sampled_from([0.0, 0.05])),
        floor_ms=draw(st.sampled_from([0.0, 73.7, 200.0])),
        rest_ms=draw(st.sampled_from([0.0, 30.0, 100.0])),
        stretch=draw(st.booleans()),
        least_squares=draw(st.booleans()),
        lookahead_ms=draw(st.sampled_from([0.0, 30.0, 100.0])),
        canvas_width_px=800,
        canvas_height_px=600,
    )
    # Starting and stepping past the canvas exercises the clamping onto the grid. The samples
    # the simplifier takes: with the pen standing through a stop's gap (see
    # test_a_gap_is_taken_as_the_pen_standing), so that the properties below hold for each.
    samples = taken_samples(
        random_walk(draw, margin_px=50, min_step_ms=min_step_ms), params.rest_ms
    )
    return params, samples


@st.composite
def _stopping_walks(draw: st.DrawFn) -> list[Sample]:
    """A random walk with up to four stops: gaps of up to 900 ms with no sample."""
    samples = random_walk(draw, margin_px=50)
    stops = draw(st.lists(st.tuples(st.integers(1, 150), st.floats(0, 900)), max_size=4))
    shifts = [sum(gap for at, gap in stops if at <= j) for j in range(len(samples))]
    return [
        Sample(s.t_ms + shift, s.x, s.y, s.pressure)
        for s, shift in zip(samples, shifts, strict=True)
    ]


@settings(max_examples=200, deadline=None)
@given(st.sampled_from([0.0, 30.0, 100.0, 300.0]), st.booleans(), _stopping_walks())
def test_a_gap_is_taken_as_the_pen_standing(
    rest_ms: float, least_squares: bool, samples: list[Sample]
) -> None:
    """A sample rest_ms or more after the one before gives the strokes of the pen standing at
    the one before until it (as the page samples a still pen), and only such a sample."""
    params = WindowParams(rest_ms=rest_ms, least_squares=least_squares)
    expected = samples[:1]
    for a, b in itertools.pairwise(samples):  # (the walk's times never run backwards)
        if 0 < rest_ms <= b.t_ms - a.t_ms:
            expected.append(Sample(b.t_ms, a.x, a.y, a.pressure))
        expected.append(b)
    taken = taken_samples(samples, rest_ms)
    assert taken == expected
    assert run(params, [samples]) == run(params, [taken])


def _rest_radius(params: WindowParams) -> float:
    """How far a sample the pen rested at may lie from the point that stands for the rest."""
    return rest_radius(params) if params.rest_ms > 0 else 0.0


def _moved(params: WindowParams) -> float:
    return max(LINE_SHARE * params.max_error, _rest_radius(params)) + FLOAT_TOLERANCE


def _ends(
    params: WindowParams, samples: list[Sample], segments: list[Segment], merged_back: int = 0
) -> list[tuple[int, int, Segment]]:
    """Each segment with the first and last sample it covers (see ``_covered``); with
    ``merged_back``, the path's last piece merged at release into the last segment."""
    mapping, moved = params.mapping, _moved(params)
    covered: list[tuple[int, int, Segment]] = []
    start = 0
    for number, segment in enumerate(segments, start=1):
        ends = [
            j
            for j in range(min(start + 1, len(samples) - 1), len(samples))
            if samples[j].t_ms >= segment.end_ms
            and math.dist(mapping.to_grid(samples[j].x, samples[j].y), segment.end) <= moved
        ]
        assert ends, f"{segment} does not end on a sample"
        # Repeated samples (same time and place) are one: the first, but the last for the last
        # (of those at the first's time: later ones at that place are a rest after it). Where
        # samples of one time lie near each other, the one the segment ends on exactly (the
        # least squares end every stroke on a sample).
        exact = [j for j in ends if mapping.to_grid(samples[j].x, samples[j].y) == segment.end]
        end = exact[0] if exact else ends[0]
        if number == len(segments):
            end = max(j for j in ends if samples[j].t_ms == samples[ends[0]].t_ms)
        covered.append((start, end, segment))
        start = end
    # The samples after the last segment are a rest at its end, or the last piece, merged into it
    # at release: within max_error of it.
    if segments:
        last = segments[-1]
        limit = min(2 * _rest_radius(params), params.max_error) + FLOAT_TOLERANCE
        if merged_back:
            limit = params.max_error + FLOAT_TOLERANCE
        for sample in samples[start + 1 :]:
            point = mapping.to_grid(sample.x, sample.y)
            assert _distance(point, last.start, last.end) <= limit, (last, sample)
    return covered


def _covered(params: WindowParams, samples: list[Sample]) -> list[tuple[int, int, Segment]]:
    """Each segment with the indices of the first and last sample it covers.

    Segments join end to start, so each starts at the sample the one before
    ended on; it ends on the first sample (from there) drawn at or after its end
    time, at its point or, going on along a line the latency cap cut, within
    LINE_SHARE x max_error of it (where the pen rested, within the rest radius).
    The samples after the last segment are a rest at its end, or a last piece merged into it at
    release (``merged_back``).
    """
    simplifier = WindowSimplifier(params)
    segments = [out for sample in samples for out in simplifier.push(sample)] + simplifier.end()
    return _ends(params, samples, segments, simplifier.merged_back)


@settings(max_examples=250, deadline=None)
@given(paths())
def test_every_drawn_sample_lies_within_max_error_of_its_stroke(
    case: tuple[WindowParams, list[Sample]],
) -> None:
    params, samples = case
    # The least squares end strokes on samples, found here by time and place: where a path goes
    # back and forth with no time passing, which sample a stroke ends on is ambiguous (the test
    # below measures those against every stroke).
    assume(not params.least_squares or all(a.t_ms < b.t_ms for a, b in itertools.pairwise(samples)))
    mapping = params.mapping
    for first, last, segment in _covered(params, samples):
        for sample in samples[first : last + 1]:
            distance = _distance(mapping.to_grid(sample.x, sample.y), segment.start, segment.end)
            assert distance <= params.max_error + FLOAT_TOLERANCE, (segment, sample, distance)


@settings(max_examples=150, deadline=None)
@given(paths())
def test_segments_join_and_keep_the_path_ends(case: tuple[WindowParams, list[Sample]]) -> None:
    params, samples = case
    # A last piece merged at release leaves the release within max_error of the last stroke.
    merged_back = _merged_back(params, [samples]) != [0]
    assert_joined_from_press_to_release(
        params,
        samples,
        release_within=params.max_error + FLOAT_TOLERANCE if merged_back else _moved(params),
        rests=params.rest_ms > 0 or params.max_stroke_ms > 0,
        release_on_last=merged_back,
    )


@settings(max_examples=300, deadline=None)
@given(paths(), st.sampled_from([0.001, 0.05, 0.1, 0.15, 0.25, 1.0]))
def test_no_piece_is_dropped_and_every_sample_lies_within_max_error_of_a_sent_stroke(
    case: tuple[WindowParams, list[Sample]], max_error: float
) -> None:
    # Whatever the caps and minimums: a piece too short to send merges into a neighbour, or is
    # sent; only a path that is one piece too short in all (a tap) is dropped, and all of it.
    params, samples = case
    params = replace(params, max_error=max_error)
    segments = [s for _, s in run(params, [samples])]
    if any(s.dropped is not None for s in segments):
        assert len(segments) == 1, segments
        assert segments[0].length < params.min_length or segments[0].duration_ms < (
            params.min_duration_ms
        )
        return
    mapping = params.mapping
    for sample in samples:
        point = mapping.to_grid(sample.x, sample.y)
        nearest = min(_distance(point, s.start, s.end) for s in segments)
        assert nearest <= params.max_error + FLOAT_TOLERANCE, (sample, nearest)


@settings(max_examples=150, deadline=None)
@given(paths(min_step_ms=0.01))
def test_a_short_piece_is_merged_or_else_could_not_be(
    case: tuple[WindowParams, list[Sample]],
) -> None:
    # A stroke sent too short to send, or briefer than the sleeve's floor, next to a stroke it
    # was held with, could not have merged: the stroke from the first's start to the second's
    # end would leave a sample farther than max_error. A merged stroke covers the pieces it
    # counts, so it is at least as long in time as they are many (each drawn at least one step).
    params, samples = case
    covered = _covered(params, samples)
    for first, last, segment in covered:
        assert last - first >= segment.merged + 1 or len(samples) == 1, segment


@settings(max_examples=300, deadline=None)
@given(paths(), st.sampled_from([0.05, 0.1, 0.15, 0.25]), st.booleans())
def test_a_last_piece_merges_at_release_where_the_stroke_before_covers_it_or_else_could_not(
    case: tuple[WindowParams, list[Sample]], max_error: float, strict: bool
) -> None:
    # Merged at release: nothing dropped then, the path's last sent stroke ends before the
    # release and every sample drawn from its end on lies within max_error of it. Not merged, the
    # last sent stroke briefer than the floor has a stroke before it that leaves a sample drawn
    # from its end on farther than max_error (without rests, which send a held piece before the
    # release; with strict minimums, one still below them merges back or is dropped there).
    params, samples = case
    params = replace(params, max_error=max_error, strict_minimums=strict)
    simplifier = WindowSimplifier(params)
    segments = [out for sample in samples for out in simplifier.push(sample)]
    at_rests = simplifier.merged_back
    released = simplifier.end()
    segments += released
    sent = [s for s in segments if s.dropped is None]
    mapping = params.mapping
    points = [(sample.t_ms, mapping.to_grid(sample.x, sample.y)) for sample in samples]

    def farthest_from(stroke: Segment) -> float:
        return max(_distance(p, stroke.start, stroke.end) for t, p in points if t >= stroke.end_ms)

    if simplifier.merged_back > at_rests:
        assert sent and all(s.dropped is None for s in released)
        assert sent[-1].end_ms <= samples[-1].t_ms
        assert farthest_from(sent[-1]) <= params.max_error + FLOAT_TOLERANCE
        return
    brief = max(params.min_duration_ms, params.floor_ms)
    if params.rest_ms == 0 and len(sent) >= 2 and sent[-1].duration_ms < brief:
        assert farthest_from(sent[-2]) > params.max_error - FLOAT_TOLERANCE


def _core_covered(params: WindowParams, samples: list[Sample]) -> list[tuple[int, int, Segment]]:
    """``_covered`` of the window's own pieces, before any is merged."""
    core = WindowCore(params)
    segments = [out for sample in samples for out in core.push(sample)] + core.end()
    return _ends(params, samples, segments)


@settings(max_examples=150, deadline=None)
@given(paths(min_step_ms=0.01))  # every sample its own time: each stroke's samples are known
def test_strokes_keep_the_caps_and_are_let_go_by_a_later_sample(
    case: tuple[WindowParams, list[Sample]],
) -> None:
    # The caps bound the window's pieces; a merged stroke may be longer than one piece.
    params, samples = case
    times = {s.t_ms for s in samples}
    for first, last, segment in _core_covered(params, samples):
        # The work cap counts the samples the stroke holds: not those of a rest before it.
        held = sum(1 for sample in samples[first + 1 : last + 1] if sample.t_ms > segment.start_ms)
        assert held <= params.max_window
        assert last > first or len(samples) == 1, "only a one-sample path gives an empty stroke"
        if params.max_stroke_ms and segment.duration_ms > params.max_stroke_ms:
            # Only a single step, or a stroke still too short to send a sample earlier.
            before = params.mapping.to_grid(samples[last - 1].x, samples[last - 1].y)
            short = math.dist(segment.start, before) < params.min_length
            assert last - first == 1 or short
        assert segment.emitted_at_ms in times and segment.emitted_at_ms >= segment.end_ms


# ---- The same strokes, to the last bit, as the simplifier first written (window_reference) ----


def _bits(segments: list[Segment]) -> list[tuple[object, ...]]:
    """Every float as its hex form, so -0.0 differs from 0.0 and a NaN equals a NaN."""
    return [
        (
            *(float(v).hex() for v in (*s.start, *s.end, s.start_ms, s.end_ms, s.emitted_at_ms)),
            s.dropped,
        )
        for s in segments
    ]


def _coordinate(draw: st.DrawFn, scale: float, grid_px: float | None) -> float:
    """A step: on a coarse pixel grid (ties, repeats, collinear runs) or anywhere, rarely NaN."""
    if draw(st.integers(0, 199)) == 0:
        return math.nan
    if grid_px is not None:
        return draw(st.integers(-3, 3)) * grid_px
    return draw(st.floats(-scale, scale))


@st.composite
def drawings(draw: st.DrawFn) -> tuple[WindowParams, list[list[Sample]]]:
    """Parameters and paths that put samples near max_error of their strokes, often.

    Steps are drawn at a scale against max_error (in pixels) so that strokes both skip and make
    the full test; some paths run on a coarse pixel grid so that distances tie exactly; times
    may stand still or run backwards; samples may leave the canvas or be NaN.
    """
    columns, rows = draw(st.integers(1, 8)), draw(st.integers(1, 8))
    params = WindowParams(
        least_squares=False,
        max_error=draw(st.sampled_from([0.001, 0.02, 0.25, 1.0])),
        max_window=draw(st.sampled_from([1, 2, 7, 256, 1000])),
        max_stroke_ms=draw(st.sampled_from([0.0, 50.0, 300.0])),
        min_length=draw(st.sampled_from([0.0, 0.1, 0.4])),
        min_duration_ms=draw(st.sampled_from([0.0, 6.1, 80.0])),
        max_bend=draw(st.sampled_from([0.0, 0.05, 0.1, 0.3])),
        bend_floor=draw(st.sampled_from([0.0, 0.01, 0.05, 0.5])),
        rest_ms=draw(st.sampled_from([0.0, 30.0, 100.0])),
        rows=rows,
        columns=columns,
        stretch=draw(st.booleans()),
        canvas_width_px=800,
        canvas_height_px=600,
    )
    scale = params.mapping.scale or 1.0  # grid units per pixel
    step_px = draw(st.sampled_from([0.1, 0.5, 1.0, 3.0])) * params.max_error / scale
    # Sideways noise against max_error: none (lines the latency cap cuts, straight on), a
    # line's (within LINE_SHARE), or a scribble's.
    noise_px = draw(st.sampled_from([0.0, 0.05, 0.3, 1.0])) * params.max_error / scale
    grid_px = draw(st.sampled_from([None, None, 1.0, step_px]))
    drawn = []
    for _ in range(draw(st.integers(1, 2))):
        x, y, t_ms = draw(st.floats(-50, 850)), draw(st.floats(-50, 650)), draw(st.floats(0, 100))
        heading = draw(st.floats(-math.pi, math.pi))
        path = [Sample(t_ms, x, y)]
        for _ in range(draw(st.integers(0, 80))):
            # Mostly straight on, with sideways noise: lines the latency cap cuts, and corners.
            if draw(st.integers(0, 15)) == 0:
                heading = draw(st.floats(-math.pi, math.pi))
            along = step_px if grid_px is None else 0.0
            x += along * math.cos(heading) + _coordinate(draw, noise_px, grid_px)
            y += along * math.sin(heading) + _coordinate(draw, noise_px, grid_px)
            if math.isnan(x) or math.isnan(y):
                path.append(Sample(t_ms, x, y))
                x, y = path[-2].x, path[-2].y
                continue
            t_ms += draw(st.sampled_from([0.0, -3.0, 8.0, 16.7, 40.0]))
            path.append(Sample(t_ms, x, y))
        drawn.append(path)
    return params, drawn


@settings(max_examples=600, deadline=None)
@given(drawings())
def test_the_same_strokes_to_the_last_bit_as_the_reference(
    case: tuple[WindowParams, list[list[Sample]]],
) -> None:
    params, drawn = case
    fast, reference = WindowCore(params), ReferenceWindowSimplifier(params)
    for path in drawn:
        for sample in path:
            assert _bits(fast.push(sample)) == _bits(reference.push(sample)), sample
            assert fast.line_start == reference.line_start and fast.drawing == reference.drawing
        assert _bits(fast.end()) == _bits(reference.end())
        assert fast.line_start is None and not fast.drawing


# ---- Drawings along the canvas edges: every stroke stays on the grid ----


@st.composite
def edge_drawings(draw: st.DrawFn) -> tuple[WindowParams, list[Sample]]:
    """A line drawn along the canvas edges, on them and beyond, that the latency cap cuts.

    The canvas has the grid's aspect ratio (or is stretched onto it), so its edges map onto the
    grid's and a sample beyond one maps onto it. The line runs along one edge, or turns its
    corners onto the next ones (a "U"); it may start inside and drift across the edge at a shallow
    angle, wobble about it or run exactly on it, so that a stroke the cap ended may point a little
    off the grid.
    """
    columns, rows = draw(st.integers(2, 8)), draw(st.integers(2, 8))
    unit_px = draw(st.sampled_from([100.0, 250.0]))  # canvas pixels per grid unit
    width_px, height_px = (columns - 1) * unit_px, (rows - 1) * unit_px
    params = WindowParams(
        least_squares=False,
        max_error=draw(st.sampled_from([0.02, 0.1, 0.25, 0.5])),
        max_window=draw(st.sampled_from([7, 256])),
        max_stroke_ms=draw(st.sampled_from([50.0, 100.0, 300.0])),
        min_length=draw(st.sampled_from([0.0, 0.1])),
        min_duration_ms=draw(st.sampled_from([0.0, 6.1])),
        rows=rows,
        columns=columns,
        stretch=draw(st.booleans()),
        canvas_width_px=width_px,
        canvas_height_px=height_px,
    )
    error_px = params.max_error * unit_px
    # The canvas corners clockwise, and each edge's inward normal.
    corners = [(0.0, 0.0), (width_px, 0.0), (width_px, height_px), (0.0, height_px)]
    inward = [(0.0, 1.0), (-1.0, 0.0), (0.0, -1.0), (1.0, 0.0)]
    first_edge, legs = draw(st.integers(0, 3)), draw(st.integers(1, 3))
    # How far inside the edge the line runs (pixels; negative is beyond it) where it starts and
    # where it ends, and its noise across the edge: none, a line's or more.
    depth_from_px = draw(st.floats(-0.5, 1.0)) * error_px
    depth_to_px = draw(st.floats(-0.5, 1.0)) * error_px
    noise_px = draw(st.sampled_from([0.0, 0.05, 0.2])) * error_px
    step_ms = draw(st.sampled_from([4.0, 8.0, 16.7]))
    samples: list[Sample] = []
    for leg in range(legs):
        edge = (first_edge + leg) % 4
        (x0, y0), (x1, y1) = corners[edge], corners[(edge + 1) % 4]
        nx, ny = inward[edge]
        # The first leg may start partway along, the last end partway (or overshoot a corner).
        start = draw(st.floats(-0.05, 0.5)) if leg == 0 else 0.0
        stop = draw(st.floats(0.5, 1.05)) if leg == legs - 1 else 1.0
        count = draw(st.integers(2, 60))
        noises = draw(st.lists(st.floats(-1.0, 1.0), min_size=count, max_size=count))
        for k, noise in enumerate(noises):
            share = k / (count - 1)
            along = start + (stop - start) * share
            depth = (leg + share) / legs * (depth_to_px - depth_from_px) + depth_from_px
            depth += noise * noise_px
            x, y = x0 + (x1 - x0) * along + nx * depth, y0 + (y1 - y0) * along + ny * depth
            samples.append(Sample(len(samples) * step_ms, x, y))
    return params, samples


@settings(max_examples=400, deadline=None)
@given(edge_drawings())
def test_a_drawing_along_the_edges_gives_strokes_on_the_grid(
    case: tuple[WindowParams, list[Sample]],
) -> None:
    # The sleeve refuses a stroke that starts or ends off the grid, and the mapping puts every
    # drawn sample on it: a line going on along a stroke the cap ended must not leave it.
    params, samples = case
    x_max, y_max = params.columns - 1, params.rows - 1
    for _, segment in run(params, [samples]):
        for x, y in (segment.start, segment.end):
            assert 0.0 <= x <= x_max and 0.0 <= y <= y_max, segment


# --- a resting pen and a slow, steady one -------------------------------------------------------

# The slowest steady pen that is never taken for a resting one: half a pixel a frame at 60 fps.
SLOW_PEN_PX_PER_MS = 0.5 * 60 / 1000


@st.composite
def slow_legs(draw: st.DrawFn) -> tuple[WindowParams, list[Sample]]:
    """A straight leg drawn at a steady speed of at least ``SLOW_PEN_PX_PER_MS``, in any
    direction, on any canvas and grid, sampled every frame or every pointer event (times
    jittered), its samples at exact or whole pixels."""
    width_px = draw(st.floats(200, 4000))
    height_px = draw(st.floats(200, 4000))
    params = WindowParams(
        least_squares=False,
        max_stroke_ms=0.0,  # one stroke a leg: only a rest could cut it
        max_window=10_000,
        rest_ms=draw(st.sampled_from([100.0, 200.0, 500.0])),
        min_length=draw(st.sampled_from([0.0, 0.1, 0.4])),
        max_error=draw(st.sampled_from([0.05, 0.25, 1.0])),
        columns=draw(st.integers(2, 12)),
        rows=draw(st.integers(2, 12)),
        stretch=draw(st.booleans()),
        canvas_width_px=width_px,
        canvas_height_px=height_px,
    )
    speed = draw(st.floats(SLOW_PEN_PX_PER_MS, 0.5))
    angle = draw(st.floats(0, 2 * math.pi))
    duration_ms = draw(st.floats(300, 4000))
    step_ms = draw(st.sampled_from([1000 / 60, 8.0]))
    whole_px = draw(st.booleans())
    length_px = speed * duration_ms
    ux, uy = math.cos(angle), math.sin(angle)
    # A start from which the whole leg stays on the canvas (no clamping onto the grid's edge).
    room_x, room_y = width_px - abs(ux) * length_px - 2, height_px - abs(uy) * length_px - 2
    assume(room_x > 0 and room_y > 0)
    x0 = draw(st.floats(0, 1)) * room_x + 1 + max(0.0, -ux) * length_px
    y0 = draw(st.floats(0, 1)) * room_y + 1 + max(0.0, -uy) * length_px
    samples, t_ms = [], 0.0
    while t_ms <= duration_ms:
        x, y = x0 + ux * speed * t_ms, y0 + uy * speed * t_ms
        if whole_px:
            x, y = round(x), round(y)
        samples.append(Sample(t_ms, x, y))
        t_ms += step_ms * draw(st.floats(0.5, 1.5))
    return params, samples


@settings(max_examples=300, deadline=None)
@given(slow_legs())
def test_a_slow_steady_leg_is_never_cut_for_rest(case: tuple[WindowParams, list[Sample]]) -> None:
    params, samples = case
    core = WindowCore(params)
    for sample in samples:
        assert core.push(sample) == [], sample
        assert not core.rested, sample
    (stroke,) = core.end()
    mapping = params.mapping
    assert stroke.start_ms == samples[0].t_ms and stroke.end_ms == samples[-1].t_ms
    assert stroke.start == mapping.to_grid(samples[0].x, samples[0].y)
    assert stroke.end == mapping.to_grid(samples[-1].x, samples[-1].y)


@st.composite
def rests(draw: st.DrawFn) -> tuple[WindowParams, list[Sample], int, int]:
    """A leg, a rest of at least rest_ms at its end (the pen still, or trembling well within the
    rest radius), then a leg in another direction; with the index of the rest's first and last
    samples."""
    cap_ms = draw(st.sampled_from([0.0, 200.0]))
    params = WindowParams(
        least_squares=False,
        max_stroke_ms=cap_ms,
        # A rest longer than the latency cap is the crawl rule's: the stroke after it starts at
        # most the cap before the pen moves on.
        rest_ms=draw(st.sampled_from([50.0, 100.0] if cap_ms else [50.0, 100.0, 300.0])),
        canvas_width_px=1200.0,
        canvas_height_px=800.0,
    )
    radius_px = rest_radius(params) / params.mapping.scale
    step_ms = draw(st.sampled_from([1000 / 60, 8.0]))
    step_px = draw(st.floats(1.5, 9.0))  # long enough to send, short enough to stay on the canvas
    speed = step_px / step_ms
    samples = [Sample(k * step_ms, 200.0 + step_px * k, 400.0) for k in range(40)]
    arrival = len(samples) - 1
    x, y, t_ms = samples[-1].x, samples[-1].y, samples[-1].t_ms
    tremble = draw(st.sampled_from([0.0, 0.4])) * radius_px
    rest_steps = math.ceil(draw(st.floats(1.2, 4.0)) * params.rest_ms / step_ms)
    for _ in range(rest_steps):
        t_ms += step_ms
        dx, dy = draw(st.floats(-1, 1)) * tremble, draw(st.floats(-1, 1)) * tremble
        samples.append(Sample(t_ms, x + dx / math.sqrt(2), y + dy / math.sqrt(2)))
    leave = len(samples) - 1
    for k in range(1, 40):
        samples.append(Sample(t_ms + k * step_ms, x, y - speed * step_ms * k))
    return params, samples, arrival, leave


@settings(max_examples=200, deadline=None)
@given(rests())
def test_a_rest_ends_the_stroke_before_it_and_is_not_played(
    case: tuple[WindowParams, list[Sample], int, int],
) -> None:
    params, samples, arrival, leave = case
    simplifier = WindowSimplifier(params)
    during_rest: list[Segment] = []
    after: list[Segment] = []
    for index, sample in enumerate(samples):
        out = simplifier.push(sample)
        if arrival < index <= leave:
            during_rest.extend(out)
        elif index > leave:
            after.extend(out)
    after.extend(simplifier.end())
    # The stroke that arrives at the rest is sent while the pen still rests, ending where it
    # rests, when the rest began (no later than the pen's arrival).
    assert during_rest, "no stroke was let go while the pen rested"
    last = during_rest[-1]
    rest_point = params.mapping.to_grid(samples[arrival].x, samples[arrival].y)
    assert math.dist(last.end, rest_point) <= rest_radius(params) + FLOAT_TOLERANCE
    # A rest is told after rest_ms of it, and the latency cap may end a stroke first; a piece
    # held to merge, briefer than the sleeve's floor, takes the time it needs from the rest.
    assert last.end_ms <= samples[arrival].t_ms + max(params.rest_ms, params.floor_ms)
    # Nothing plays the rest: the next stroke starts when the pen moves on (if the latency cap
    # ended a stroke in the rest, what is left of it may be too brief to tell: under rest_ms).
    assert after, "the leg after the rest was not sent"
    told_ms = params.rest_ms if params.max_stroke_ms else 0.0
    assert after[0].start_ms >= samples[leave].t_ms - told_ms


@st.composite
def stops(draw: st.DrawFn) -> tuple[WindowParams, list[Sample], list[tuple[float, float]]]:
    """Legs between points of the canvas at a steady pen's speed, with the pen held still
    between some of them (a sample every 32 ms, as the page and the Processing library sample a
    still pen) for longer than rest_ms; either core, strict minimums or not (a wearer's limits
    up to a piece of half a grid unit and 150 ms). With each stop's first and last times."""
    least_squares = draw(st.booleans())
    cap_ms = draw(st.sampled_from([0.0, 200.0]))
    params = WindowParams(
        least_squares=least_squares,
        strict_minimums=draw(st.booleans()),
        min_length=draw(st.sampled_from([0.1, 0.3, 0.5])),
        min_duration_ms=draw(st.sampled_from([6.1, 120.0, 150.0])),
        # The chord core's crawl rule moves a stroke's start on before a rest longer than the
        # latency cap is seen (the stroke after it starts at most the cap before the pen moves).
        rest_ms=draw(
            st.sampled_from([50.0, 100.0] if cap_ms and not least_squares else [50.0, 100.0, 300.0])
        ),
        max_stroke_ms=cap_ms,
        canvas_width_px=900.0,
        canvas_height_px=600.0,
    )
    step_ms = draw(st.sampled_from([1000 / 60, 8.0]))
    speed = draw(st.floats(0.2, 1.5))  # px/ms: 12 to 90 px a frame at 60 Hz
    x, y = draw(st.floats(0, 900)), draw(st.floats(0, 600))
    t_ms = 0.0
    samples = [Sample(t_ms, x, y)]
    held: list[tuple[float, float]] = []
    for _ in range(draw(st.integers(2, 5))):
        tx, ty = draw(st.floats(0, 900)), draw(st.floats(0, 600))
        steps = max(2, math.ceil(math.hypot(tx - x, ty - y) / (speed * step_ms)))
        for k in range(1, steps + 1):
            t_ms += step_ms
            samples.append(Sample(t_ms, x + (tx - x) * k / steps, y + (ty - y) * k / steps))
        x, y = tx, ty
        if draw(st.booleans()):
            first = t_ms
            for _ in range(math.ceil((params.rest_ms + draw(st.floats(64, 1000))) / 32.0)):
                t_ms += 32.0
                samples.append(Sample(t_ms, x, y))
            held.append((first, t_ms))
    return params, samples, held


@settings(max_examples=300, deadline=None)
@given(stops())
def test_no_sent_stroke_spans_a_rest(
    case: tuple[WindowParams, list[Sample], list[tuple[float, float]]],
) -> None:
    """A rest is not played (the rest rule): no sent stroke starts before a stop longer than
    rest_ms and ends after it, with strict minimums too (a piece held below them is not merged
    across the stop into the stroke after it). What is not sent is said: every piece is sent,
    dropped with its reason, or merged back into the stroke before it."""
    params, samples, held = case
    simplifier = WindowSimplifier(params)
    segments = [out for sample in samples for out in simplifier.push(sample)] + simplifier.end()
    sent = [s for s in segments if s.dropped is None]
    assert sent or segments, "a path gave nothing, not even a dropped piece"
    for first, last in held:
        for stroke in sent:
            assert not (stroke.start_ms <= first and stroke.end_ms >= last), (first, last, stroke)
    if params.strict_minimums:
        for stroke in sent:
            assert stroke.length >= params.min_length - FLOAT_TOLERANCE, stroke
            assert stroke.drawn_ms >= params.min_duration_ms - FLOAT_TOLERANCE, stroke


@pytest.mark.parametrize("strict", [False, True])
@pytest.mark.parametrize("cap_ms", [0.0, 200.0])
def test_a_stop_after_a_strokes_vertex_is_not_played(strict: bool, cap_ms: float) -> None:
    """Out along a line, a stop longer than rest_ms, and back (least squares): the stroke up to
    the stop is not let go through part of it (the stop began after its vertex, so the pen was
    not still since the anchor), and no stroke spans the stop, with a wearer's strict minimums
    too (a piece held before it merges back or is dropped, never across it)."""
    params = WindowParams(
        max_stroke_ms=cap_ms,
        rest_ms=300.0,
        strict_minimums=strict,
        min_duration_ms=150.0 if strict else 0.0,
        canvas_width_px=900.0,
        canvas_height_px=600.0,
    )
    frame_ms = 1000 / 60
    # A small step first, then the line: the stroke's first vertex lies near the press.
    out = [Sample(k * frame_ms, 0.9375 * k, 0.0, 0.5) for k in range(3)] + [
        Sample(k * frame_ms, 1.875 + 7.2824 * (k - 2), 14.4444 * (k - 2), 0.5) for k in range(3, 30)
    ]
    stop_from, stop_to = out[-1].t_ms, out[-1].t_ms + 384.0
    last = out[-1]
    stop = [Sample(last.t_ms + 32.0 * k, last.x, last.y, 0.5) for k in range(1, 13)]
    back = [
        Sample(stop_to + k * frame_ms, last.x - 7.3 * k, last.y - 14.4 * k, 0.5)
        for k in range(1, 27)
    ]
    simplifier = WindowSimplifier(params)
    segments = [
        s for sample in out + stop + back for s in simplifier.push(sample)
    ] + simplifier.end()
    sent = [s for s in segments if s.dropped is None]
    assert sent
    for stroke in sent:
        # Nothing of the stop is played but the time a piece briefer than the floor borrows
        # from it (the pen was at its end then): the rest starts at the stop's first sample,
        # the strokes after it at its last.
        played_of_stop = min(stroke.end_ms, stop_to) - max(stroke.start_ms, stop_from)
        lent_ms = max(params.floor_ms, params.min_duration_ms) - (stop_from - stroke.start_ms)
        assert played_of_stop <= max(lent_ms, 0.0) + 1e-6, (stroke, stop_from, stop_to)


@pytest.mark.parametrize("start_ms", [100.3, 2000.7, 15000.1, 612345.6])
def test_a_piece_lent_the_floor_by_a_rest_lasts_the_floor_to_the_last_bit(start_ms: float) -> None:
    """A rest lends a held piece briefer than the sleeve's floor the time it needs: it lasts the
    floor, never a rounding below it (``start + floor - start`` can be 73.70099999999911 ms, which
    the sleeve slows to 73.701 and reports ``adjusted``)."""
    from feelmysign.apparent_motion import shortest_planned_ms
    from feelmysign.layout import PAPER_SLEEVE
    from feelmysign.planner import plan
    from feelmysign.simplify.segment import Segment
    from feelmysign.simplify.window import Merger, floor_end_ms
    from feelmysign.stroke import Stroke

    floor_ms = shortest_planned_ms(PAPER_SLEEVE.shortest_burst_ms)
    merger = Merger(max_error=0.25, min_length=0.05, min_duration_ms=0.0, floor_ms=floor_ms)
    merger.sample(start_ms, (0.0, 0.0))
    merger.sample(start_ms + 30.0, (1.0, 0.0))
    piece = Segment((0.0, 0.0), (1.0, 0.0), start_ms, start_ms + 30.0, start_ms + 30.0)
    assert merger.take(piece, start_ms + 30.0) == []  # briefer than the floor: held
    (sent,) = merger.rest(start_ms + 300.0)
    assert sent.duration_ms >= floor_ms
    assert sent.end_ms == floor_end_ms(start_ms, floor_ms)
    assert sent.end_ms <= math.nextafter(start_ms + floor_ms, math.inf)  # the least such end
    # The sleeve plays it as sent: not slowed, not reported adjusted.
    stroke = Stroke(start=sent.start, end=sent.end, duration_ms=sent.duration_ms)
    assert plan(stroke, PAPER_SLEEVE).adjusted is None
