"""A sleeve whose process does not run for a while (stopped, starved) does not call played
the strokes whose whole time passed meanwhile: each would have had every command written at
once, felt as nothing. They are refused as late, and every stroke still gets one outcome."""

from __future__ import annotations

import signal
import subprocess
import time
import uuid
from typing import Any

from sleeve_watch import SleeveWatch, online

from feelmysign.bench.sleeve import sleeve_command
from feelmysign.broker import Broker
from feelmysign.player import STALL_MS
from feelmysign.stroke import Stroke

WAIT_S = 60.0
FIRST_MS, STROKES, DURATION_MS = 1500.0, 9, 300.0  # the first long: the rest arrive meanwhile
STALL_S = 2.5


def test_strokes_whose_time_passed_while_the_sleeve_was_stopped_are_late_not_played(
    broker: Broker,
) -> None:
    drawing = str(uuid.uuid4())
    with SleeveWatch(broker.credentials, "status", "events") as watch:
        sleeve = subprocess.Popen(
            sleeve_command(broker.credentials_path, "--no-legacy"),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            watch.next(online, "the sleeve online")
            for seq in range(STROKES):
                duration_ms = FIRST_MS if seq == 0 else DURATION_MS
                watch.send(Stroke((0, 1), (3, 1), duration_ms, 0.8, drawing, seq))

            def mine(name: str, body: dict[str, Any]) -> bool:
                return name == "events" and body.get("drawing") == drawing

            first = watch.next(mine, "the first stroke's event")
            assert first["type"] == "played" and first["seq"] == 0, first
            time.sleep(0.3)  # the other strokes reach the sleeve, queued behind the first
            stopped_wall_ms = time.time() * 1000
            sleeve.send_signal(signal.SIGSTOP)
            time.sleep(STALL_S)
            resumed_wall_ms = time.time() * 1000
            sleeve.send_signal(signal.SIGCONT)

            def answered() -> bool:
                seqs = {body.get("seq") for name, body in watch.history if mine(name, body)}
                return seqs >= set(range(STROKES))

            watch.wait_until(answered, "an event for every stroke")
            answered_wall_ms = time.time() * 1000
            sleeve.send_signal(signal.SIGTERM)
            _, errors = sleeve.communicate(timeout=WAIT_S)
        finally:
            sleeve.kill()
        assert sleeve.returncode == 0, errors
    events = [body for name, body in watch.history if mine(name, body)]
    by_seq: dict[int, list[dict[str, Any]]] = {}
    for event in events:
        by_seq.setdefault(event["seq"], []).append(event)
    assert all(len(group) == 1 for group in by_seq.values()), by_seq  # one outcome each
    # Received before the stop, the strokes were queued behind the first (played faster to
    # catch up with their drawing, or not): the stall, from within the first to well past the
    # queue's end, covers some whole. Those are refused as late; every stroke called played
    # started before the stall, or was still due when the sleeve ran again.
    queued = [
        seq for seq in range(1, STROKES) if by_seq[seq][0]["received_at_ms"] < stopped_wall_ms
    ]
    assert queued, by_seq  # the premise: the strokes reached the sleeve before it stopped
    late = [seq for seq in queued if by_seq[seq][0].get("reason") == "late"]
    assert late, (stopped_wall_ms, resumed_wall_ms, by_seq)
    for seq in late:
        refused = by_seq[seq][0]
        assert "did not run for" in refused["message"], refused
        # How late it was when refused, as any late refusal says: its planned start came
        # while the sleeve was stopped (else it would have started), and its whole time
        # passed before it was refused (at least the shortest stroke the sleeve plays).
        assert 73.0 < refused.get("lag_ms", 0.0) <= answered_wall_ms - stopped_wall_ms, refused
    for seq, (event,) in by_seq.items():
        if (
            event["type"] in ("played", "adjusted")
            and event["first_command_at_ms"] > stopped_wall_ms
        ):
            planned_end_ms = event["start_at_ms"] + event["duration_ms"]
            assert planned_end_ms >= resumed_wall_ms - STALL_MS - 50.0, (seq, event)
    # Said in the sleeve's log as its other lines are: naming the sleeve.
    said = [line for line in errors.splitlines() if "the player ran" in line]
    assert said and all(
        f"sleeve {broker.credentials.sleeve_id}: the player ran" in line for line in said
    ), errors
    assert "late" in said[0], said
