"""Distances shared by the window simplifier's cores (``window.py``, the chord, and ``fit.py``,
the least squares): their float operations are the reference's, to the last bit, that the
TypeScript (``web/src/simplify/distance.ts``) and Java cores repeat."""

from __future__ import annotations

# Far more than any rounding error of a distance computed here (grid coordinates are at most 63,
# so under 1e-12 grid units), far less than the least max_error (0.001): what the reach of a
# stroke (the chord's ``WindowSimplifier._reach``, the least squares' ``FitCore._keeps``) adds
# for rounding, so that it never understates a true distance, and the room it keeps below
# max_error, so that no distance it lets through could compute above it.
ROUNDING_SLACK = 1e-9


def segment_distance_sq(px: float, py: float, ax: float, ay: float, ex: float, ey: float) -> float:
    """Squared distance from (px, py) to the segment (ax, ay) -> (ex, ey): the projection clamped
    onto it (the operations of ``window.segment_distance_sq``, which takes points)."""
    dx = ex - ax
    dy = ey - ay
    qx = px - ax
    qy = py - ay
    length_sq = dx * dx + dy * dy
    if length_sq > 0.0:
        t = (qx * dx + qy * dy) / length_sq
        if t >= 1.0:
            qx = qx - dx
            qy = qy - dy
        elif not t <= 0.0:
            qx = qx - t * dx
            qy = qy - t * dy
    return qx * qx + qy * qy
