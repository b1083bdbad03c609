"""The measurements behind the defaults: playback as the sleeve plays, $1, re-timing, DP ties."""

from __future__ import annotations

import itertools
import json
import math
import random
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from feelmysign.cli import main
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.research import dollar, metrics
from feelmysign.research.evaluate import Row, Run, Source, evaluate_one, grid_points
from feelmysign.research.lasa import load_lasa
from feelmysign.research.playback import simulate
from feelmysign.research.speeds import retimed
from feelmysign.simplify import ALGORITHMS, PathSegment, Sample, Segment, WindowParams
from feelmysign.simplify.recording import Recording
from feelmysign.simplify.registry import params_for


def _stroke(start: tuple[float, float], end: tuple[float, float], t0: float, t1: float) -> Segment:
    return Segment(start, end, t0, t1, t1)


def test_strokes_play_back_to_back_and_the_felt_end_follows_the_last() -> None:
    # Three strokes of 1 grid unit, each drawn in 400 ms, let go when drawn.
    segments = [
        PathSegment(0, _stroke((0.0, 0.0), (1.0, 0.0), 0.0, 400.0)),
        PathSegment(0, _stroke((1.0, 0.0), (2.0, 0.0), 400.0, 800.0)),
        PathSegment(0, _stroke((2.0, 0.0), (3.0, 0.0), 800.0, 1200.0)),
    ]
    path = [Sample(0.0, 0, 0), Sample(1200.0, 0, 0)]
    played = simulate(segments, [path], PAPER_SLEEVE)
    assert played.drawing_ms == 1200.0
    assert played.skin_ms == pytest.approx(1200.0)  # kept in time: no stroke slowed
    assert played.slowed == 0
    # Each starts when let go (its end), so pen to skin is one stroke's duration.
    assert played.pen_to_skin_ms == pytest.approx((400.0, 400.0, 400.0))
    (release,) = played.release_to_felt_end_ms
    assert 400.0 <= release <= 400.0 + 60.0  # the last stroke, and its last burst's tail
    # Their schedules, in the order they play: what the felt path is read from.
    assert [s.stroke.start for s in played.schedules] == [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]


def test_a_slowed_stroke_delays_the_ones_after_it() -> None:
    # A 5 ms stroke cannot be felt as drawn: the planner slows it, the next one waits.
    segments = [
        PathSegment(0, _stroke((0.0, 0.0), (1.0, 0.0), 0.0, 5.0)),
        PathSegment(0, _stroke((1.0, 0.0), (1.0, 1.0), 5.0, 10.0)),
    ]
    played = simulate(segments, [[Sample(0.0, 0, 0), Sample(10.0, 0, 0)]], PAPER_SLEEVE)
    assert played.skin_ratio > 2
    assert played.pen_to_skin_ms[1] > played.pen_to_skin_ms[0]
    assert played.slowed == 2  # both, counted for evaluate's slowed_total


def test_a_stroke_behind_its_drawing_plays_faster_and_the_felt_end_catches_up() -> None:
    # The first stroke is let go 100 ms after it was drawn and plays until 900; the second,
    # let go at 820, is 80 ms behind: it plays in 320 ms instead of 400.
    segments = [
        PathSegment(0, Segment((0.0, 0.0), (1.0, 0.0), 0.0, 400.0, 500.0)),
        PathSegment(0, Segment((1.0, 0.0), (2.0, 0.0), 400.0, 800.0, 820.0)),
    ]
    path = [Sample(0.0, 0, 0), Sample(800.0, 0, 0)]
    played = simulate(segments, [path], PAPER_SLEEVE)
    assert played.compressed == 1
    assert played.compressed_ms == pytest.approx(80.0)
    assert (played.skipped, played.skipped_ms) == (0, 0.0)
    assert played.skin_ms == pytest.approx(720.0)
    assert [s.duration_ms for s in played.schedules] == pytest.approx([400.0, 320.0])
    assert played.pen_to_skin_ms == pytest.approx((500.0, 500.0))  # 900 - 400
    (release,) = played.release_to_felt_end_ms
    assert 1220.0 - 800.0 <= release <= 1220.0 - 800.0 + 60.0


def test_strokes_let_go_at_once_catch_up_to_the_floor_and_none_is_skipped() -> None:
    # Forty 300 ms strokes let go at once: all but the first play at the floor, ahead of the
    # sender's time line (back to back at 300 ms), so the pace rule skips none.
    segments = [
        PathSegment(0, Segment((0.0, 0.0), (1.0, 0.0), 0.0, 300.0, 300.0)) for _ in range(40)
    ]
    played = simulate(segments, [[Sample(0.0, 0, 0), Sample(300.0, 0, 0)]], PAPER_SLEEVE)
    assert played.compressed == 39 and played.skipped == 0
    assert [s.duration_ms for s in played.schedules[1:]] == [73.701] * 39
    assert played.compressed_ms == pytest.approx(39 * (300.0 - 73.701))


def test_dollar_recognises_a_rotated_scaled_copy_and_tells_shapes_apart() -> None:
    t = np.linspace(0, 2 * math.pi, 80)
    circle = np.stack([np.cos(t), np.sin(t)], axis=1)
    zigzag = np.array([[0, 0], [1, 1], [2, 0], [3, 1], [4, 0]], dtype=float)
    check = np.array([[0, 1], [1, 0], [3, 3]], dtype=float)
    templates = dollar.Templates.of([("circle", circle), ("zigzag", zigzag), ("check", check)])
    angle = math.radians(30)
    turn = np.array([[math.cos(angle), math.sin(angle)], [-math.sin(angle), math.cos(angle)]])
    assert dollar.recognise(3 * zigzag @ turn + 7, templates)[0] == "zigzag"
    assert dollar.recognise(0.5 * check @ turn, templates)[0] == "check"
    name, score = dollar.recognise(circle * 2 + 1, templates)
    assert name == "circle" and score > 0.99


def test_dollar_search_finds_the_best_angle() -> None:
    zigzag = np.array([[0, 0], [1, 1], [2, 0], [3, 1], [4, 0]], dtype=float)
    templates = dollar.Templates.of([("zigzag", zigzag)])
    # Its own copy is at distance ~0; the golden-section search stops within 2 degrees.
    assert dollar.distances(zigzag, templates)[0] < 1.0


def test_retimed_recordings_last_the_set_time_at_125_hz() -> None:
    samples = tuple(Sample(k * 1.0, k * 2.0, 0.0) for k in range(1001))
    recording = retimed(Recording(800.0, 600.0, (samples,)), 600.0)
    (path,) = recording.paths
    times = [s.t_ms for s in path]
    assert times[0] == 0.0 and times[-1] == 600.0
    assert np.allclose(np.diff(times)[:-1], 8.0)
    assert path[-1].x == pytest.approx(2000.0)  # the whole shape, not a part of it


def test_douglas_peucker_runs_above_a_tie_with_the_rows_deviation() -> None:
    # Noisy lines with one bump, all within the error of one stroke first to last: DP,
    # whose first test is that very chord, must need one stroke too. At exactly the
    # row's deviation the bump's own point ties (the distance computed another way)
    # and DP would keep it: the evaluation compared against a stroke too many.
    rng = random.Random(1)
    ties = 0
    for _ in range(40):
        bump_x, bump_y = rng.uniform(150, 450), 300 - rng.uniform(5, 40)
        line = [
            Sample(10.0 * k, 100.0 + 10.0 * k + rng.uniform(-3, 3), 300.0 + rng.uniform(-3, 3))
            for k in range(41)
        ]
        at = int((bump_x - 100) / 10)
        samples = (*line[: at + 1], Sample(line[at].t_ms + 1, bump_x, bump_y), *line[at + 1 :])
        recording = Recording(1200.0, 800.0, (samples,), 3, 4)
        run = Run(
            ALGORITHMS["window"],
            {
                "least_squares": False,
                "max_error": 0.6,
                "min_duration_ms": 0.0,
                "max_stroke_ms": 0.0,
                "max_bend": 0.0,
            },
        )
        row = evaluate_one(Source("bump", "bump", recording), run)
        assert row.strokes == 1 and row.dp_strokes == 1
        points = grid_points(params_for(run.algorithm, recording, run.overrides), samples)
        ties += metrics.douglas_peucker_strokes(points, row.max_deviation) > 1
    assert ties > 0, "the cases include ties (else this test could not fail)"


def test_rows_without_shape_metrics_keep_every_timing_figure() -> None:
    """The bench leaves out the shape metrics (the Frechet distance is slow): the rest of a row,
    and so every timing and recognition figure, is the same as with them."""
    rng = np.random.default_rng(7)
    samples = tuple(
        Sample(12.0 * k, 100.0 + 9.0 * k, 300.0 + 80.0 * math.sin(k / 6) + rng.uniform(-2, 2))
        for k in range(90)
    )
    recording = Recording(1200.0, 800.0, (samples,), 3, 4)
    source = Source("wave", "wave", recording)
    for name in ALGORITHMS:
        full = evaluate_one(source, Run(ALGORITHMS[name], {}))
        lean = evaluate_one(source, Run(ALGORITHMS[name], {}), shape_metrics=False)
        assert full.strokes > 1 and full.frechet > 0 and full.dp_strokes > 0
        assert math.isnan(lean.frechet) and math.isnan(lean.max_deviation)

        def without_shape(row: Row) -> Row:
            return replace(row, max_deviation=0.0, frechet=0.0, dp_strokes=0)

        assert without_shape(lean) == without_shape(full)


def test_simplify_json_gives_each_stroke_its_drawn_times(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    line = [{"t_ms": 10.0 * k, "x": 100 + 8.0 * k, "y": 300 + 60.0 * (k > 30)} for k in range(60)]
    path = tmp_path / "line.json"
    path.write_text(json.dumps({"canvas": {"width_px": 800, "height_px": 600}, "paths": [line]}))
    assert main(["simplify", str(path), "--algorithm", "window", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    strokes = document["strokes"]
    every = sorted(strokes + document["dropped"], key=lambda s: s["start_ms"])
    assert strokes and every[0]["start_ms"] == 0.0 and every[-1]["end_ms"] == 590.0
    for before, after in itertools.pairwise(every):
        assert after["start_ms"] == before["end_ms"]
    # Played as drawn, but a stroke drawn briefer than the sleeve's floor (here the jump, which
    # no longer stroke keeps within max_error), which is sent to last the floor.
    floor_ms = WindowParams().floor_ms
    for stroke in every:
        drawn = stroke["end_ms"] - stroke["start_ms"]
        assert stroke["duration_ms"] == pytest.approx(drawn if drawn >= floor_ms else floor_ms)


def test_lasa_drawings_are_recognised_leaving_their_own_out() -> None:
    demos = load_lasa()[:21]  # three shapes
    templates = dollar.Templates.of(
        [(d.shape, np.array([(s.x, s.y) for s in d.recording.paths[0]])) for d in demos]
    )
    right = 0
    for index, demo in enumerate(demos):
        points = np.array([(s.x, s.y) for s in demo.recording.paths[0]])
        right += dollar.recognise(points, templates.without(index))[0] == demo.shape
    assert right >= 19
