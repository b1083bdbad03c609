"""``kill -9`` of a real sleeve mid-drawing: nothing it acknowledged vanishes.

The sleeve acknowledges a stroke only once it has played it (or refused it with
an event), so the strokes it held unplayed when it died are delivered again by
the broker to the restarted sleeve, which plays them.
"""

from __future__ import annotations

import time
from contextlib import ExitStack
from pathlib import Path

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
