"""The duty-cycle cap: no window ever holds more than its budget, no started stroke is cut,
and light use is never refused. Pure: the timeline on made-up times."""

from __future__ import annotations

import bisect
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from timelines import TIGHT_WINDOW_MS, Played, tight_layout

from feelmysign.duty_cycle import Drive, DutyCycle
from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.schedule import Command, Schedule
from feelmysign.stroke import Stroke
from feelmysign.timeline import Change, Timeline

WINDOW_MS = TIGHT_WINDOW_MS
TIGHT = tight_layout(max_duty_cycle=0.5)
BUDGET_MS = WINDOW_MS * 0.5

strokes = st.lists(
    st.tuples(
        st.floats(0, 3),
        st.floats(0, 2),
        st.floats(0, 3),
        st.floats(0, 2),
        st.floats(300, 1000),  # duration
        st.floats(0, 600),  # gap after the previous stroke's start
        st.floats(0.2, 1.0),  # intensity
    ),
    min_size=1,
    max_size=15,
)


def _play(
    timeline: Timeline, planned: list[tuple[Schedule, float]]
) -> tuple[list[Change], list[object], list[object]]:
    for index, (schedule, start_ms) in enumerate(planned):
        timeline.add(schedule, start_ms, tag=index)
    return Played().play_out(timeline)


def _levels(changes: list[Change]) -> dict[tuple[int, int], list[tuple[float, float]]]:
    """Per actuator, its (t_ms, intensity) steps."""
    steps: dict[tuple[int, int], list[tuple[float, float]]] = {}
    for change in changes:
        steps.setdefault((change.row, change.column), []).append((change.t_ms, change.intensity))
    return steps


def _energy_ms(steps: list[tuple[float, float]], start_ms: float, end_ms: float) -> float:
    total = 0.0
    for (t, level), (t_next, _) in zip(steps, [*steps[1:], (float("inf"), 0.0)], strict=True):
        span = min(t_next, end_ms) - max(t, start_ms)
        if span > 0:
            total += level * level * span
    return total


def _level_at(steps: list[tuple[float, float]], t_ms: float) -> float:
    index = bisect.bisect_right([t for t, _ in steps], t_ms) - 1
    return steps[index][1] if index >= 0 else 0.0


def _strokes(drawn: list[tuple[float, ...]]) -> list[tuple[Schedule, float]]:
    """Planned strokes at their start times (those the layout cannot render left out)."""
    planned, start_ms = [], 0.0
    for x0, y0, x1, y1, duration_ms, gap_ms, intensity in drawn:
        start_ms += gap_ms
        try:
            schedule = plan(Stroke((x0, y0), (x1, y1), duration_ms, intensity), TIGHT)
        except StrokeError:
            continue
        planned.append((schedule, start_ms))
    return planned


@settings(max_examples=60, deadline=None)
@given(strokes)
def test_no_window_ever_holds_more_than_the_budget(drawn: list[tuple[float, ...]]) -> None:
    planned = _strokes(drawn)
    changes, started, capped = _play(Timeline(TIGHT), planned)
    assert sorted(i for i in [*started, *capped] if isinstance(i, int)) == list(
        range(len(planned))
    )  # each one, once
    for steps in _levels(changes).values():
        ends = {t for t, _ in steps} | {t + WINDOW_MS for t, _ in steps}
        for end_ms in ends:
            assert _energy_ms(steps, end_ms - WINDOW_MS, end_ms) <= BUDGET_MS + 1e-6


@settings(max_examples=60, deadline=None)
@given(strokes)
def test_a_started_stroke_is_felt_whole_and_a_capped_one_adds_nothing(
    drawn: list[tuple[float, ...]],
) -> None:
    planned = _strokes(drawn)
    changes, started, _capped = _play(Timeline(TIGHT), planned)
    steps = _levels(changes)
    for index in started:
        assert isinstance(index, int)
        schedule, start_ms = planned[index]
        for command in schedule.commands:
            on = steps.get((command.row, command.column), [])
            middle_ms = start_ms + (command.start_ms + command.end_ms) / 2
            assert _level_at(on, middle_ms) > 0, (index, command)
    # Only the started strokes: the same output, so the capped ones added nothing.
    kept = [planned[i] for i in range(len(planned)) if i in started]
    again, started_again, capped_again = _play(Timeline(TIGHT), kept)
    assert (again, len(started_again), capped_again) == (changes, len(started), [])


@settings(max_examples=100, deadline=None)
@given(st.floats(50, 10_000), st.floats(0.05, 0.2), st.floats(0.2, 1.0))
def test_a_motor_used_up_to_a_fifth_of_the_time_is_never_refused(
    duration_ms: float, used: float, intensity: float
) -> None:
    """The defaults (a minute, half of it, strokes up to 10 s): any steady pace up to 20%."""
    layout = Layout(rows=3, columns=4, spacing_cm=3.0)
    timeline = Timeline(layout)
    period_ms = duration_ms / used
    count = min(2000, math.ceil(4 * layout.duty_cycle_window_ms / period_ms))  # four windows
    command = Command(1, 1, 0.0, duration_ms, intensity)
    schedule = Schedule(Stroke((1, 1), (1, 1), duration_ms), (command,), duration_ms)
    for index in range(count):
        timeline.add(schedule, index * period_ms, tag=index)
    _, started, capped = _play(timeline, [])
    assert capped == [] and len(started) == count


def test_energy_counts_intensity_squared_and_forgets_what_left_the_window() -> None:
    duty = DutyCycle(1000.0, 0.5)
    duty.output((0, 0), 0.0, 0.5)
    duty.output((0, 0), 400.0, 0.0)
    assert duty.energy_ms((0, 0), 400.0) == pytest.approx(100.0)
    assert duty.energy_ms((0, 0), 1200.0) == pytest.approx(50.0)  # 200..400 still inside
    assert duty.energy_ms((0, 0), 1400.0) == 0.0
    plan_ = {(0, 0): [Drive(1400.0, 1900.0, 1.0)]}
    assert duty.check(plan_, 1400.0) is None
    duty.commit(plan_, 1400.0)
    duty.output((0, 0), 1400.0, 1.0)
    assert duty.check({(0, 0): [Drive(1500.0, 1500.0, 1.0)]}, 1500.0) is None  # 100 + 400 = 500
    refusal = duty.check({(0, 0): [Drive(1500.0, 1600.0, 1.0)]}, 1500.0)
    assert refusal is not None and refusal.duty_cycle == pytest.approx(0.6)  # 100 + 400 + 100


@pytest.mark.parametrize(("window_ms", "duty"), [(0.0, 0.5), (1000.0, 0.0), (1000.0, 1.5)])
def test_a_meaningless_cap_is_refused(window_ms: float, duty: float) -> None:
    with pytest.raises(ValueError, match="window_ms must be above 0"):
        DutyCycle(window_ms, duty)


_drives = st.lists(
    st.tuples(
        st.integers(0, 2),  # actuator row (one column): few actuators, so drives pile up
        st.floats(0, 1_000),  # start, ms after the one before
        st.floats(1, 3_000),  # length, ms
        st.floats(0.05, 1.0),  # intensity
        st.booleans(),  # committed (a stroke admitted, not over) or written (the past)
    ),
    max_size=40,
)


@settings(max_examples=300, deadline=None)
@given(_drives, st.floats(0, 12_000), st.floats(0, 2_000))
def test_what_surely_fits_is_admitted(
    drives: list[tuple[int, float, float, float, bool]], energy_ms: float, after_ms: float
) -> None:
    """surely_fits answers from totals and one bound for every actuator: whenever it says
    yes, the exact check admits a stroke of that energy on any one actuator."""
    duty = DutyCycle(window_ms=20_000.0, max_duty_cycle=0.5)
    t_ms = 0.0
    for actuator_row, gap_ms, length_ms, intensity, committed in drives:
        t_ms += gap_ms
        actuator = (actuator_row, 0)
        if committed:
            duty.commit({actuator: [Drive(t_ms, t_ms + length_ms, intensity**2)]}, t_ms)
        else:
            duty.output(actuator, t_ms, intensity)
            duty.output(actuator, t_ms + length_ms, 0.0)
    now_ms = t_ms + after_ms
    if duty.surely_fits(energy_ms, now_ms):
        for row in range(3):
            stroke = {(row, 0): [Drive(now_ms, now_ms + energy_ms, 1.0)]}
            assert duty.check(stroke, now_ms) is None
