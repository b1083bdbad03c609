"""How recognisable a felt path is as each of the study's shapes: the scoring hook of the
simulated participant.

The felt path is what the sleeve renders: the virtual actuators (bursts) of
the sleeve's own planner, in the order they are felt. It is compared with
each shape's ideal outline by the $1 recogniser's template distance
(Wobbrock, Wilson & Li, UIST 2007): both are resampled to ``RESAMPLE_POINTS``
points, scaled to a unit square and centred, and the mean point-to-point
distance gives a score in [0, 1] (1 = the same path). Rotation is not
searched: a shape on the arm has a known orientation, and a tilted square
(a diamond) should not score as a square.

``Scorer`` is the interface: any recogniser giving one score per template
(for example the one in ``feelmysign.research``) can replace ``dollar_scores``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.stroke import Point, Stroke

RESAMPLE_POINTS = 64  # the $1 recogniser's N
HALF_DIAGONAL = 0.5 * math.sqrt(2.0)  # $1: the largest distance between unit-square paths

Scorer = Callable[[Sequence[Point], Mapping[str, Sequence[Point]]], dict[str, float]]


def felt_path(strokes: Sequence[Stroke], layout: Layout) -> list[Point]:
    """The points the sleeve makes felt, in order: every burst of every planned stroke."""
    points: list[Point] = []
    for stroke in strokes:
        schedule = plan(stroke, layout)
        bursts = sorted(schedule.bursts, key=lambda b: b.peak_ms)
        for burst in bursts:
            point = (burst.x, burst.y)
            if not points or math.dist(points[-1], point) > 1e-9:
                points.append(point)
    return points


def outline(strokes: Sequence[Stroke]) -> list[Point]:
    """The drawn path of ``strokes``: every vertex, joined end to start."""
    if not strokes:
        return []
    return [strokes[0].start, *(s.end for s in strokes)]


def _resample(points: Sequence[Point], n: int) -> NDArray[np.float64]:
    path = np.asarray(points, dtype=float)
    if len(path) == 1:
        return np.repeat(path, n, axis=0)
    steps = np.hypot(*np.diff(path, axis=0).T)
    cumulative = np.concatenate([[0.0], np.cumsum(steps)])
    if cumulative[-1] == 0:
        return np.repeat(path[:1], n, axis=0)
    targets = np.linspace(0.0, cumulative[-1], n)
    return np.column_stack(
        [np.interp(targets, cumulative, path[:, 0]), np.interp(targets, cumulative, path[:, 1])]
    )


def _normalised(points: Sequence[Point]) -> NDArray[np.float64]:
    path = _resample(points, RESAMPLE_POINTS)
    size = np.ptp(path, axis=0)
    # Uniform scale by the larger side: a line stays a line instead of filling the square.
    path = path / max(float(size.max()), 1e-9)
    centred: NDArray[np.float64] = path - path.mean(axis=0)
    return centred


def dollar_scores(
    path: Sequence[Point], templates: Mapping[str, Sequence[Point]]
) -> dict[str, float]:
    """$1 score of ``path`` against each template: 1 - mean distance / half the unit diagonal."""
    candidate = _normalised(path)
    scores = {}
    for name, template in templates.items():
        distance = float(np.mean(np.hypot(*(candidate - _normalised(template)).T)))
        scores[name] = max(0.0, 1.0 - distance / HALF_DIAGONAL)
    return scores
