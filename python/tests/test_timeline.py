"""The timeline: planned strokes at absolute times -> intensity changes, safety caps."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from timelines import Played, tight_layout

from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.schedule import Command, Schedule
from feelmysign.stroke import Stroke
from feelmysign.timeline import Change, Timeline

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
# A 2 s window with half of it at full drive: 1000 ms of budget, quick to reach.
TIGHT = tight_layout(max_duty_cycle=0.5)


def _schedule(*commands: Command, duration_ms: float = 100.0) -> Schedule:
    return Schedule(Stroke((0, 0), (1, 0), duration_ms), tuple(commands), duration_ms)


def _drain(timeline: Timeline) -> list[Change]:
    changes: list[Change] = []
    while (t := timeline.next_ms()) is not None:
        changes += timeline.pop_due(t).changes
    return changes


def test_a_planned_stroke_becomes_its_commands_at_absolute_times() -> None:
    schedule = plan(Stroke((0, 0), (2, 0), 1000), PAPER)
    timeline = Timeline(PAPER)
    timeline.add(schedule, 5000.0, tag="first")
    first = timeline.pop_due(5000.0)
    assert first.started == ["first"]
    assert first.changes == [Change(5000.0, 0, 0, 1.0)]
    rest = _drain(timeline)
    ons = [(c.t_ms - 5000.0, c.column) for c in rest if c.intensity > 0]
    assert [(round(t, 3), col) for t, col in ons] == [(157.045, 1), (480.372, 2)]
    final = {(c.row, c.column): c.intensity for c in rest}
    assert final == {(0, 0): 0.0, (0, 1): 0.0, (0, 2): 0.0} and not timeline.busy


def test_overlapping_strokes_add_energy_capped_by_the_layout() -> None:
    capped = Layout(rows=3, columns=4, spacing_cm=3.0, max_intensity=0.9)
    timeline = Timeline(capped)
    timeline.add(_schedule(Command(0, 0, 0, 100, 0.6)), 0.0)
    timeline.add(_schedule(Command(0, 0, 0, 100, 0.6)), 50.0)
    levels = [(c.t_ms, round(c.intensity, 6)) for c in _drain(timeline)]
    assert levels == [(0.0, 0.6), (50.0, 0.848528), (100.0, 0.6), (150.0, 0.0)]
    timeline.add(_schedule(Command(0, 0, 0, 100, 1.0)), 200.0)
    assert [c.intensity for c in _drain(timeline)] == [0.9, 0.0]


def test_writes_only_on_change() -> None:
    timeline = Timeline(PAPER)
    timeline.add(_schedule(Command(1, 1, 0, 100, 0.5), Command(1, 1, 100, 100, 0.5)), 0.0)
    assert [(c.t_ms, c.intensity) for c in _drain(timeline)] == [(0.0, 0.5), (200.0, 0.0)]


def test_a_stroke_over_the_duty_cycle_budget_plays_not_at_all_and_a_rest_restores_it() -> None:
    timeline = Timeline(TIGHT)
    for k in range(4):  # back-to-back strokes keeping one motor at full drive
        timeline.add(_schedule(Command(2, 3, 0, 500, 1.0), duration_ms=500), k * 500.0, tag=k)
    timeline.add(_schedule(Command(2, 3, 0, 100, 1.0)), 3000.0, tag="rested")
    changes, started, capped = Played().play_out(timeline)
    # 0 and 1 fill the 1000 ms budget exactly; 2 and 3 would exceed it: not a single command.
    assert started == [0, 1, "rested"] and capped == [2, 3]
    assert [(c.t_ms, c.intensity) for c in changes] == [
        (0.0, 1.0),
        (1000.0, 0.0),
        (3000.0, 1.0),
        (3100.0, 0.0),
    ]


def test_a_refusal_says_which_motor_and_by_how_much() -> None:
    timeline = Timeline(TIGHT)
    timeline.add(_schedule(Command(1, 1, 0, 900, 1.0), duration_ms=900), 0.0)
    timeline.add(_schedule(Command(1, 2, 0, 400, 1.0), Command(1, 1, 0, 400, 0.6)), 900.0, "x")
    assert timeline.pop_due(0.0).started
    (capped,) = timeline.pop_due(900.0).capped
    assert capped.tag == "x" and capped.refusal.actuator == (1, 1)
    # 900 ms at full drive, then 400 ms at 0.6 (0.36 of full): 1044 of 2000 ms.
    assert capped.refusal.duty_cycle == pytest.approx(0.522)
    assert (capped.refusal.max_duty_cycle, capped.refusal.window_ms) == (0.5, 2000.0)


def test_short_gaps_are_rests_in_proportion_not_resets() -> None:
    timeline = Timeline(TIGHT)
    for k in range(6):  # 400 ms on, 1 ms off: the motor hardly rests
        timeline.add(_schedule(Command(1, 1, 0, 400, 1.0), duration_ms=400), k * 401.0, tag=k)
    _, started, capped = Played().play_out(timeline)
    assert started == [0, 1] and capped == [2, 3, 4, 5]


def test_a_motor_used_a_fifth_of_the_time_is_never_refused() -> None:
    timeline = Timeline(PAPER)  # the defaults: a minute, half of it
    for k in range(600):  # ten minutes of 200 ms at full drive every second
        timeline.add(_schedule(Command(0, 1, 0, 200, 1.0), duration_ms=200), k * 1000.0, tag=k)
    _, started, capped = Played().play_out(timeline)
    assert capped == [] and len(started) == 600


def test_clear_switches_running_actuators_off() -> None:
    timeline = Timeline(PAPER)
    timeline.add(_schedule(Command(0, 2, 0, 100, 0.4)), 0.0)
    timeline.pop_due(0.0)
    assert timeline.clear() == [Change(0.0, 0, 2, 0.0)]
    assert timeline.next_ms() is None


@settings(max_examples=150, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0, 3),
            st.floats(0, 2),
            st.floats(0, 3),
            st.floats(0, 2),
            st.floats(50, 2000),
            st.floats(0, 1500),
        ),
        min_size=1,
        max_size=6,
    )
)
def test_any_strokes_end_with_every_actuator_off(
    strokes: list[tuple[float, float, float, float, float, float]],
) -> None:
    timeline = Timeline(PAPER)
    for x0, y0, x1, y1, duration_ms, start_ms in strokes:
        timeline.add(plan(Stroke((x0, y0), (x1, y1), duration_ms), PAPER), start_ms)
    last: dict[tuple[int, int], float] = {}
    previous_t = -math.inf
    for change in _drain(timeline):
        assert change.t_ms >= previous_t
        assert 0 <= change.intensity <= PAPER.max_intensity
        assert last.get((change.row, change.column), 0.0) != change.intensity  # only changes
        last[(change.row, change.column)] = change.intensity
        previous_t = change.t_ms
    assert all(v == 0 for v in last.values())
    assert not timeline.busy


def test_pop_due_is_lazy_about_the_future() -> None:
    timeline = Timeline(PAPER)
    timeline.add(_schedule(Command(0, 0, 10, 100, 0.5)), 0.0)
    assert timeline.pop_due(5.0).changes == []
    assert timeline.next_ms() == pytest.approx(10.0)


def test_an_ended_stroke_leaves_nothing_planned() -> None:
    """The on-time cap of a finished on-period must not keep the sleeve busy."""
    timeline = Timeline(PAPER)
    timeline.add(_schedule(Command(0, 0, 0, 100, 0.5)), 0.0)
    _drain(timeline)
    assert timeline.next_ms() is None and not timeline.busy


def test_cancelling_a_refused_stroke_does_not_call_it_cut_short() -> None:
    timeline = Timeline(TIGHT)
    timeline.add(_schedule(Command(2, 3, 0, 1000, 1.0), duration_ms=1000), 0.0, tag="full")
    timeline.add(_schedule(Command(2, 3, 0, 500, 1.0), duration_ms=500), 1000.0, tag="refused")
    assert timeline.pop_due(0.0).started == ["full"]
    assert [c.tag for c in timeline.pop_due(1000.0).capped] == ["refused"]
    cut = timeline.cancel(lambda tag: True, 1200.0)
    assert (cut.started, cut.unstarted, cut.changes) == ([], [], [])
    assert timeline.next_ms() is None and not timeline.busy


def test_a_stroke_that_takes_over_the_motors_left_on_changes_nothing_until_it_moves() -> None:
    # Back to back, the second starting where the first ends: at the joint the first's last
    # burst goes off as the second's first comes on, at the same intensity. No change there,
    # so no change (and no --record line) names the second stroke at its start.
    first, second = (
        plan(Stroke((0, 0), (1, 0), 400), PAPER),
        plan(Stroke((1, 0), (2, 0), 400), PAPER),
    )
    timeline = Timeline(PAPER)
    timeline.add(first, 0.0, tag="first")
    timeline.add(second, first.duration_ms, tag="second")
    changes, started, _ = Played().play_out(timeline)
    assert started == ["first", "second"]
    at_joint = [c for c in changes if c.t_ms == first.duration_ms]
    assert at_joint == []  # (0, 1) stays on: now the second stroke's
    ons = [(c.tag, c.t_ms) for c in changes if c.intensity > 0]
    assert ons[0] == ("first", 0.0)
    assert min(t for tag, t in ons if tag == "second") > first.duration_ms
    off = next(c for c in changes if (c.row, c.column) == (0, 1) and c.t_ms > first.duration_ms)
    assert off.intensity == 0.0 and off.tag == "second"
