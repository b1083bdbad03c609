"""Metrics on cases checkable by hand, and their invariants on random polylines."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from feelmysign.research import metrics
from feelmysign.simplify.segment import Segment

coordinate = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
polyline = st.lists(st.tuples(coordinate, coordinate), min_size=1, max_size=12).map(
    metrics.as_points
)


def seg(start: tuple[float, float], end: tuple[float, float], t0: float, t1: float) -> Segment:
    return Segment(start, end, t0, t1, emitted_at_ms=t1 + 16.0)


def test_segment_distance_is_to_the_segment_not_its_line() -> None:
    points = metrics.as_points([(1, 1), (3, 0), (-4, 0), (0, 0)])
    distances = metrics.segment_distances(points, (0, 0), (2, 0))
    assert distances.tolist() == pytest.approx([1.0, 1.0, 4.0, 0.0])


def test_deviation_uses_the_segment_covering_each_frame() -> None:
    # An L: (0,0) -> (2,0) over 0..100 ms, then (2,0) -> (2,2) over 100..200 ms.
    segments = [seg((0, 0), (2, 0), 0, 100), seg((2, 0), (2, 2), 100, 200)]
    points = metrics.as_points([(0, 0), (1, 0.5), (2, 0), (2.25, 1), (2, 2)])
    times = [0, 50, 100, 150, 200]
    assert metrics.deviations(times, points, segments).tolist() == pytest.approx(
        [0, 0.5, 0, 0.25, 0]
    )
    # (1, 0.5) at 150 ms is judged against the second segment: 1 away, not 0.5.
    assert metrics.max_deviation([0, 150], points[[0, 1]], segments) == pytest.approx(1.0)


def test_a_frame_in_a_gap_takes_the_nearest_segment() -> None:
    segments = [seg((0, 0), (1, 0), 0, 100), seg((2, 0), (3, 0), 200, 300)]
    points = metrics.as_points([(1.5, 0.25)])
    assert metrics.max_deviation([150], points, segments) == pytest.approx(math.hypot(0.5, 0.25))


def test_frechet_of_two_parallel_lines_is_their_distance() -> None:
    p = metrics.densify(metrics.as_points([(0, 0), (4, 0)]), 0.01)
    q = metrics.densify(metrics.as_points([(0, 1), (4, 1)]), 0.01)
    assert metrics.discrete_frechet(p, q) == pytest.approx(1.0)


def test_frechet_sees_the_order_hausdorff_does_not() -> None:
    forward = metrics.as_points([(0, 0), (1, 0), (2, 0)])
    backward = forward[::-1]
    assert metrics.discrete_frechet(forward, backward) == pytest.approx(2.0)


def test_path_frechet_densifies_the_strokes() -> None:
    # Frames on the stroke itself: distance ~0, not half the stroke's length.
    points = metrics.as_points([(x / 10, 0) for x in range(31)])
    segments = [seg((0, 0), (3, 0), 0, 300)]
    assert metrics.path_frechet(points, segments) <= metrics.FRECHET_STEP / 2 + 1e-12


def test_counts_and_lags() -> None:
    dropped = Segment((0, 0), (0.01, 0), 0, 5, 21, dropped="not_enough_distance")
    segments = [seg((0, 0), (1, 0), 0, 100), dropped, seg((1, 0), (2, 0), 100, 250)]
    assert metrics.stroke_count(segments) == 2
    assert metrics.dropped_count(segments) == 1
    assert metrics.emission_lags_ms(segments).tolist() == [16.0, 16.0]


def test_douglas_peucker_on_a_hand_checked_path() -> None:
    # A tent: the apex is 1 away from the base line, the bumps 0.1 from their legs.
    points = metrics.as_points([(0, 0), (1, 0.95), (2, 1), (3, 0.95), (4, 0)])
    assert metrics.douglas_peucker(points, 1.5).tolist() == [0, 4]
    assert metrics.douglas_peucker(points, 0.5).tolist() == [0, 2, 4]
    assert metrics.douglas_peucker_strokes(points, 0.5) == 2


@given(polyline, polyline)
@settings(max_examples=60, deadline=None)
def test_frechet_is_a_symmetric_non_negative_distance(p: np.ndarray, q: np.ndarray) -> None:
    d = metrics.discrete_frechet(p, q)
    assert d >= 0
    assert d == pytest.approx(metrics.discrete_frechet(q, p))
    assert metrics.discrete_frechet(p, p.copy()) == 0.0


@given(polyline, st.floats(0.001, 5))
@settings(max_examples=100, deadline=None)
def test_douglas_peucker_keeps_the_ends_and_its_bound(points: np.ndarray, error: float) -> None:
    kept = metrics.douglas_peucker(points, error)
    assert kept[0] == 0 and kept[-1] == len(points) - 1
    assert np.all(np.diff(kept) > 0) or len(points) == 1
    for a, b in itertools.pairwise(kept):
        between = metrics.segment_distances(points[a : b + 1], points[a], points[b])
        assert between.max() <= error + 1e-9


@given(polyline, st.floats(0.01, 1))
@settings(max_examples=60, deadline=None)
def test_densify_keeps_the_vertices_and_the_step(points: np.ndarray, step: float) -> None:
    dense = metrics.densify(points, step)
    assert np.all(np.hypot(*np.diff(dense, axis=0).T) <= step + 1e-9)
    assert dense[0].tolist() == points[0].tolist()
    assert np.allclose(dense[-1], points[-1])
