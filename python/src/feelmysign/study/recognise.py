"""How recognisable a felt path is as each of the study's shapes: the scoring hook of the
simulated participant.

The felt path is what the sleeve renders: the virtual actuators (bursts) of
the sleeve's own planner, in the order they are felt. It is compared with
each shape's ideal outline by the $1 recogniser of ``feelmysign.research.dollar``
(Wobbrock, Wilson & Li, UIST 2007) with a fixed orientation: a shape on the arm
has a known orientation, so rotation is not searched (a tilted square, a
diamond, should not score as a square) and paths are scaled uniformly (a line
stays a line). The score is the paper's, in [0, 1] (1 = the same path).

``Scorer`` is the interface: any recogniser giving one score per template can
replace ``dollar_scores``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.research import dollar
from feelmysign.stroke import Point, Stroke

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


def dollar_scores(
    path: Sequence[Point], templates: Mapping[str, Sequence[Point]]
) -> dict[str, float]:
    """$1 score of ``path`` against each template, orientation fixed, at least 0."""
    known = dollar.Templates.of(
        [(name, np.asarray(points, dtype=float)) for name, points in templates.items()],
        fixed_orientation=True,
    )
    found = dollar.scores(np.asarray(path, dtype=float), known)
    return {name: max(0.0, float(score)) for name, score in zip(known.names, found, strict=True)}
