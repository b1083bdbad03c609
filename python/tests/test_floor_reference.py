"""The best polyline at the sleeve's floor (research.floor_reference): every piece lasts at
least the floor, it is the least-squares one among all such polylines through drawn samples
(against a brute force over every split), and ``evaluate --best-at-floor`` reports it."""

from __future__ import annotations

import csv
import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_cli_evaluate import evaluate_json, gesture_folder

from feelmysign.cli import main
from feelmysign.research import metrics
from feelmysign.research.floor_reference import (
    best_at_floor,
    online_at_floor,
    piece_errors,
    reference,
)


def line_error(points: np.ndarray, i: int, j: int) -> float:
    """Sample by sample: squared distances of points[i..j] to the line points[i] -> points[j]."""
    a, b = points[i], points[j]
    d = b - a
    length_sq = float(d @ d)
    total = 0.0
    for k in range(i, j + 1):
        q = points[k] - a
        total += (d[0] * q[1] - d[1] * q[0]) ** 2 / length_sq if length_sq > 0 else float(q @ q)
    return total


def brute_force(points: np.ndarray, times: np.ndarray, floor_ms: float) -> float:
    """The least total error over every split whose pieces all last at least the floor."""
    n = len(points)
    best = math.inf
    for inner in range(n - 1):
        for chosen in itertools.combinations(range(1, n - 1), inner):
            vertices = [0, *chosen, n - 1]
            if any(times[b] - times[a] < floor_ms for a, b in itertools.pairwise(vertices)):
                continue
            best = min(best, sum(line_error(points, a, b) for a, b in itertools.pairwise(vertices)))
    return best


coordinate = st.floats(0, 3, allow_nan=False)
paths = st.lists(st.tuples(coordinate, coordinate, st.floats(0, 60)), min_size=2, max_size=8)


@settings(max_examples=200, deadline=None)
@given(paths, st.sampled_from([0.0, 20.0, 73.701, 120.0]))
def test_every_piece_lasts_the_floor_and_no_split_is_nearer(
    drawn: list[tuple[float, float, float]], floor_ms: float
) -> None:
    points = np.array([(x, y) for x, y, _ in drawn])
    times = np.cumsum([step for _, _, step in drawn])
    kept = best_at_floor(points, times, floor_ms)
    assert kept[0] == 0 and kept[-1] == len(points) - 1
    assert np.all(np.diff(kept) > 0)
    if times[-1] - times[0] < floor_ms:
        assert list(kept) == [0, len(points) - 1]
        return
    assert all(times[b] - times[a] >= floor_ms for a, b in itertools.pairwise(kept))
    total = sum(line_error(points, a, b) for a, b in itertools.pairwise(kept))
    assert total == pytest.approx(brute_force(points, times, floor_ms), rel=1e-6, abs=1e-9)


def test_piece_errors_from_sums_match_the_samples() -> None:
    rng = np.random.default_rng(7)
    points = rng.uniform(0, 3, size=(30, 2))
    points[20] = points[5]  # a closed loop: the piece 5 -> 20 has no length
    starts = np.arange(25, dtype=np.int64)
    fast = piece_errors(points, starts, 25)
    slow = [line_error(points, i, 25) for i in range(25)]
    assert fast == pytest.approx(slow, rel=1e-9, abs=1e-9)
    assert piece_errors(points, np.array([5]), 20)[0] == pytest.approx(line_error(points, 5, 20))


def test_a_square_drawn_slowly_keeps_its_corners() -> None:
    # Four sides of 20 samples, 10 ms apart, a little noise: the floor leaves time for every
    # corner, and the nearest polyline turns at them.
    corners = [(0.5, 0.5), (2.5, 0.5), (2.5, 1.5), (0.5, 1.5), (0.5, 0.5)]
    rng = np.random.default_rng(3)
    points = [
        np.array(a) + (np.array(b) - np.array(a)) * k / 20 + rng.normal(0, 0.005, 2)
        for a, b in itertools.pairwise(corners)
        for k in range(20)
    ]
    points.append(np.array(corners[-1]))
    path = np.array(points)
    kept = best_at_floor(path, np.arange(len(path)) * 10.0, 73.701)
    # The cheapest is a vertex at each corner (samples 20, 40, 60), plus vertices along the
    # sides where they lower the noise's error: each corner is among them.
    for corner in (20, 40, 60):
        assert corner in kept


def test_a_fast_circle_gets_at_most_what_the_floor_allows() -> None:
    # A circle drawn in 450 ms, a sample every 10 ms: a piece spans at least 8 steps (80 ms) to
    # last the floor, so 5 strokes at most, and the polyline nearest a circle takes them all.
    k = np.arange(46)
    path = np.stack([1.5 + np.cos(2 * np.pi * k / 45), 1 + np.sin(2 * np.pi * k / 45)], axis=1)
    found = reference([path], [k * 10.0], 73.701)
    assert found.strokes == 5
    assert found.polyline[0] == pytest.approx(path[0]) and found.polyline[-1] == pytest.approx(
        path[-1]
    )


def test_evaluate_reports_the_best_at_the_floor_beside_the_drawings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = gesture_folder(tmp_path / "gestures")
    argv = [str(root), "--defaults", "--algorithm", "window", "--out", str(tmp_path / "o")]
    document = evaluate_json(capsys, *argv, "--best-at-floor")
    at_floor = {s["set"]: s for s in document["best_at_floor"]}
    assert set(at_floor) == {"fast", "slow"}
    # 40 steps of 8 ms (fast) or 24 ms (slow): at most 320 / 73.7 or 960 / 73.7 strokes.
    assert 1 <= at_floor["fast"]["strokes_mean"] <= 4
    assert at_floor["fast"]["strokes_mean"] < at_floor["slow"]["strokes_mean"] <= 13
    for entry in at_floor.values():
        assert entry["floor_ms"] == pytest.approx(73.701)
        assert entry["recognised_drawn_pct"] == 100.0
        assert entry["recognised_pct"] is not None
        assert entry["recognised_felt_pct"] is not None
    # A floor given: finer strokes for the slow gestures.
    document = evaluate_json(capsys, *argv, "--best-at-floor", "30")
    finer = {s["set"]: s for s in document["best_at_floor"]}
    assert finer["slow"]["strokes_mean"] > at_floor["slow"]["strokes_mean"]
    # Bounded, offline and online: every stroke keeps its samples within the bound.
    document = evaluate_json(
        capsys, *argv, "--best-at-floor", "--lookahead-ms", "30", "--bound", "0.05"
    )
    assert {(s["lookahead_ms"], s["max_error"]) for s in document["best_at_floor"]} == {
        (None, 0.05),
        (30.0, 0.05),
    }
    assert all(s["max_deviation_max"] <= 0.05 + 1e-9 for s in document["best_at_floor"])
    # Each drawing's own figures, per reference: which ones it loses.
    with (tmp_path / "o" / "best_at_floor.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 2 * document["recordings"]
    assert {r["lookahead_ms"] for r in rows} == {"", "30.0"}
    assert all(float(r["max_deviation"]) <= 0.05 + 1e-9 for r in rows)
    assert all(int(r["brief_strokes"]) <= int(r["strokes"]) for r in rows)
    assert {r["recognised_drawn"] for r in rows} == {"1"}
    assert main(["evaluate", *argv, "--best-at-floor", "--lookahead-ms", "30"]) == 0
    out = capsys.readouterr().out
    assert "Best at a floor of 73.701 ms" in out and "offline" in out and "online, 30 ms" in out


def test_bound_needs_the_best_at_floor(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["evaluate", "--lasa", "--bound", "0.25"])
    assert exit_info.value.code == 2
    assert "give it with --best-at-floor" in capsys.readouterr().err


def test_lookahead_needs_the_best_at_floor(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["evaluate", "--lasa", "--lookahead-ms", "30"])
    assert exit_info.value.code == 2
    assert "give it with --best-at-floor" in capsys.readouterr().err


def test_a_floor_out_of_range_names_the_range(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["evaluate", "--lasa", "--best-at-floor", "-5"])
    assert exit_info.value.code == 2
    assert "-5 is out of range; give a number from 0 to 10000 ms" in capsys.readouterr().err


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.tuples(coordinate, coordinate, st.floats(0, 40)), min_size=2, max_size=40),
    st.sampled_from([0.0, 30.0, 100.0]),
    st.sampled_from([150.0, 200.0, math.inf]),
)
def test_online_pieces_join_last_the_floor_and_wait_for_the_lookahead(
    drawn: list[tuple[float, float, float]], lookahead_ms: float, cap_ms: float
) -> None:
    floor_ms = 73.701
    points = np.array([(x, y) for x, y, _ in drawn])
    times = np.cumsum([step for _, _, step in drawn])
    pieces = online_at_floor(points, times, floor_ms, lookahead_ms, cap_ms)
    assert pieces[0][0] == 0 and pieces[-1][1] == len(points) - 1
    assert all(a < b for a, b, _ in pieces)
    assert all(p[1] == q[0] for p, q in itertools.pairwise(pieces))
    release_ms = times[-1]
    for a, b, let_go_ms in pieces:
        assert times[b] <= let_go_ms <= release_ms
        if let_go_ms < release_ms:  # let go while the pen still draws
            assert times[b] - times[a] >= floor_ms
            waited = let_go_ms - times[b] >= lookahead_ms
            capped = let_go_ms - times[a] > cap_ms
            assert waited or capped
    # At release the rest is let go: pieces lasting the floor, the last one briefer only when
    # what was left after the last piece let go was.
    assert all(times[b] - times[a] >= floor_ms for a, b, _ in pieces[:-1])


@settings(max_examples=100, deadline=None)
@given(paths, st.sampled_from([20.0, 73.701]))
def test_online_with_a_lookahead_past_the_path_is_the_offline_polyline(
    drawn: list[tuple[float, float, float]], floor_ms: float
) -> None:
    points = np.array([(x, y) for x, y, _ in drawn])
    times = np.cumsum([step for _, _, step in drawn])
    online = online_at_floor(points, times, floor_ms, lookahead_ms=1e9, cap_ms=math.inf)
    kept = best_at_floor(points, times, floor_ms)
    assert [a for a, _, _ in online] + [online[-1][1]] == list(kept)
    assert {let_go for _, _, let_go in online} == {times[-1]}


def farthest(points: np.ndarray, a: int, b: int) -> float:
    """The farthest of points[a..b] from the segment points[a] -> points[b]."""
    return float(np.max(metrics.segment_distances(points[a : b + 1], points[a], points[b])))


@settings(max_examples=150, deadline=None)
@given(paths, st.sampled_from([20.0, 73.701]), st.sampled_from([0.1, 0.5]))
def test_bounded_pieces_keep_the_bound_with_the_fewest_brief_ones(
    drawn: list[tuple[float, float, float]], floor_ms: float, max_error: float
) -> None:
    points = np.array([(x, y) for x, y, _ in drawn])
    times = np.cumsum([step for _, _, step in drawn])
    kept = list(best_at_floor(points, times, floor_ms, max_error))
    assert kept[0] == 0 and kept[-1] == len(points) - 1
    assert all(farthest(points, a, b) <= max_error + 2e-9 for a, b in itertools.pairwise(kept))

    def rank(vertices: list[int]) -> tuple[int, float]:
        pairs = list(itertools.pairwise(vertices))
        brief = sum(times[b] - times[a] < floor_ms for a, b in pairs)
        return brief, sum(line_error(points, a, b) for a, b in pairs)

    n = len(points)
    splits = [
        [0, *inner, n - 1]
        for count in range(n - 1)
        for inner in itertools.combinations(range(1, n - 1), count)
    ]
    valid = [
        v
        for v in splits
        if all(farthest(points, a, b) <= max_error + 1e-9 for a, b in itertools.pairwise(v))
    ]
    best_brief, best_error = min(rank(v) for v in valid)
    brief, error = rank(kept)
    assert brief == best_brief
    assert error == pytest.approx(best_error, rel=1e-6, abs=1e-9)


@settings(max_examples=100, deadline=None)
@given(
    st.lists(st.tuples(coordinate, coordinate, st.floats(0, 40)), min_size=2, max_size=30),
    st.sampled_from([0.0, 30.0]),
)
def test_online_bounded_pieces_keep_the_bound(
    drawn: list[tuple[float, float, float]], lookahead_ms: float
) -> None:
    points = np.array([(x, y) for x, y, _ in drawn])
    times = np.cumsum([step for _, _, step in drawn])
    pieces = online_at_floor(points, times, 73.701, lookahead_ms, 200.0, max_error=0.25)
    assert pieces[0][0] == 0 and pieces[-1][1] == len(points) - 1
    assert all(p[1] == q[0] for p, q in itertools.pairwise(pieces))
    assert all(farthest(points, a, b) <= 0.25 + 2e-9 for a, b, _ in pieces)
