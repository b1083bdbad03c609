"""``kill -9`` of a real sleeve mid-drawing: nothing it acknowledged vanishes.

The sleeve acknowledges a stroke only once it has played it (or refused it with
an event), so the strokes it held unplayed when it died are delivered again by
the broker to the restarted sleeve, which plays them.
"""

from __future__ import annotations

import time
from contextlib import ExitStack
from pathlib import Path

import pytest
from conftest import StartBroker
from delivery import FLOOR_MS, SleeveProcess, by_seq, delivery, played, stroke, wait_for

# Sent at once, strokes longer than the floor would catch up: 80 at the floor are 5.9 s of
# playing, so most are still waiting at the kill.
STROKES = 80
DURATION_MS = FLOOR_MS
KILL_AFTER_PLAYED = 4


def test_a_killed_sleeve_loses_no_stroke_it_received(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    with (
        delivery(start_broker, tmp_path, sleeve_login=True) as (broker, watcher, first, sender),
        ExitStack() as later,
    ):
        for seq in range(STROKES):
            now_ms = time.time() * 1000
            sender.publish(seq, stroke(sender.drawing, seq, DURATION_MS, sent_at_ms=now_ms))
        wait_for(lambda: len(sender.acked_seqs()) == STROKES, "the broker's acknowledgements")
        wait_for(lambda: len(played(watcher.snapshot())) >= KILL_AFTER_PLAYED, "the first strokes")
        first.kill()
        before = by_seq(watcher.snapshot(), sender.drawing)
        assert len(before) < STROKES, "the drawing ended before the kill: nothing was tested"

        second = later.enter_context(
            SleeveProcess(broker.sleeve_credentials_path, tmp_path / "second.jsonl")
        )
        wait_for(
            lambda: len(by_seq(watcher.snapshot(), sender.drawing)) == STROKES,
            "an event for every stroke",
        )
        events = by_seq(watcher.snapshot(), sender.drawing)
        for seq in range(STROKES):
            kinds = [(e["type"], e.get("reason")) for e in events[seq]]
            assert any(kind in ("played", "adjusted", "rejected") for kind, _ in kinds), kinds
        replayed = [seq for seq in range(STROKES) if seq not in before]
        # What the first sleeve held unplayed, the second one felt: motors moved after restart.
        second_played = {e["seq"] for e in played(watcher.snapshot()) if e["seq"] in replayed}
        assert second_played, f"none of {replayed} played after the restart: {events}"
        assert any(change["intensity"] > 0 for change in second.changes())


# Strokes of a drawing drawn live, one every STEP_MS, each lasting STEP_MS: the pen's pace.
STEP_MS = 100.0
DOWN_S = 2.5  # how long the sleeve stays down while the drawing goes on: above max_lag_ms (1 s)


@pytest.mark.parametrize("stop", ["kill", "clean"])
def test_a_restarted_sleeve_catches_up_with_a_drawing_that_went_on(
    start_broker: StartBroker, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, stop: str
) -> None:
    """The strokes the broker held while the sleeve was down are measured against the time line
    the sleeve kept (feelmysign.sleeve.pace_memory): late by how long they were held, skipped
    until it has caught up, and the strokes drawn after the restart play in real time. Without
    the kept time line the first held stroke set a new one, the backlog played seconds late,
    and the strokes drawn after the restart waited behind it. The same after kill -9 and after
    a clean stop (SIGTERM: a service restarted in the middle of a drawing)."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "sleeve-state"))  # the processes' own

    def draw(seqs: range) -> None:
        for seq in seqs:
            sender.publish(seq, stroke(sender.drawing, seq, STEP_MS, sent_at_ms=time.time() * 1000))
            time.sleep(STEP_MS / 1000)

    with (
        delivery(start_broker, tmp_path, sleeve_login=True) as (broker, watcher, first, sender),
        ExitStack() as later,
    ):
        before = range(0, 5)
        draw(before)
        wait_for(lambda: set(before) <= set(by_seq(watcher.snapshot(), sender.drawing)), "5 events")
        time.sleep(0.2)  # the played events out, and the time line kept
        first.kill() if stop == "kill" else first.stop()
        held = range(5, 5 + round(DOWN_S * 1000 / STEP_MS))
        draw(held)
        wait_for(lambda: set(held) <= sender.acked_seqs(), "the broker holding the strokes")
        restarted_ms = time.time() * 1000
        later.enter_context(
            SleeveProcess(broker.sleeve_credentials_path, tmp_path / "second.jsonl")
        )
        # Every stroke sent before the sleeve is back was held: the strokes drawn after it are.
        wait_for(lambda: watcher.is_online(restarted_ms), "the sleeve to come back")
        after = range(held.stop, held.stop + 10)
        draw(after)
        wait_for(
            lambda: len(by_seq(watcher.snapshot(), sender.drawing)) == after.stop,
            "an event for every stroke",
        )
        events = by_seq(watcher.snapshot(), sender.drawing)

    def fates(seqs: range) -> list[str]:
        return [
            "late"
            if any(e.get("reason") == "late" for e in events[seq])
            else "played"
            if any(e["type"] in ("played", "adjusted") for e in events[seq])
            else str([(e["type"], e.get("reason")) for e in events[seq]])
            for seq in seqs
        ]

    assert fates(before) == ["played"] * len(before)
    # Held more than max_lag_ms (1 s) behind the drawing: skipped as late, from the first one.
    held_fates = fates(held)
    assert held_fates[:5] == ["late"] * 5, held_fates
    assert set(held_fates) <= {"late", "played"}, held_fates
    # Drawn after the restart: felt in real time, none skipped.
    assert fates(after) == ["played"] * len(after), (held_fates, fates(after))
