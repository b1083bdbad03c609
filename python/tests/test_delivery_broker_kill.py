"""SIGKILL of the real broker at a random point of a drawing: every stroke it acknowledged
to the sender is felt exactly once.

``feelmysign broker`` has Mosquitto save its state after every change
(``autosave_on_changes``), so what it acknowledged is on disk, and so is the
sleeve's session. Restarted on the same state, it delivers what the sleeve had not
acknowledged, and the sleeve drops what it had already played (by
``drawing``/``seq``). Both orders of return: the sender first (its strokes must
wait in the sleeve's saved session) and the sleeve first.

"Felt once" is counted by starts, not by events: events are QoS 1 too, and a copy of
one that the restarted broker delivers again is the same start (see ``delivery.starts``).
The sleeve's own count of the strokes it started must be the drawing's length.
"""

from __future__ import annotations

import os
import random
import signal
import time
from pathlib import Path

import pytest
from conftest import StartBroker
from delivery import (
    Sender,
    SleeveProcess,
    Watcher,
    delivery,
    felt_more_than_once,
    played,
    stroke,
    wait_for,
)

from feelmysign.broker import Broker

STROKES = 60
DURATION_MS = 100.0  # sent in real time: 6 s of drawing
# The pace rules would skip strokes the restart delayed: this test is about delivery.
NO_PACE = ("--max-age-ms", "3600000", "--max-lag-ms", "600000")


@pytest.mark.parametrize("first", ["sender", "sleeve"])
def test_every_stroke_the_broker_acknowledged_is_felt_once_after_a_sigkill(
    start_broker: StartBroker, tmp_path: Path, first: str
) -> None:
    kill_at = random.randrange(5, STROKES - 5)
    with delivery(start_broker, tmp_path, *NO_PACE) as (broker, watcher, sleeve, sender):
        start_s = time.monotonic()
        for seq in range(STROKES):
            if seq == kill_at:
                broker = _kill_and_restart(broker, start_broker, sleeve, sender, watcher, first)
            now_ms = time.time() * 1000
            sender.publish(seq, stroke(sender.drawing, seq, DURATION_MS, sent_at_ms=now_ms))
            # Drawing time, not a wait for an event: the pace is the point.
            time.sleep(max(0.0, start_s + (seq + 1) * DURATION_MS / 1000 - time.monotonic()))
        wait_for(lambda: len(sender.acked_seqs()) == STROKES, "every acknowledgement")
        wait_for(
            lambda: set(range(STROKES)) <= {e["seq"] for e in played(watcher.snapshot())},
            f"every acknowledged stroke to play (broker killed at stroke {kill_at})",
        )
        sleeve.stop()  # a copy still on its way would be played before the sleeve stops
        twice = felt_more_than_once(watcher.snapshot(), sender.drawing)
        assert not twice, f"played more than once (broker killed at stroke {kill_at}): {twice}"
        assert sleeve.started() == STROKES, f"broker killed at stroke {kill_at}"
        assert any(change["intensity"] > 0 for change in sleeve.changes())


def test_a_played_event_the_broker_sends_again_is_one_start_and_two_starts_are_two() -> None:
    """What a watcher received in a run where the broker was killed just after the sleeve's
    played event of stroke 37 went out: the event twice, the same bytes (QoS 1: the broker
    died before an acknowledgement of the event was recorded, and it came again after the
    restart), for a stroke the sleeve started once. A second start has a first command of
    its own, and counts."""
    drawing = "fe2e1a7e-6b17-4fb8-a81b-7f3301b55e25"
    event = {
        "type": "played",
        "drawing": drawing,
        "seq": 37,
        "received_at_ms": 1795684435817.3193,
        "first_command_at_ms": 1795684435856.3828,
    }
    other = {**event, "seq": 36, "first_command_at_ms": 1795684435756.1}
    assert felt_more_than_once([other, event, dict(event)], drawing) == {}
    again = {**event, "type": "adjusted", "first_command_at_ms": 1795684436012.5}
    assert felt_more_than_once([other, event, dict(event), again], drawing) == {
        37: [1795684435856.3828, 1795684436012.5]
    }


def _kill_and_restart(
    broker: Broker,
    start_broker: StartBroker,
    sleeve: SleeveProcess,
    sender: Sender,
    watcher: Watcher,
    first: str,
) -> Broker:
    """SIGKILL the broker, restart it on its state; let ``first`` come back before the other."""
    c = broker.credentials
    if first == "sender":
        sleeve.pause()  # stopped: it cannot come back before the sender
    else:
        sender.client.loop_stop()  # no network thread: it cannot come back before the sleeve
    assert broker.pid is not None
    os.kill(broker.pid, signal.SIGKILL)
    broker.stop()  # reaps it
    connections = sender.connections
    restarted_ms = time.time() * 1000
    broker = start_broker(state_dir=broker.state_dir, port=c.mqtt_port, ws_port=c.ws_port)
    if first == "sender":
        wait_for(lambda: sender.connections > connections, "the sender to come back")
        published = sender.published()
        wait_for(lambda: sender.acked_seqs() >= published, "the acknowledgements")
        sleeve.resume()
    else:
        wait_for(lambda: watcher.is_online(restarted_ms), "the sleeve to come back")
        sender.client.loop_start()
        wait_for(lambda: sender.connections > connections, "the sender to come back")
    return broker
