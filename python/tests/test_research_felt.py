"""The felt path: the phantom point a planned schedule renders, from the real planner."""

from __future__ import annotations

import numpy as np
import pytest

from feelmysign.layout import PAPER_SLEEVE
from feelmysign.planner import plan
from feelmysign.research.felt import felt_path, felt_samples
from feelmysign.schedule import Command, Schedule
from feelmysign.stroke import Stroke


def _planned(start: tuple[float, float], end: tuple[float, float], duration_ms: float) -> Schedule:
    return plan(Stroke(start, end, duration_ms), PAPER_SLEEVE)


@pytest.mark.parametrize(
    ("start", "end", "duration_ms"),
    [
        ((0.0, 0.0), (1.0, 0.0), 400.0),  # neighbours on a row
        ((2.0, 0.0), (2.0, 2.0), 600.0),  # down a column, across an actuator
        ((3.0, 2.0), (0.0, 0.0), 900.0),  # backwards, through cells
        ((0.0, 1.0), (3.0, 1.0), 80.0),  # fast: thinned to its two ends
    ],
)
def test_a_straight_stroke_is_felt_from_its_start_to_its_end_along_it(
    start: tuple[float, float], end: tuple[float, float], duration_ms: float
) -> None:
    times, points = felt_samples(_planned(start, end, duration_ms))
    assert len(points) >= 2
    assert points[0] == pytest.approx(start) and points[-1] == pytest.approx(end)
    assert np.all(np.diff(times) > 0)
    # Monotone: each sample farther along the stroke than the one before, and on it.
    direction = np.subtract(end, start) / np.hypot(*np.subtract(end, start))
    offsets = points - np.asarray(start)
    along = offsets @ direction
    assert np.all(np.diff(along) > 0)
    across = offsets[:, 0] * direction[1] - offsets[:, 1] * direction[0]
    assert np.abs(across).max() < 1e-9


def test_a_stroke_between_columns_is_felt_between_them_as_funneling_places_it() -> None:
    # Every burst lies a quarter of the way from column 0 to 1, rendered on both at
    # sqrt(0.75) and sqrt(0.25) of its intensity: their energies put it back at 0.25.
    _, points = felt_samples(_planned((0.25, 0.0), (0.25, 2.0), 600.0))
    assert points[:, 0] == pytest.approx(np.full(len(points), 0.25))
    assert points[0, 1] == pytest.approx(0.0) and points[-1, 1] == pytest.approx(2.0)


def test_a_stroke_on_one_actuator_is_felt_at_one_point() -> None:
    schedule = _planned((1.0, 2.0), (1.0, 2.0), 200.0)
    assert schedule.commands  # it plays
    times, points = felt_samples(schedule)
    assert points.tolist() == [[1.0, 2.0]] and times.tolist() == [0.0]


def test_an_empty_schedule_is_felt_nowhere() -> None:
    stroke = Stroke((0.0, 0.0), (1.0, 0.0), 100.0)
    times, points = felt_samples(Schedule(stroke, (), 100.0))
    assert points.shape == (0, 2) and times.shape == (0,)
    assert felt_path([]).shape == (0, 2)
    assert felt_path([Schedule(stroke, (), 100.0)]).shape == (0, 2)


def test_the_phantom_is_the_energy_weighted_mean_of_the_actuators_on() -> None:
    stroke = Stroke((0.0, 0.0), (3.0, 2.0), 300.0)
    commands = (
        Command(0, 0, 0.0, 100.0, 0.6),  # x 0, y 0
        Command(1, 2, 50.0, 100.0, 0.8),  # x 2, y 1
        Command(2, 1, 60.0, 20.0, 0.0),  # on at intensity 0: no energy, no weight
        Command(2, 3, 200.0, 50.0, 1.0),  # after a silence
    )
    times, points = felt_samples(Schedule(stroke, commands, 300.0))
    # Energies 0.36 and 0.64 while both are on: x = 0.64 * 2, y = 0.64 * 1 (intensities
    # as weights would give 2 * 0.8 / 1.4 = 1.14 instead).
    assert times.tolist() == [0.0, 50.0, 100.0, 200.0]
    assert points == pytest.approx(np.array([[0.0, 0.0], [1.28, 0.64], [2.0, 1.0], [3.0, 2.0]]))


def test_a_drawing_is_felt_stroke_after_stroke_in_the_order_they_play() -> None:
    first = _planned((0.0, 0.0), (1.0, 0.0), 300.0)
    second = _planned((1.0, 0.0), (1.0, 2.0), 300.0)
    path = felt_path([first, second])
    assert len(path) == len(felt_samples(first)[1]) + len(felt_samples(second)[1])
    assert path[0] == pytest.approx((0.0, 0.0)) and path[-1] == pytest.approx((1.0, 2.0))
    backwards = felt_path([second, first])
    assert backwards[0] == pytest.approx((1.0, 0.0)) and backwards[-1] == pytest.approx((1.0, 0.0))
