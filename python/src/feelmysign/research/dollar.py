"""The $1 unistroke recogniser (Wobbrock, Wilson & Li, UIST 2007), written from the paper.

Does a drawing still read as its shape once it is cut into straight strokes?
Each candidate and template goes through the paper's four steps:

1. resample the path to ``N = 64`` points equally spaced along it;
2. rotate it about its centroid so that its indicative angle (centroid to
   first point) is 0;
3. scale it, non-uniformly, to a ``SIZE`` x ``SIZE`` square;
4. translate its centroid to the origin.

A candidate is then compared with every template at the best rotation found by
golden-section search over +-45 degrees, stopping at 2 degrees; the distance is
the mean distance between corresponding points, and the template with the least
distance names the shape (score ``1 - d / (0.5 sqrt(2 SIZE^2))``). The search runs
for all templates at once (numpy): every template starts from the same range,
so the search takes the same steps for each.

With ``fixed_orientation`` (shapes whose orientation is part of their meaning, as on an
arm: a square turned 45 degrees is a diamond, not a square) step 2 and the search are
left out, as the paper suggests for orientation-dependent gestures, and step 3 scales
uniformly by the larger side, so that a line stays a line (the paper's 1-D limitation).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

N = 64
SIZE = 250.0
ANGLE_RANGE_RAD = math.radians(45.0)
ANGLE_PRECISION_RAD = math.radians(2.0)
PHI = 0.5 * (-1.0 + math.sqrt(5.0))
HALF_DIAGONAL = 0.5 * math.sqrt(SIZE * SIZE + SIZE * SIZE)

Points = NDArray[np.float64]  # (n, 2)


def resample(points: Points, n: int = N) -> Points:
    """``n`` points equally spaced along the path (the paper's RESAMPLE)."""
    path = np.asarray(points, dtype=np.float64)
    steps = np.hypot(*np.diff(path, axis=0).T)
    total = float(steps.sum())
    if total == 0.0:
        return np.repeat(path[:1], n, axis=0)
    # The arc length of every vertex, and the n arc lengths wanted: the same points the
    # paper's incremental loop gives, without its drift from repeated subtraction.
    along = np.concatenate([[0.0], np.cumsum(steps)])
    wanted = np.linspace(0.0, total, n)
    x = np.interp(wanted, along, path[:, 0])
    y = np.interp(wanted, along, path[:, 1])
    return np.stack([x, y], axis=1)


def normalise(points: Points, *, fixed_orientation: bool = False) -> Points:
    """Steps 1 to 4: resampled, rotated to its indicative angle, scaled, centred (without the
    rotation and with uniform scaling when ``fixed_orientation``)."""
    path = resample(points)
    centre = path.mean(axis=0)
    if fixed_orientation:
        path = path - centre
    else:
        angle = math.atan2(centre[1] - path[0, 1], centre[0] - path[0, 0])
        path = _rotate(path - centre, -angle)
    low, high = path.min(axis=0), path.max(axis=0)
    # A straight line has no height: keep it from dividing by zero (the paper's 1-D limit).
    extent = np.maximum(high - low, 1e-9)
    path = path * (SIZE / (extent.max() if fixed_orientation else extent))
    result: Points = path - path.mean(axis=0)
    return result


def _rotate(points: Points, angle: float) -> Points:
    c, s = math.cos(angle), math.sin(angle)
    result: Points = points @ np.array([[c, s], [-s, c]])
    return result


@dataclass(frozen=True)
class Templates:
    """Normalised templates and their names."""

    names: tuple[str, ...]
    points: NDArray[np.float64]  # (templates, N, 2)
    fixed_orientation: bool = False

    @classmethod
    def of(
        cls, named: Sequence[tuple[str, Points]], *, fixed_orientation: bool = False
    ) -> Templates:
        normalised = [normalise(p, fixed_orientation=fixed_orientation) for _, p in named]
        return cls(tuple(n for n, _ in named), np.stack(normalised), fixed_orientation)

    def without(self, index: int) -> Templates:
        """All templates but one (leave-one-out)."""
        keep = [i for i in range(len(self.names)) if i != index]
        return Templates(
            tuple(self.names[i] for i in keep), self.points[keep], self.fixed_orientation
        )


def distances(candidate: Points, templates: Templates) -> NDArray[np.float64]:
    """The paper's distance at the best angle, from the candidate to every template."""
    points = normalise(candidate, fixed_orientation=templates.fixed_orientation)
    count = len(templates.names)
    if templates.fixed_orientation:
        return _distances_at(points, templates.points, np.zeros(count))
    low = np.full(count, -ANGLE_RANGE_RAD)
    high = np.full(count, ANGLE_RANGE_RAD)
    x1 = PHI * low + (1 - PHI) * high
    x2 = (1 - PHI) * low + PHI * high
    f1 = _distances_at(points, templates.points, x1)
    f2 = _distances_at(points, templates.points, x2)
    while abs(high[0] - low[0]) > ANGLE_PRECISION_RAD:
        left = f1 < f2
        # Where f1 < f2 the minimum lies in [low, x2]: high moves down; else low moves up.
        high = np.where(left, x2, high)
        low = np.where(left, low, x1)
        new_x1 = np.where(left, PHI * low + (1 - PHI) * high, x2)
        new_x2 = np.where(left, x1, (1 - PHI) * low + PHI * high)
        probe = np.where(left, new_x1, new_x2)
        f_probe = _distances_at(points, templates.points, probe)
        f1, f2 = np.where(left, f_probe, f2), np.where(left, f1, f_probe)
        x1, x2 = new_x1, new_x2
    result: NDArray[np.float64] = np.minimum(f1, f2)
    return result


def _distances_at(
    points: Points, templates: NDArray[np.float64], angles: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Mean point-to-point distance of the candidate rotated by each angle to each template."""
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    x = points[None, :, 0] * c - points[None, :, 1] * s
    y = points[None, :, 0] * s + points[None, :, 1] * c
    result: NDArray[np.float64] = np.hypot(x - templates[:, :, 0], y - templates[:, :, 1]).mean(
        axis=1
    )
    return result


def scores(candidate: Points, templates: Templates) -> NDArray[np.float64]:
    """The paper's score against every template (1 is a perfect match)."""
    result: NDArray[np.float64] = 1.0 - distances(candidate, templates) / HALF_DIAGONAL
    return result


def recognise(candidate: Points, templates: Templates) -> tuple[str, float]:
    """The name of the nearest template and the paper's score (1 is a perfect match)."""
    found = scores(candidate, templates)
    best = int(np.argmax(found))
    return templates.names[best], float(found[best])
