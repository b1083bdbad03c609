"""The least-squares core (``least_squares``, ``simplify/fit.py``) against the research
reference it is built from, and its own rules."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from simplifier_checks import random_walk

from feelmysign.research.floor_reference import online_at_floor
from feelmysign.simplify import Sample, WindowParams, WindowSimplifier
from feelmysign.simplify.distance import segment_distance_sq
from feelmysign.simplify.fit import FitCore, piece_error
from feelmysign.simplify.segment import Segment


@st.composite
def fitted(draw: st.DrawFn) -> tuple[WindowParams, list[Sample]]:
    params = WindowParams(
        least_squares=True,
        max_error=draw(st.sampled_from([0.05, 0.1, 0.15, 0.25, 1.0])),
        max_stroke_ms=draw(st.sampled_from([0.0, 100.0, 200.0])),
        lookahead_ms=draw(st.sampled_from([0.0, 30.0, 100.0])),
        floor_ms=draw(st.sampled_from([20.0, 73.701, 150.0])),
        min_duration_ms=0.0,
        rest_ms=0.0,
        canvas_width_px=800,
        canvas_height_px=600,
    )
    # Inside the canvas (no sample clamped onto an edge), and no two samples at one place: where
    # pieces tie exactly, the two ways of summing break the tie apart.
    walk = random_walk(draw, margin_px=-20, min_step_ms=1.0)
    return params, [
        Sample(s.t_ms, s.x + 3 * math.sin(1.7 * k), s.y + 3 * math.cos(2.3 * k))
        for k, s in enumerate(walk)
    ]


@settings(max_examples=200, deadline=None)
@given(fitted())
def test_the_strokes_are_the_research_references_online_polyline(
    case: tuple[WindowParams, list[Sample]],
) -> None:
    # floor_reference.online_at_floor solves the whole problem again at every sample with numpy;
    # the core solves it one sample at a time. Same pieces, let go by the same samples. (Without
    # the latency cap: the core's pieces keep it, the reference's only let go by it.)
    params, samples = case
    params = WindowParams(**{**params.__dict__, "max_stroke_ms": 0.0})
    core = FitCore(params)
    pieces = [piece for sample in samples for piece in core.push(sample)] + core.end()
    mapping = params.mapping
    points = np.array([mapping.to_grid(s.x, s.y) for s in samples])
    times = [s.t_ms for s in samples]
    cap = params.max_stroke_ms if params.max_stroke_ms > 0 else math.inf
    expected = online_at_floor(
        points, times, params.floor_ms, params.lookahead_ms, cap, params.max_error
    )
    if len(samples) == 1:
        assert len(pieces) == 1 and pieces[0].start == pieces[0].end
        return
    assert [(p.start, p.end, p.start_ms, p.end_ms, p.emitted_at_ms) for p in pieces] == [
        (tuple(points[a]), tuple(points[b]), times[a], times[b], at) for a, b, at in expected
    ]


@settings(max_examples=200, deadline=None)
@given(fitted(), st.sampled_from([0.0, 100.0]))
def test_every_sample_lies_within_max_error_of_the_stroke_drawn_through_it(
    case: tuple[WindowParams, list[Sample]], rest_ms: float
) -> None:
    params, samples = case
    params = WindowParams(**{**params.__dict__, "rest_ms": rest_ms})
    simplifier = WindowSimplifier(params)
    strokes = [s for sample in samples for s in simplifier.push(sample)] + simplifier.end()
    mapping = params.mapping
    limit_sq = params.max_error * params.max_error
    for sample in samples:
        x, y = mapping.to_grid(sample.x, sample.y)
        nearest = min(
            segment_distance_sq(x, y, s.start[0], s.start[1], s.end[0], s.end[1]) for s in strokes
        )
        assert nearest <= limit_sq, (sample, math.sqrt(nearest))
    # Joined end to start, each briefer than the floor sent to last it, none dropped but a tap.
    for before, after in itertools.pairwise(strokes):
        assert before.end == after.start
        assert before.end_ms <= after.start_ms
    for stroke in strokes:
        if stroke.dropped is None and stroke.end_ms - stroke.start_ms < params.floor_ms:
            assert stroke.duration_ms >= params.floor_ms, stroke
    # None outlasts the latency cap, but one from a sample to the next drawn further apart.
    cap = params.max_stroke_ms
    for stroke in strokes:
        between = [s for s in samples if stroke.start_ms < s.t_ms < stroke.end_ms]
        assert cap == 0 or stroke.end_ms - stroke.start_ms <= cap or not between, stroke
    assert all(s.dropped is None for s in strokes) or len(strokes) == 1


def _circle(radius_px: float, step_ms: float, turns: float = 1.0) -> list[Sample]:
    count = int(turns * 120)
    return [
        Sample(
            k * step_ms,
            400 + radius_px * math.cos(2 * math.pi * turns * k / count),
            300 + radius_px * math.sin(2 * math.pi * turns * k / count),
        )
        for k in range(count + 1)
    ]


def test_a_circle_keeps_its_round_shape_with_strokes_at_the_floor() -> None:
    # Drawn in 1.2 s, a circle of radius 2 grid units: the chord's farthest sample cuts it where
    # the bound breaks, into few strokes; the least squares into as many as the floor allows.
    circle = _circle(radius_px=128, step_ms=10.0)
    chord = WindowSimplifier(
        WindowParams(least_squares=False, canvas_width_px=800, canvas_height_px=600)
    )
    fit = WindowSimplifier(
        WindowParams(least_squares=True, canvas_width_px=800, canvas_height_px=600)
    )
    strokes = {}
    for name, simplifier in (("chord", chord), ("fit", fit)):
        out = [s for sample in circle for s in simplifier.push(sample)] + simplifier.end()
        strokes[name] = out
    floor = WindowParams().floor_ms
    assert all(s.end_ms - s.start_ms >= floor for s in strokes["fit"])
    assert len(strokes["fit"]) > len(strokes["chord"])
    # No stroke waits longer than the lookahead past the one after it starts (but at release).
    lookahead = WindowParams().lookahead_ms
    for stroke in strokes["fit"][:-3]:
        assert stroke.emitted_at_ms - stroke.end_ms <= lookahead + floor + 10.0, stroke


def test_a_resting_pen_ends_the_polyline_and_the_rest_is_not_played() -> None:
    line = [Sample(k * 10.0, 100 + 8.0 * k, 300) for k in range(40)]
    rest = [Sample(400 + k * 10.0, line[-1].x, 300) for k in range(1, 31)]
    on = [Sample(700 + k * 10.0, line[-1].x, 300 + 8.0 * k) for k in range(1, 40)]
    simplifier = WindowSimplifier(
        WindowParams(least_squares=True, canvas_width_px=800, canvas_height_px=600)
    )
    sent_by = {}
    for sample in line + rest + on:
        for stroke in simplifier.push(sample):
            sent_by[stroke] = sample.t_ms
    strokes = list(sent_by) + simplifier.end()
    # The line's strokes are all out once the pen has rested rest_ms, before it moves on.
    line_strokes = [s for s in strokes if s.end_ms <= line[-1].t_ms]
    assert line_strokes and max(sent_by[s] for s in line_strokes) < 700
    # No stroke plays the rest: the one after it starts when the pen moves on.
    after = [s for s in strokes if s.start_ms > line[-1].t_ms]
    assert after and min(s.start_ms for s in after) >= 690.0


@pytest.mark.parametrize("rest_ms", [100.0, 150.0, 300.0, 600.0])
@pytest.mark.parametrize("lookahead_ms", [0.0, 30.0, 120.0])
def test_a_stop_longer_than_a_stroke_at_the_floor_is_not_played(
    rest_ms: float, lookahead_ms: float
) -> None:
    # A pen held still for a second, a sample every 16 ms (the page samples a still pointer): no
    # stroke of the stop is sent, whatever rest_ms (longer than a stroke at the floor and its
    # lookahead, too) and however long the lookahead; the line before it and after it are felt.
    down = [Sample(k * 16.0, 150, 60 + 6.0 * k) for k in range(40)]
    still = [Sample(640 + k * 16.0, 150, 300) for k in range(62)]
    on = [Sample(1632 + k * 16.0, 150, 300 + 8.0 * k) for k in range(1, 30)]
    simplifier = WindowSimplifier(
        WindowParams(
            canvas_width_px=900, canvas_height_px=600, rest_ms=rest_ms, lookahead_ms=lookahead_ms
        )
    )
    strokes = [s for sample in down + still + on for s in simplifier.push(sample)]
    strokes += simplifier.end()
    sent = [s for s in strokes if s.dropped is None]
    stop_start, stop_end = still[0].t_ms, still[-1].t_ms
    assert [s for s in sent if s.start_ms >= stop_start and s.end_ms <= stop_end] == []
    assert [s for s in sent if s.start == s.end] == []
    assert any(s.end_ms <= stop_start + 16 for s in sent) and any(
        s.start_ms >= stop_end for s in sent
    )


@settings(max_examples=200, deadline=None)
@given(fitted())
def test_each_piece_s_error_is_its_samples_squared_distances_to_its_line(
    case: tuple[WindowParams, list[Sample]],
) -> None:
    # The core's errors (written out in its loop) are piece_error's to the bit, and piece_error
    # is the sum of each sample's squared distance to the piece's line, to rounding.
    params, samples = case
    params = WindowParams(**{**params.__dict__, "max_stroke_ms": 0.0, "lookahead_ms": 1000.0})
    core = FitCore(params)
    for sample in samples[:40]:
        core.push(sample)
    xs, ys, sums = core._xs, core._ys, core._sums
    k = len(xs) - 1
    if k < 1:
        return
    low, _ = core._scan(k)
    for i in range(low, k):
        error = piece_error(xs, ys, xs[0], ys[0], sums, i, k)
        if core._errors[i - low] < 0:
            # Left out: a start with more pieces briefer than the floor than the first choice.
            assert core._brief[i] > core._brief[core._open_first]
            continue
        assert core._errors[i - low] == error
        ax, ay, dx, dy = xs[i], ys[i], xs[k] - xs[i], ys[k] - ys[i]
        length = math.hypot(dx, dy)
        direct = sum(
            ((xs[m] - ax) * dy - (ys[m] - ay) * dx) ** 2 / length**2
            if length > 0
            else (xs[m] - ax) ** 2 + (ys[m] - ay) ** 2
            for m in range(i, k + 1)
        )
        assert error == pytest.approx(direct, rel=1e-6, abs=1e-9)


def test_a_sample_costs_at_most_a_few_bound_tests_per_sample_held() -> None:
    # The widest settings the page offers (window 10000, no latency cap, lookahead 1000 ms, floor
    # 10000 ms) and a slow arc at 1000 Hz: every piece is briefer than the floor, and at sample
    # 1793 the fewest-pieces starts break the bound one after another (about 1000 of them). Each
    # rejected start once cost a pass over every start and a test of every sample of its piece
    # from the first (205698 distance tests and 4.6 s in one push); the starts are now taken
    # from a heap in the same order and a piece's samples tested coarse to fine.
    params = WindowParams(
        least_squares=True,
        max_window=10000,
        max_stroke_ms=0.0,
        lookahead_ms=1000.0,
        floor_ms=10000.0,
        rest_ms=0.0,
        canvas_width_px=800,
        canvas_height_px=600,
    )
    core = FitCore(params)
    worst = 0
    pieces: list[Segment] = []
    for k in range(1800):
        before = core.distance_tests
        pieces += core.push(
            Sample(float(k), 400 + 200 * math.cos(k * 0.002), 300 + 200 * math.sin(k * 0.002))
        )
        worst = max(worst, core.distance_tests - before)
    pieces += core.end()
    assert worst <= 2 * 1800
    assert len(pieces) >= 2 and all(a.end == b.start for a, b in itertools.pairwise(pieces))
