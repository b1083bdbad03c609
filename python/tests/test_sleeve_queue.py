"""The sleeve's queue against the shared vectors (testdata/queue), in its pure form and in
the player that plays on the sleeve."""

from __future__ import annotations

import math
import threading
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st
from vectors import load

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.backends.sim import SimBackend
from feelmysign.events import Event, Played, StrokeRef
from feelmysign.layout import Layout
from feelmysign.planner import outline
from feelmysign.player import PlannedStroke, Player
from feelmysign.schedule import Schedule
from feelmysign.sleeve.queue import (
    NEVER_MS,
    Arrival,
    CancelAt,
    Outcome,
    Queue,
    SeenSeqs,
    catch_up_ms,
    replay,
    start_ms,
)
from feelmysign.stroke import Stroke

CASES = load("queue")


class Events:
    """The player's events, to wait for: one ``played`` per stroke started."""

    def __init__(self) -> None:
        self.count = 0
        self.changed = threading.Condition()
        self.events: list[Event] = []

    def __call__(self, event: Event) -> None:
        with self.changed:
            self.count += 1
            self.events.append(event)
            self.changed.notify_all()

    def wait_for(self, count: int, timeout_s: float = 10.0) -> None:
        with self.changed:
            assert self.changed.wait_for(lambda: self.count >= count, timeout_s), self.count


PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)


def _steps(case: dict[str, Any]) -> list[Arrival | CancelAt]:
    steps: list[Arrival | CancelAt] = []
    for step in case["steps"]:
        if "cancel" in step:
            drawing = None if step["cancel"] == "*" else step["cancel"]
            steps.append(CancelAt(step["at_ms"], drawing))
        else:
            steps.append(
                Arrival(
                    step["arrival_ms"], step["duration_ms"], step.get("drawing"), step.get("seq")
                )
            )
    return steps


def _expected(case: dict[str, Any]) -> list[Outcome]:
    return [Outcome(o["outcome"], o.get("start_ms"), o.get("played_ms")) for o in case["outcomes"]]


def test_the_vectors_cover_every_outcome() -> None:
    seen = {o["outcome"] for _, case in CASES for o in case["outcomes"]}
    assert seen == {"played", "cut", "cancelled", "held", "duplicate"}


@pytest.mark.parametrize(("name", "case"), CASES, ids=[n for n, _ in CASES])
def test_replay(name: str, case: dict[str, Any]) -> None:
    assert replay(_steps(case), case["floor_ms"]) == _expected(case)


WITHOUT_CANCELS = [(n, c) for n, c in CASES if not any("cancel" in s for s in c["steps"])]


@pytest.mark.parametrize(("name", "case"), WITHOUT_CANCELS, ids=[n for n, _ in WITHOUT_CANCELS])
def test_the_player_starts_strokes_as_the_vectors_say(name: str, case: dict[str, Any]) -> None:
    # The player's clock is each step's arrival; before the step, the strokes due by then
    # have started (a copy of one that started is a duplicate, of one still waiting held).
    now_ms = [-1e9]
    backend = SimBackend(PAPER)
    started = Events()
    player = Player(backend, PAPER, clock=lambda: now_ms[0], on_event=started)
    player.start()
    try:
        outcomes: list[Outcome] = []
        accepted: list[PlannedStroke] = []
        for step in case["steps"]:
            now_ms[0] = step["arrival_ms"]
            started.wait_for(sum(1 for p in accepted if p.start_ms <= now_ms[0]))
            stroke = Stroke((0.0, 0.0), (1.0, 0.0), step["duration_ms"])
            schedule = Schedule(stroke, (), step["duration_ms"])
            info = {k: step[k] for k in ("drawing", "seq") if k in step}
            if player.hold(info.get("drawing"), info.get("seq"), lambda: None):
                outcomes.append(Outcome("held"))
                continue
            planned = PlannedStroke(schedule, step["arrival_ms"], StrokeRef(**info))
            refusal = player.submit(planned)
            if refusal is not None:
                outcomes.append(Outcome(refusal.reason))
            else:
                accepted.append(planned)
                outcomes.append(Outcome("played", planned.start_ms, planned.schedule.duration_ms))
    finally:
        player.stop()
        backend.close()
    assert outcomes == _expected(case)


def test_start_is_arrival_or_the_tail_whichever_is_later() -> None:
    assert start_ms(10.0, NEVER_MS) == 10.0
    assert start_ms(10.0, 25.0) == 25.0
    assert start_ms(30.0, 25.0) == 30.0


def test_the_queue_waits_and_replans_after_a_cancel() -> None:
    queue = Queue()
    assert queue.wait_ms(0.0) == 0.0
    assert queue.place(0.0, 300.0) == 0.0
    assert queue.place(100.0, 300.0) == 300.0
    assert queue.wait_ms(100.0) == 500.0
    queue.replan([])
    assert queue.tail_ms == NEVER_MS and queue.place(150.0, 10.0) == 150.0
    queue.replan([(400.0, "a"), (700.0, "b")])
    assert queue.tail_drawing == "b"
    assert queue.place(200.0, 10.0) == 700.0


def test_seqs_are_remembered_per_drawing() -> None:
    queue = Queue()
    queue.remember("a", 3)
    assert queue.seen("a", 3) and not queue.seen("b", 3) and not queue.seen("a", 4)
    assert not queue.seen(None, 3) and not queue.seen("a", None)


def test_seen_seqs_keep_one_range_per_gap() -> None:
    seqs = SeenSeqs()
    for seq in (0, 1, 2, 5, 4, 3):
        seqs.add(seq)
    assert seqs.ranges == 1 and 5 in seqs and 6 not in seqs


MS = st.floats(0.0, 5_000.0)


@given(MS, MS, MS, st.floats(1.0, 200.0))
def test_catching_up_never_goes_below_the_floor_nor_lengthens(
    arrival_ms: float, tail_ms: float, duration_ms: float, floor_ms: float
) -> None:
    fast_ms = catch_up_ms(arrival_ms, tail_ms, duration_ms, floor_ms)
    assert fast_ms <= duration_ms
    assert fast_ms >= min(duration_ms, floor_ms)
    if tail_ms <= arrival_ms:
        assert fast_ms == duration_ms  # not behind: as it came
    elif duration_ms > floor_ms:
        # Shorter by how far behind, unless the floor stops it.
        assert fast_ms == max(floor_ms, duration_ms - (tail_ms - arrival_ms))


def test_the_queue_catches_up_only_behind_the_same_drawing() -> None:
    queue = Queue()
    queue.place(0.0, 300.0, "a", 0)
    assert queue.catch_up_ms(100.0, 300.0, 70.0, "a") == 100.0  # 200 ms behind
    assert queue.catch_up_ms(100.0, 300.0, 70.0, "b") == 300.0
    assert queue.catch_up_ms(100.0, 300.0, 70.0, None) == 300.0
    queue.place(100.0, 300.0)  # a stroke without a drawing is nobody's tail
    assert queue.catch_up_ms(200.0, 300.0, 70.0, "a") == 300.0


def test_the_player_plays_a_stroke_behind_its_drawing_faster_and_says_so() -> None:
    now_ms = [0.0]
    backend = SimBackend(PAPER)
    events = Events()
    # The clock jumps ahead to let every stroke play: no stall (which would refuse them).
    player = Player(backend, PAPER, clock=lambda: now_ms[0], on_event=events, stall_ms=math.inf)
    floor_ms = shortest_planned_ms(PAPER.shortest_burst_ms)
    # A long diagonal: many crossings, which must be thinned to fit the shorter time.
    stroke = Stroke((0.0, 0.0), (3.0, 2.0), 600.0)
    player.start()
    try:
        first = PlannedStroke(
            outline(stroke, PAPER), 0.0, StrokeRef(drawing="d", seq=0, received_at_ms=0.0)
        )
        assert player.submit(first) is None
        now_ms[0] = 10.0  # 590 ms behind: down to the floor
        second = PlannedStroke(
            outline(stroke, PAPER), 10.0, StrokeRef(drawing="d", seq=1, received_at_ms=10.0)
        )
        assert player.submit(second) is None
        now_ms[0] = 650.0  # 23.701 ms behind: shorter by that
        third = PlannedStroke(
            outline(stroke, PAPER), 650.0, StrokeRef(drawing="d", seq=2, received_at_ms=650.0)
        )
        assert player.submit(third) is None
        now_ms[0] = 10_000.0
        player._wake.set()
        events.wait_for(3)
    finally:
        player.stop()
        backend.close()
    assert (second.start_ms, third.start_ms) == (600.0, 600.0 + floor_ms)
    assert second.schedule.duration_ms == floor_ms
    assert third.schedule.duration_ms == pytest.approx(600.0 - (600.0 + floor_ms - 650.0))
    played = [e for e in events.events if isinstance(e, Played)]
    assert [e.compressed_ms for e in played] == [
        None,
        pytest.approx(600.0 - floor_ms),
        pytest.approx(600.0 + floor_ms - 650.0),
    ]
    assert all(type(e) is Played for e in played)  # caught up, never slowed
    for planned in (second, third):
        schedule = planned.planned()
        # The same path in less time: its ends kept, crossings thinned to fit, and every
        # command within the shorter stroke (its bursts may run on by the usual allowance).
        assert schedule.stroke.start == stroke.start and schedule.stroke.end == stroke.end
        assert schedule.thinned >= first.planned().thinned
        assert schedule.bursts[-1].start_ms + schedule.bursts[-1].duration_ms == pytest.approx(
            schedule.duration_ms
        )
        assert all(c.start_ms >= 0 and c.duration_ms > 0 for c in schedule.commands)


def test_a_stroke_planned_faster_before_the_lock_is_planned_again_when_the_queue_moved() -> None:
    # The player plans a waiting stroke faster before it takes its lock (the queue as it then
    # stood); when a cancel moved the tail meanwhile, the duration decided under the lock wins.
    player = Player(SimBackend(PAPER), PAPER)
    stroke = PlannedStroke(
        outline(Stroke((0.0, 0.0), (3.0, 2.0), 600.0), PAPER), 0.0, StrokeRef(received_at_ms=0.0)
    )
    stale = outline(Stroke((0.0, 0.0), (3.0, 2.0), 100.0), PAPER)
    assert player._catch_up(stroke, 250.0, stale) == 250.0
    assert stroke.schedule.duration_ms == 250.0 and stroke.compressed_ms == 350.0
    fresh = outline(Stroke((0.0, 0.0), (3.0, 2.0), 200.0), PAPER)
    again = PlannedStroke(
        outline(Stroke((0.0, 0.0), (3.0, 2.0), 600.0), PAPER), 0.0, StrokeRef(received_at_ms=0.0)
    )
    assert player._catch_up(again, 200.0, fresh) == 200.0 and again.schedule is fresh
