"""A connection that drops while the sleeve holds strokes unplayed, then a ``kill -9`` of the
sleeve: nothing the broker acknowledged to the sender vanishes.

When the sleeve comes back, the broker sends again every stroke the sleeve had not
acknowledged, among them those still waiting in its player. Acknowledging such a copy at
once (as a duplicate) would let the broker forget a stroke that only the sleeve's memory
holds; the sleeve keeps the copy's acknowledgement until the stroke has played, so a
``kill -9`` right after the reconnect loses nothing: the broker delivers the rest again to
the restarted sleeve.
"""

from __future__ import annotations

import time
from contextlib import ExitStack
from pathlib import Path
from typing import Any

from conftest import StartBroker
from delivery import SleeveProcess, delivery, played, plays, stroke, wait_for

STROKES = 20
DURATION_MS = 500.0  # 10 s of playing: most strokes still wait when the connection drops
NO_PACE = ("--max-age-ms", "3600000", "--max-lag-ms", "600000")  # this test is about delivery


def drawing_of(drawing: str, seq: int) -> str:
    """The odd strokes in a second drawing: each then waits behind another drawing's stroke, so
    none catches up (plays faster) and the 20 strokes, all the broker keeps in flight to the
    sleeve, play for 10 s."""
    return drawing if seq % 2 == 0 else f"{drawing}-odd"


def both(events: list[dict[str, Any]], drawing: str) -> dict[int, int]:
    """How many times each stroke of the two drawings started, by seq (even and odd apart)."""
    return plays(events, drawing) | plays(events, drawing_of(drawing, 1))


def test_strokes_sent_again_after_a_reconnect_survive_a_sigkill_of_the_sleeve(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    with (
        delivery(start_broker, tmp_path, *NO_PACE) as (broker, watcher, first, sender),
        ExitStack() as later,
    ):
        c = broker.credentials
        for seq in range(STROKES):
            drawing = drawing_of(sender.drawing, seq)
            sender.publish(seq, stroke(drawing, seq, DURATION_MS, sent_at_ms=None))
        wait_for(lambda: len(sender.acked_seqs()) == STROKES, "the broker's acknowledgements")
        wait_for(lambda: len(played(watcher.snapshot())) >= 1, "the first stroke to play")

        # The connection drops: the broker stops (saving its state) and starts again.
        broker.stop()
        restarted_ms = time.time() * 1000
        broker = start_broker(state_dir=broker.state_dir, port=c.mqtt_port, ws_port=c.ws_port)
        wait_for(lambda: watcher.is_online(restarted_ms), "the sleeve to come back")
        # The broker sends the unacknowledged strokes again; wait until the sleeve has
        # handled the copy of the last one (its log names it, whatever it made of it).
        last = f"stroke {STROKES - 1} of drawing {drawing_of(sender.drawing, STROKES - 1)}"
        wait_for(lambda: last in first.log.read_text(), "the copies sent again")
        # What the sleeve made of them goes out before anything it says later: so once a
        # stroke that starts from now on is reported, the broker has every acknowledgement
        # the sleeve gave for the copies (those of strokes it played while the broker was
        # away among them), and the kill tests only what it still holds.
        handled_ms = time.time() * 1000
        wait_for(
            lambda: any(e["first_command_at_ms"] > handled_ms for e in played(watcher.snapshot())),
            "a stroke started after the copies",
        )
        first.kill()
        before = set(both(watcher.snapshot(), sender.drawing))
        assert len(before) < STROKES, "the drawing ended before the kill: nothing was tested"

        second = later.enter_context(
            SleeveProcess(broker.credentials_path, tmp_path / "second.jsonl", *NO_PACE)
        )
        wait_for(
            lambda: set(both(watcher.snapshot(), sender.drawing)) == set(range(STROKES)),
            f"every stroke to play (before the kill: {sorted(before)})",
        )
        second.stop()
        # Started (and so acknowledged) once: the restarted sleeve played none of them again.
        twice = {seq: n for seq, n in both(watcher.snapshot(), sender.drawing).items() if n > 1}
        assert not twice, f"played more than once: {twice}"
        assert any(change["intensity"] > 0 for change in second.changes())
