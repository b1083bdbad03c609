"""Cancelling: the timeline drops a stroke's plan, the player switches its motors off and
reports it, and the sleeve obeys a control message sent through a real Mosquitto."""

from __future__ import annotations

import subprocess
import sys
import time
import uuid
from collections.abc import Iterator
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from test_daemon import Running, _sender
from test_player import Events, _planned, started_player

from feelmysign.backends.sim import SimBackend
from feelmysign.broker import Broker
from feelmysign.control import Cancel, format_control
from feelmysign.layout import Layout
from feelmysign.player import Player
from feelmysign.protocol import format_json
from feelmysign.schedule import Command, Schedule
from feelmysign.stroke import Stroke
from feelmysign.timeline import Change, Timeline
from feelmysign.topics import control_topic, strokes_topic

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
WAIT_S = 10.0


def _one(row: int, column: int, start_ms: float, duration_ms: float) -> Schedule:
    command = Command(row, column, start_ms, duration_ms, 0.8)
    return Schedule(
        Stroke((0, 0), (1, 0), start_ms + duration_ms), (command,), start_ms + duration_ms
    )


# --- the timeline ---------------------------------------------------------------------------


def test_cancel_cuts_a_playing_stroke_and_drops_a_queued_one() -> None:
    timeline = Timeline(PAPER)
    timeline.add(_one(0, 0, 0, 1000), 0.0, tag="a")
    timeline.add(_one(0, 1, 0, 1000), 1000.0, tag="b")
    timeline.add(_one(2, 3, 0, 1000), 0.0, tag="other")
    timeline.pop_due(0.0)  # a and other switch on
    cut = timeline.cancel(lambda tag: tag in ("a", "b"), 300.0)
    assert cut.changes == [Change(300.0, 0, 0, 0.0)]
    assert (cut.started, cut.unstarted) == (["a"], ["b"])
    assert timeline.tags() == ["other"]
    # What remains is the other stroke's own plan: off at 1000 ms, nothing of a or b.
    rest: list[Change] = []
    while (t := timeline.next_ms()) is not None:
        rest += timeline.pop_due(t).changes
    assert rest == [Change(1000.0, 2, 3, 0.0)]


def test_cancel_keeps_a_motor_another_stroke_drives() -> None:
    timeline = Timeline(PAPER)
    timeline.add(_one(1, 1, 0, 1000), 0.0, tag="a")
    timeline.add(_one(1, 1, 0, 1000), 0.0, tag="b")
    timeline.pop_due(0.0)
    cut = timeline.cancel(lambda tag: tag == "a", 10.0)
    # Energies added (0.8² + 0.8²), now only b's 0.8 is left.
    assert [(c.row, c.column, round(c.intensity, 6)) for c in cut.changes] == [(1, 1, 0.8)]


def test_cancel_of_nothing_changes_nothing() -> None:
    timeline = Timeline(PAPER)
    timeline.add(_one(0, 0, 0, 100), 0.0, tag="a")
    cut = timeline.cancel(lambda tag: tag == "zzz", 0.0)
    assert (cut.changes, cut.started, cut.unstarted) == ([], [], [])
    assert timeline.tags() == ["a"]


# --- the player -----------------------------------------------------------------------------


@pytest.fixture
def player() -> Iterator[tuple[Player, SimBackend, Events]]:
    with started_player() as started:
        yield started


def _wait(condition: Any, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < deadline, what
        time.sleep(0.005)


def test_the_player_stops_a_drawing_at_once_and_reports_every_stroke(player: Any) -> None:
    player_, backend, events = player
    for seq in range(3):
        assert player_.submit(_planned(0, 0, 3, 2, 3000, drawing="d", seq=seq)) is None
    events.wait_for(1)  # stroke 0 is playing
    _wait(lambda: any(any(row) for row in backend.snapshot()), "no motor came on")
    player_.cancel(Cancel("d"), 1234.5)
    reported = events.wait_for(4)
    cancelled = [e for e in reported if e["type"] == "cancelled"]
    assert [(e["seq"], e["started"]) for e in cancelled] == [(0, True), (1, False), (2, False)]
    assert all(e["cancelled_at_ms"] == 1234.5 and e["drawing"] == "d" for e in cancelled)
    _wait(lambda: player_.idle, "the player still has work after the cancel")
    assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]


def test_cancel_one_drawing_leaves_another_playing(player: Any) -> None:
    player_, _, events = player
    assert player_.submit(_planned(0, 0, 3, 0, 2000, drawing="d", seq=0)) is None
    assert player_.submit(_planned(0, 2, 3, 2, 300, drawing="e", seq=0)) is None
    events.wait_for(1)
    player_.cancel(Cancel("d"), 1.0)
    reported = events.wait_for(3)  # d cancelled, e played after it (it moved up)
    kinds = sorted((e["drawing"], e["type"]) for e in reported)
    assert kinds == [("d", "cancelled"), ("d", "played"), ("e", "played")]


def test_strokes_accepted_after_a_cancel_are_not_touched(player: Any) -> None:
    player_, _, events = player
    player_.cancel(Cancel("*"), 1.0)
    assert player_.submit(_planned(0, 0, 1, 0, 100, drawing="d", seq=0)) is None
    assert [e["type"] for e in events.wait_for(1)] == ["played"]


# --- the sleeve, through the broker ----------------------------------------------------------

ThroughBroker = tuple[Running, mqtt.Client, str]


@pytest.fixture
def through_broker(broker: Broker) -> Iterator[ThroughBroker]:
    """A sleeve on a thread and a sender, both logged in to ``broker``, and the sleeve's id."""
    running = Running(broker.credentials)
    sender = _sender(broker.credentials)
    try:
        yield running, sender, broker.credentials.sleeve_id
    finally:
        sender.loop_stop()
        running.stop()


def test_a_control_message_stops_the_sleeve_and_later_strokes_stay_cancelled(
    through_broker: ThroughBroker,
) -> None:
    running, sender, sid = through_broker
    drawing = str(uuid.uuid4())
    for seq in range(3):
        stroke = Stroke((0.0, 0.0), (3.0, 2.0), 3000.0, 0.8, drawing, seq)
        sender.publish(strokes_topic(sid), format_json(stroke), qos=1).wait_for_publish(5)
    running.wait_events(1)
    control = format_control(Cancel(drawing))
    sender.publish(control_topic(sid), control, qos=1).wait_for_publish(5)
    events = running.wait_events(4)
    cancelled = [e for e in events if e["type"] == "cancelled"]
    assert [(e["seq"], e["started"]) for e in cancelled] == [(0, True), (1, False), (2, False)]
    _wait(lambda: running.sleeve.player.idle, "the sleeve still plays after the cancel")
    assert running.backend.snapshot() == [[0.0] * 4 for _ in range(3)]
    # A stroke of that drawing arriving later (held by the broker, say) is cancelled too.
    late = Stroke((0.0, 0.0), (1.0, 0.0), 300.0, 0.8, drawing, 3)
    sender.publish(strokes_topic(sid), format_json(late), qos=1).wait_for_publish(5)
    (after,) = running.wait_events(5)[4:]
    assert (after["type"], after["seq"], after["started"]) == ("cancelled", 3, False)
    # A control message the sleeve cannot read is rejected like a stroke.
    sender.publish(control_topic(sid), '{"v":1}', qos=1).wait_for_publish(5)
    (refused,) = running.wait_events(6)[5:]
    assert (refused["type"], refused["reason"]) == ("rejected", "missing_field")
    assert refused["topic"] == control_topic(sid)


# --- feelmysign stop ----------------------------------------------------------------------------


def test_feelmysign_stop_cancels_through_the_broker(
    broker: Broker, through_broker: ThroughBroker
) -> None:
    running, sender, sid = through_broker
    stroke = Stroke((0.0, 0.0), (3.0, 0.0), 5000.0, 0.8, "drawn-by-cli", 0)
    sender.publish(strokes_topic(sid), format_json(stroke), qos=1).wait_for_publish(5)
    running.wait_events(1)
    command = [
        sys.executable,
        "-m",
        "feelmysign",
        "stop",
        "--credentials",
        str(broker.credentials_path),
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert f"Stop sent to sleeve {sid}: everything." in done.stdout
    (event,) = running.wait_events(2)[1:]
    assert (event["type"], event["drawing"], event["started"]) == (
        "cancelled",
        "drawn-by-cli",
        True,
    )


def test_feelmysign_stop_refuses_a_bad_drawing_id() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "feelmysign", "stop", "a b"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 1
    assert done.stderr.startswith("Error: DRAWING = 'a b' is not allowed")


def test_a_stroke_felt_long_after_it_was_sent_is_logged_as_delayed(
    through_broker: ThroughBroker, caplog: pytest.LogCaptureFixture
) -> None:
    running, sender, sid = through_broker
    with caplog.at_level("WARNING", logger="feelmysign.daemon"):
        # Sent 5 s ago by the sender's clock: held at the broker while the sleeve was away.
        sent_at_ms = time.time() * 1000 - 5000
        stroke = Stroke((0.0, 0.0), (1.0, 0.0), 200.0, 0.8, "held", 0, sent_at_ms)
        sender.publish(strokes_topic(sid), format_json(stroke), qos=1).wait_for_publish(5)
        running.wait_events(1)
    # Delayed on the way, not "late" (the refusal of a stroke the sleeve is too far behind for).
    said = [r.getMessage() for r in caplog.records if "delayed" in r.getMessage()]
    assert len(said) == 1 and "stroke 1 of drawing held delayed by 5." in said[0], said
