"""The player's stall rule on a clock that jumps: strokes whose whole time passed while the
player did not run are refused as ``late`` with how late they were, and the warning names the
sleeve as the sleeve's other log lines do."""

from __future__ import annotations

import logging
import threading

import pytest

from feelmysign.backends.sim import SimBackend
from feelmysign.clock import wall_ms
from feelmysign.events import Event, Rejected, StrokeRef
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.player import STALL_MS, PlannedStroke, Player
from feelmysign.stroke import Stroke

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
STALL_FOR_MS = 5000.0


class Clock:
    """The player's clock (ms), moved by the test only."""

    def __init__(self, now_ms: float) -> None:
        self.now_ms = now_ms

    def __call__(self) -> float:
        return self.now_ms


def planned(received_ms: float, duration_ms: float, **ref: object) -> PlannedStroke:
    schedule = plan(Stroke((0.0, 0.0), (3.0, 0.0), duration_ms), PAPER)
    return PlannedStroke(schedule, received_ms, StrokeRef(**ref, received_at_ms=wall_ms()))  # type: ignore[arg-type]


def test_strokes_refused_after_a_stall_say_how_late_they_were(
    caplog: pytest.LogCaptureFixture,
) -> None:
    clock = Clock(1000.0)
    events: list[Event] = []
    answered = threading.Condition()

    def on_event(event: Event) -> None:
        with answered:
            events.append(event)
            answered.notify_all()

    backend = SimBackend(PAPER)
    player = Player(backend, PAPER, on_event=on_event, clock=clock, sleeve_id="s7")
    player.start()
    try:
        playing = planned(clock.now_ms, 300.0, drawing="a", seq=0)
        # Queued behind it: one admitted 12 ms behind its sender's time line, one without
        # sent_at_ms (no lag at admission: late only by the stall).
        behind = planned(clock.now_ms, 300.0, drawing="b", seq=0, sent_at_ms=1.0, lag_ms=12.0)
        legacy = planned(clock.now_ms, 300.0, topic="deviceOne/line")
        for stroke in (playing, behind, legacy):
            assert player.submit(stroke) is None
        assert behind.start_ms > clock.now_ms and legacy.start_ms > behind.start_ms
        with caplog.at_level(logging.WARNING, logger="feelmysign.player"):
            clock.now_ms += STALL_FOR_MS  # the player did not run for 5 s
            with answered:
                assert answered.wait_for(lambda: len(events) == 3, 10.0), events
            refused_at_ms = clock.now_ms
    finally:
        player.stop()
        backend.close()

    played, *others = events
    assert played.kind == "played"
    refused = [e for e in others if isinstance(e, Rejected) and e.reason == "late"]
    assert refused == others, others
    lags = {e.drawing: e.lag_ms for e in refused}
    assert lags == {
        "b": round(12.0 + refused_at_ms - behind.start_ms, 1),
        None: round(refused_at_ms - legacy.start_ms, 1),
    }
    assert all(lag is not None and lag > STALL_MS for lag in lags.values()), lags
    [said] = [r.getMessage() for r in caplog.records if "the player ran" in r.getMessage()]
    assert said.startswith("sleeve s7: the player ran"), said
    assert "2 stroke(s)" in said, said
