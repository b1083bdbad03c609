"""A stroke's first commands before the rest of it: what is played must not change.

The sleeve starts a stroke that is due at once from its outline (``Outline.head``
and ``Timeline.add_outline``) and plans the rest while the first burst plays.
These tests pin that this plays exactly what the whole plan plays: the head is
the plan's first commands, and a timeline fed outlines writes the same changes
(time, actuator, intensity, stroke) and starts or caps the same strokes as one
fed whole schedules, also near the duty-cycle cap.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from timelines import Played, tight_layout

from feelmysign.apparent_motion import fitting_timings, lengths_bound_ms, surely_fits, timings
from feelmysign.layout import Layout
from feelmysign.planner import outline, plan
from feelmysign.stroke import Stroke
from feelmysign.timeline import FIRST_COMMANDS_MS, Change, Timeline

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
WIDE = Layout(rows=3, columns=12, spacing_cm=3.0)
LRA = Layout(rows=4, columns=6, spacing_cm=2.5, actuator_type="LRA")
# A 2 s window with a third of it at full drive: reached within a few strokes.
TIGHT = tight_layout(max_duty_cycle=0.3)
LAYOUTS = (PAPER, WIDE, LRA, TIGHT)


def _coordinate(count: int) -> st.SearchStrategy[float]:
    # Whole numbers and points a hair off them too: on a grid line is where funneling turns.
    near_lines = st.builds(
        lambda k, d: min(max(k + d, 0.0), count - 1.0),
        st.integers(0, count - 1),
        st.sampled_from([0.0, 1e-10, -1e-10, 0.03, -0.03, 0.5]),
    )
    return st.one_of(st.floats(0, count - 1), near_lines)


@st.composite
def _strokes(draw: st.DrawFn, layout: Layout) -> Stroke:
    x, y = _coordinate(layout.columns), _coordinate(layout.rows)
    start = (draw(x), draw(y))
    end = draw(st.one_of(st.just(start), st.tuples(x, y)))
    duration_ms = draw(st.floats(20, min(layout.max_stroke_duration_ms, 4000)))
    intensity = draw(st.one_of(st.none(), st.floats(0, 1)))
    return Stroke(start, end, duration_ms, intensity)


@st.composite
def _layout_and_strokes(draw: st.DrawFn, count: int) -> tuple[Layout, list[Stroke]]:
    layout = draw(st.sampled_from(LAYOUTS))
    return layout, draw(st.lists(_strokes(layout), min_size=1, max_size=count))


@settings(max_examples=400, deadline=None)
@given(_layout_and_strokes(1), st.sampled_from([FIRST_COMMANDS_MS, 40.0, 200.0]))
def test_the_head_is_the_plans_first_commands(
    case: tuple[Layout, list[Stroke]], before_ms: float
) -> None:
    layout, (stroke,) = case
    whole = plan(stroke, layout)
    head = outline(stroke, layout).head(before_ms)
    assert head == tuple(c for c in whole.commands if c.start_ms < before_ms)
    assert outline(stroke, layout).schedule() == whole


def _play(
    layout: Layout, strokes: list[Stroke], gaps_ms: list[float], *, lazily: bool
) -> tuple[list[Change], list[object], list[object]]:
    """Every change, started and capped tag, strokes arriving as the player takes them:
    each at the end of the one before (or after a gap), popped at its start, then on."""
    timeline = Timeline(layout)
    played = Played()

    def pop(now_ms: float) -> None:
        played.take(timeline.pop_due(now_ms))

    start_ms = 1000.0
    for k, (stroke, gap_ms) in enumerate(zip(strokes, gaps_ms, strict=True)):
        pop(start_ms - 1e-3)  # what played before it arrives
        if lazily:
            timeline.add_outline(outline(stroke, layout), start_ms, tag=k)
            pop(start_ms)  # its first commands written...
            timeline.complete()  # ...then the rest planned, as the player does
        else:
            timeline.add(plan(stroke, layout), start_ms, tag=k)
            pop(start_ms)
        start_ms += plan(stroke, layout).duration_ms + gap_ms
    return played.play_out(timeline)


@settings(max_examples=300, deadline=None)
@given(_layout_and_strokes(8), st.data())
def test_a_timeline_fed_outlines_plays_what_whole_schedules_play(
    case: tuple[Layout, list[Stroke]], data: st.DataObject
) -> None:
    layout, strokes = case
    gaps = st.sampled_from([0.0, 0.0, 10.0, 500.0, 3000.0])
    gaps_ms = data.draw(st.lists(gaps, min_size=len(strokes), max_size=len(strokes)))
    lazy = _play(layout, strokes, gaps_ms, lazily=True)
    whole = _play(layout, strokes, gaps_ms, lazily=False)
    assert [(c.t_ms, c.row, c.column, c.intensity, c.tag) for c in lazy[0]] == [
        (c.t_ms, c.row, c.column, c.intensity, c.tag) for c in whole[0]
    ]
    assert lazy[1:] == whole[1:]


@pytest.mark.parametrize("duration_ms", [130.0, 150.0, 200.0, 900.0])
def test_the_cap_is_decided_the_same_for_an_outline_near_it(duration_ms: float) -> None:
    """Strokes on one motor at full drive until the cap (600 ms of a 2 s window) refuses
    one: near it the outline's bound cannot admit a stroke, so its whole drive decides,
    and the same strokes play or are capped."""
    strokes = [Stroke((1.0, 1.0), (1.0, 1.0), duration_ms, 1.0)] * 8
    lazy = _play(TIGHT, strokes, [0.0] * 8, lazily=True)
    whole = _play(TIGHT, strokes, [0.0] * 8, lazily=False)
    assert whole[2], "the cap refuses some of these strokes"
    assert [(c.t_ms, c.row, c.column, c.intensity, c.tag) for c in lazy[0]] == [
        (c.t_ms, c.row, c.column, c.intensity, c.tag) for c in whole[0]
    ]
    assert lazy[1:] == whole[1:]


@st.composite
def _fractions_of_a_way(draw: st.DrawFn) -> list[float]:
    inside = draw(st.lists(st.floats(1e-6, 1 - 1e-6), min_size=2, max_size=40, unique=True))
    return [0.0, *sorted(inside), 1.0]


@settings(max_examples=500, deadline=None)
@given(
    _fractions_of_a_way(),
    st.floats(50, 30_000),
    st.sampled_from([0.0, 10.0, 20.0, 60.0]),
)
def test_a_stroke_timed_later_surely_fits_and_its_bound_holds(
    fractions: list[float], duration_ms: float, min_command_ms: float
) -> None:
    """``surely_fits`` (which lets a long stroke's timings wait) never says so of timings
    that do not fit; and the bound on their lengths it then uses is at least their sum."""
    if not surely_fits(fractions, duration_ms, min_command_ms):
        return
    fitting = fitting_timings(fractions, duration_ms, min_command_ms)
    assert fitting is not None
    assert fitting == timings(fractions)
    lengths_ms = sum(a * duration_ms + b for _, _, a, b in fitting)
    assert lengths_bound_ms(fractions, duration_ms) >= lengths_ms


@settings(max_examples=300, deadline=None)
@given(_layout_and_strokes(1))
def test_the_energy_bound_before_the_bursts_is_at_least_the_one_after(
    case: tuple[Layout, list[Stroke]],
) -> None:
    layout, (stroke,) = case
    planned = outline(stroke, layout)
    before = planned.energy_bound_ms()
    planned.schedule()
    assert before >= planned.energy_bound_ms()
