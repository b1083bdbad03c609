"""How far a simplifier's strokes stray from the drawn path, how many it sends, how late.

Pure functions over the frames of one path (the samples the simplifier saw, in
grid units, with their times) and the segments it gave for that path. Sent and
dropped segments both count as covering the path (they join end to start);
the dropped ones are counted apart.

- Deviation: each frame's distance to the segment whose time span covers it
  (the window simplifier bounds exactly this). A frame no segment covers (the
  gap a failed check leaves with ``recover`` off) takes the nearest segment.
- Discrete Fréchet distance (Eiter & Mannila 1994) between the frames and the
  stroke polyline, both densified first: on the polyline's bare corners the
  discrete distance would count half a stroke's length as error (and half the
  gap between two fast frames).
- Emission lag: ``emitted_at_ms - end_ms``, how long after the pointer reached
  a stroke's end the stroke was let go (the sleeve cannot start it earlier).
- Douglas-Peucker (Douglas & Peucker 1973), offline and so with the whole path
  in view, gives the fewest-ish strokes for an error: the frontier an online
  simplifier is compared against.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import similaritymeasures
from numpy.typing import NDArray
from simplification.cutil import simplify_coords_idx

from feelmysign.simplify.segment import Segment

Points = NDArray[np.float64]  # shape (n, 2): x (column), y (row) in grid units

# Spacing of the densified polylines, grid units: 1.5 mm on the paper's 3 cm sleeve,
# far below the forearm's two-point threshold (about 35 mm). The discrete distance
# then overstates the continuous one by at most half of it.
FRECHET_STEP = 0.05


def as_points(points: Sequence[tuple[float, float]] | Points) -> Points:
    array = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    return array


def segment_distances(points: Points, start: Sequence[float], end: Sequence[float]) -> Points:
    """Distance of every point to the segment start -> end (to its nearest point, not its line)."""
    a = np.asarray(start, dtype=np.float64)
    d = np.asarray(end, dtype=np.float64) - a
    q = points - a
    length_sq = float(d @ d)
    t = np.clip(q @ d / length_sq, 0.0, 1.0) if length_sq > 0.0 else np.zeros(len(points))
    result: Points = np.hypot(q[:, 0] - t * d[0], q[:, 1] - t * d[1])
    return result


def deviations(times_ms: Sequence[float], points: Points, segments: Sequence[Segment]) -> Points:
    """Each frame's distance to the segment covering its time (grid units); NaN with no segment."""
    if not segments:
        return np.full(len(points), np.nan)
    times = np.asarray(times_ms, dtype=np.float64)
    distances = np.stack([segment_distances(points, s.start, s.end) for s in segments], axis=1)
    starts = np.array([s.start_ms for s in segments])
    ends = np.array([s.end_ms for s in segments])
    covered = (times[:, None] >= starts[None, :]) & (times[:, None] <= ends[None, :])
    nearest_covering = np.where(covered, distances, np.inf).min(axis=1)
    result: Points = np.where(covered.any(axis=1), nearest_covering, distances.min(axis=1))
    return result


def max_deviation(times_ms: Sequence[float], points: Points, segments: Sequence[Segment]) -> float:
    """The farthest any frame lies from its covering segment, grid units (0 for no frames)."""
    values = deviations(times_ms, points, segments)
    return float(values.max()) if len(values) else 0.0


def stroke_polyline(segments: Sequence[Segment]) -> Points:
    """The segments' ends in order: start, end, start, end... (a joined pair repeats a point)."""
    return as_points([p for s in segments for p in (s.start, s.end)])


def densify(polyline: Points, step: float) -> Points:
    """The polyline with points added: no two consecutive ones more than ``step`` apart."""
    if len(polyline) < 2:
        return polyline
    pieces = [polyline[:1]]
    for a, b in itertools.pairwise(polyline):
        count = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
        t = np.arange(1, count + 1, dtype=np.float64)[:, None] / count
        pieces.append(a + t * (b - a))
    return np.concatenate(pieces)


def discrete_frechet(p: Points, q: Points) -> float:
    """The discrete Fréchet distance between two polylines (their vertices), Euclidean."""
    if len(p) == 0 or len(q) == 0:
        raise ValueError("the discrete Fréchet distance needs two non-empty polylines")
    return float(similaritymeasures.frechet_dist(p, q))


def path_frechet(points: Points, segments: Sequence[Segment], step: float = FRECHET_STEP) -> float:
    """Discrete Fréchet distance between the frames and the stroke polyline, both densified."""
    if not segments:
        return math.nan
    return discrete_frechet(densify(points, step), densify(stroke_polyline(segments), step))


def stroke_count(segments: Sequence[Segment]) -> int:
    """Strokes sent (segments not dropped)."""
    return sum(1 for s in segments if s.dropped is None)


def dropped_count(segments: Sequence[Segment]) -> int:
    return sum(1 for s in segments if s.dropped is not None)


def emission_lags_ms(segments: Sequence[Segment]) -> Points:
    """For every stroke sent: ms from the pointer reaching its end to its emission."""
    return np.array([s.emitted_at_ms - s.end_ms for s in segments if s.dropped is None])


def douglas_peucker(points: Points, max_error: float) -> NDArray[np.int64]:
    """Indices of the points Douglas-Peucker keeps at ``max_error`` (the first and last always)."""
    if len(points) < 3:
        return np.arange(len(points), dtype=np.int64)
    kept: Any = simplify_coords_idx(np.ascontiguousarray(points), float(max_error))
    return np.asarray(kept, dtype=np.int64)


def douglas_peucker_strokes(points: Points, max_error: float) -> int:
    """How many strokes Douglas-Peucker needs to stay within ``max_error`` of every point."""
    return max(len(douglas_peucker(points, max_error)) - 1, 1 if len(points) else 0)
