"""The dry runs' sleeve publishes what the real sleeve would: events its readers accept."""

from __future__ import annotations

import pytest

from feelmysign.events import Adjusted, Played, Rejected, event_from_json
from feelmysign.layout import Layout
from feelmysign.stroke import Stroke
from feelmysign.study.simulated_sleeve import offline_player

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)


def test_each_stroke_gets_the_event_a_real_sleeve_publishes_field_for_field() -> None:
    strokes = [
        Stroke((0.0, 0.0), (3.0, 0.0), 900.0, None, "d", 0),  # played as asked
        Stroke((0.0, 0.0), (1.0, 0.0), 10.0, None, "d", 1),  # too fast to feel: slowed
        Stroke((0.0, 0.0), (9.0, 0.0), 300.0, None, "d", 2),  # off the grid: refused
    ]
    events = offline_player(PAPER)(strokes)
    typed = [event_from_json(e) for e in events]
    # Read back and written again, each is the same object: no field a real sleeve lacks.
    assert [e.to_json() for e in typed] == events
    played, adjusted, rejected = typed
    assert type(played) is Played and played.seq == 0 and played.duration_ms == 900.0
    assert isinstance(adjusted, Adjusted) and adjusted.requested_duration_ms == 10.0
    assert isinstance(rejected, Rejected) and rejected.reason == "outside_grid"
    assert played.drawing == adjusted.drawing == rejected.drawing == "d"


def test_a_stroke_behind_its_drawing_catches_up_as_on_the_real_sleeve() -> None:
    # A brief stroke is slowed to the sleeve's floor, so the next one of its drawing arrives
    # while the sleeve is behind and plays faster by as much (the player's catch-up rule).
    strokes = [
        Stroke((0.0, 0.0), (1.0, 0.0), 30.0, None, "d", 0),
        Stroke((1.0, 0.0), (2.0, 0.0), 300.0, None, "d", 1),
        Stroke((2.0, 0.0), (3.0, 0.0), 300.0, None, "d", 2),
    ]
    slowed, caught_up, on_time = (event_from_json(e) for e in offline_player(PAPER)(strokes))
    assert isinstance(slowed, Adjusted) and slowed.compressed_ms is None
    # It ended that much after the next one arrived (times on the wall clock: to 1e-3 ms).
    behind_ms = slowed.duration_ms - 30.0
    assert isinstance(caught_up, Played) and caught_up.queued_ms == pytest.approx(
        behind_ms, abs=1e-3
    )
    assert caught_up.compressed_ms == pytest.approx(behind_ms, abs=1e-3)
    assert caught_up.duration_ms == pytest.approx(300.0 - behind_ms, abs=1e-3)
    # Caught up: the third starts when it arrives, as drawn, and is not shortened.
    assert isinstance(on_time, Played) and on_time.compressed_ms is None
    assert on_time.queued_ms == pytest.approx(0.0, abs=1e-3)
