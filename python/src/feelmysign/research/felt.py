"""The felt path: where the touch a planned schedule renders lies, over time.

A schedule drives physical actuators at constant intensities over spans of
time; several at once make one phantom point between them (funneling, Israr &
Poupyrev 2011). By the energy model the planner renders it with, the phantom
lies at the actuators' positions weighted by their energies, intensity
squared: a burst at fraction ``beta`` of the way between two actuators drives
them at ``sqrt(1 - beta)`` and ``sqrt(beta)`` of its intensity, and the
energy-weighted mean is exactly its point. Where bursts overlap (apparent
motion) the same mean lies between them: the touch moving.

The intensities are constant between consecutive command starts and ends, so
the phantom is too: ``felt_samples`` takes it once in each such interval (the
exact sampling, whatever the rate), and leaves out the silent ones. A
drawing's felt path is its strokes' samples in the order they play.

Positions are in grid units, as the planner's: an actuator at ``(row,
column)`` lies at ``x = column``, ``y = row``.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import NDArray

from feelmysign.schedule import Schedule

Points = NDArray[np.float64]  # (n, 2): x, y in grid units


def felt_samples(schedule: Schedule) -> tuple[NDArray[np.float64], Points]:
    """The phantom point of each interval in which the commands do not change, in time order.

    Returns the intervals' start times (ms from the stroke's start) and the
    energy-weighted position of the actuators on in each; an interval with
    nothing on (or only at intensity 0) gives no sample. Consecutive intervals
    felt at the same point give one sample, at the first's time.
    """
    commands = schedule.commands
    if not commands:
        return np.empty(0), np.empty((0, 2))
    table = np.array(
        [(c.start_ms, c.start_ms + c.duration_ms, c.intensity, c.column, c.row) for c in commands]
    )
    starts, ends, intensities, xy = table[:, 0], table[:, 1], table[:, 2], table[:, 3:]
    times = np.unique(np.concatenate([starts, ends]))[:-1]  # each interval's start
    on = (starts[None, :] <= times[:, None]) & (times[:, None] < ends[None, :])
    energies = on * intensities[None, :] ** 2
    total = energies.sum(axis=1)
    felt = total > 0
    points: Points = (energies[felt] @ xy) / total[felt, None]
    times = times[felt]
    if len(points) > 1:
        moved = np.concatenate([[True], np.any(points[1:] != points[:-1], axis=1)])
        points, times = points[moved], times[moved]
    return times, points


def felt_path(schedules: Iterable[Schedule]) -> Points:
    """The phantom's positions over the strokes of a drawing, given in the order they play."""
    parts = [felt_samples(schedule)[1] for schedule in schedules]
    return np.concatenate(parts) if parts else np.empty((0, 2))
