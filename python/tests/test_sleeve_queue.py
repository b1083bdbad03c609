"""The sleeve's queue against the shared vectors (testdata/queue), in its pure form and in
the player that plays on the sleeve."""

from __future__ import annotations

import threading
from typing import Any

import pytest
from vectors import load

from feelmysign.backends.sim import SimBackend
from feelmysign.events import Event, StrokeRef
from feelmysign.layout import Layout
from feelmysign.player import PlannedStroke, Player
from feelmysign.schedule import Schedule
from feelmysign.sleeve.queue import (
    NEVER_MS,
    Arrival,
    CancelAt,
    Outcome,
    Queue,
    SeenSeqs,
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

    def __call__(self, event: Event) -> None:
        with self.changed:
            self.count += 1
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
    assert replay(_steps(case)) == _expected(case)


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
                outcomes.append(Outcome("played", planned.start_ms, step["duration_ms"]))
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
    queue.replan([400.0, 700.0])
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
