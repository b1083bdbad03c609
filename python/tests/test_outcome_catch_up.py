"""What ``feelmysign send --wait`` tells the sender of a drawing whose strokes queued: how many
the sleeve played faster to catch up and by how much in all, how many it slowed to its floor,
and how many it skipped as late, apart from the other refusals; in the words of
``feelmysign.fates.CatchUp``, as the page's card and ``up``'s line say it."""

from __future__ import annotations

import json
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.outcome import DrawingOutcome

RECEIVED_AT_MS = 1795326267664.25
REF = {"topic": "feelmysign/s/strokes", "drawing": "d", "received_at_ms": RECEIVED_AT_MS}
TIMING = {
    "start_at_ms": RECEIVED_AT_MS,
    "first_command_at_ms": RECEIVED_AT_MS + 0.25,
    "latency_ms": 0.25,
    "start_error_ms": 0.031,
    "queued_ms": 0,
    "duration_ms": 417.5,
    "commands": 5,
}


def message(body: dict[str, Any]) -> mqtt.MQTTMessage:
    received = mqtt.MQTTMessage(topic=b"feelmysign/s/events")
    received.payload = json.dumps(body).encode()
    return received


def played(seq: int, **extra: Any) -> dict[str, Any]:
    return {"type": "played", "seq": seq, **REF, **TIMING, **extra}


def slowed(seq: int) -> dict[str, Any]:
    return {
        **played(seq, duration_ms=73.7),
        "type": "adjusted",
        "reason": "too_fast",
        "requested_duration_ms": 40,
    }


def rejected(seq: int, reason: str) -> dict[str, Any]:
    return {"type": "rejected", "reason": reason, "message": reason, "seq": seq, **REF}


def outcome_of(count: int, *bodies: dict[str, Any]) -> DrawingOutcome:
    outcome = DrawingOutcome("d", count)
    for body in bodies:
        outcome.on_message(None, None, message(body))  # type: ignore[arg-type]
    return outcome


def test_the_summary_says_what_was_played_faster_slowed_and_skipped_as_late() -> None:
    outcome = outcome_of(
        7,
        played(0),
        played(1, queued_ms=300, compressed_ms=143.25),
        played(1, queued_ms=300, compressed_ms=143.25),  # a copy of the event: counted once
        played(2, queued_ms=300, compressed_ms=1100.0),
        slowed(3),
        rejected(4, "late"),
        rejected(5, "late"),
        rejected(6, "outside_grid"),
    )
    summary = outcome.summary()
    assert summary.text() == (
        "The sleeve played 4 of 7 strokes (2 faster to catch up, 1.2 s shorter in all; "
        "1 slowed to the sleeve's floor), skipped 2 as late, refused 1 (outside_grid)"
    )
    assert summary.catch_up.late == 2 and summary.refused["late"] == 2
    assert not summary.all_played


def test_a_stroke_caught_up_and_then_cut_is_not_said_caught_up() -> None:
    cut = {
        "type": "cancelled",
        "reason": "cancelled",
        "message": "stopped",
        "seq": 1,
        **REF,
        "cancelled_at_ms": RECEIVED_AT_MS + 50,
        "started": True,
    }
    outcome = outcome_of(2, played(0), played(1, compressed_ms=95.0), cut)
    assert outcome.summary().text() == (
        "The sleeve played 1 of 2 strokes, cut 1 part-way (cancelled)"
    )


def test_a_drawing_played_as_it_came_reads_as_before() -> None:
    summary = outcome_of(2, played(0), played(1)).summary()
    assert summary.text() == "The sleeve played 2 of 2 strokes"
    assert summary.all_played


def test_each_stroke_skipped_as_late_is_said_so_as_the_summary_says_it() -> None:
    from feelmysign.cli.send import _answer_line
    from feelmysign.events import event_from_json

    late = {**rejected(1, "late"), "message": "the stroke would start 2.10 s after it was due"}
    other = rejected(2, "outside_grid")
    outcome = outcome_of(3, played(0), late, other)
    lines = [
        _answer_line(seq, 3, outcome.strokes[seq], event_from_json(body), json_lines=False)
        for seq, body in ((1, late), (2, other))
    ]
    assert lines == [
        "[2/3] skipped as late: the stroke would start 2.10 s after it was due",
        "[3/3] refused (outside_grid): outside_grid",
    ]
    assert "skipped 1 as late" in outcome.summary().text()


def test_a_strokes_line_says_its_wait_only_when_it_is_notable() -> None:
    # The wait behind the strokes before it is said when it is 5 % or more of the stroke's
    # duration (as fates.NOTABLE_CHANGE has it for a catch-up); a few ms of jitter is not.
    from feelmysign.cli.send import _answer_line

    outcome = outcome_of(
        3,
        played(0, queued_ms=4, latency_ms=5),
        played(1, queued_ms=80, latency_ms=81),
        played(2, queued_ms=21, latency_ms=22, duration_ms=417.25),
    )
    lines = [
        _answer_line(i, 3, s, s.played, json_lines=False)  # type: ignore[arg-type]
        for i, s in enumerate(outcome.strokes)
    ]
    assert lines[0] == "[1/3] played: 417.5 ms, latency 5 ms"
    assert lines[1] == (
        "[2/3] played: 417.5 ms, latency 81 ms (of which 80 ms waiting for the strokes before it)"
    )
    assert lines[2].startswith("[3/3] played: 417.2 ms, latency 22 ms (of which 21 ms waiting")


def test_a_strokes_line_says_when_it_was_delayed_on_the_way() -> None:
    # Held by the broker 3.4 s (a sleeve restarting): said, as the page and up say it; a stroke
    # that came in time is not.
    from feelmysign.cli.send import _answer_line

    sent_ms = TIMING["first_command_at_ms"] - 3400.0
    outcome = outcome_of(2, played(0), played(1, sent_at_ms=sent_ms))
    lines = [
        _answer_line(i, 2, s, s.played, json_lines=False)  # type: ignore[arg-type]
        for i, s in enumerate(outcome.strokes)
    ]
    assert "delayed" not in lines[0]
    assert lines[1].endswith(", delayed on the way by 3.4 s"), lines[1]
