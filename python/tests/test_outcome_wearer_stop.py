"""What ``feelmysign send --wait`` makes of a stroke refused ``paused`` during the wearer's long
press and then ``cancelled`` by the wearer's stop: cancelled, by the wearer, once; the stop is
what the sender is told last, as the page's and the sleeve's fates count it."""

from __future__ import annotations

import json
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.outcome import DrawingOutcome

RECEIVED_AT_MS = 1795326267664.25
REF = {"topic": "feelmysign/s/strokes", "drawing": "d", "received_at_ms": RECEIVED_AT_MS}


def message(body: dict[str, Any]) -> mqtt.MQTTMessage:
    received = mqtt.MQTTMessage(topic=b"feelmysign/s/events")
    received.payload = json.dumps(body).encode()
    return received


def paused(seq: int) -> dict[str, Any]:
    return {"type": "rejected", "reason": "paused", "message": "paused", "seq": seq, **REF}


def cancelled(seq: int, by: str | None) -> dict[str, Any]:
    body = {
        "type": "cancelled",
        "reason": "cancelled",
        "message": "stopped",
        "seq": seq,
        **REF,
        "cancelled_at_ms": RECEIVED_AT_MS + 5,
        "started": False,
    }
    return body if by is None else {**body, "by": by}


def test_the_wearers_stop_after_a_pause_refusal_is_what_stands() -> None:
    told: list[tuple[int, str | None]] = []
    outcome = DrawingOutcome(
        "d", 3, lambda seq, stroke, _e: told.append((seq, stroke.refused_reason))
    )
    for body in (paused(0), cancelled(0, "wearer"), paused(1), cancelled(1, None), paused(2)):
        outcome.on_message(None, None, message(body))  # type: ignore[arg-type]
    stroke0, stroke1, stroke2 = outcome.strokes
    # The wearer's stop replaces the pause; a sender's cancel after the refusal changes nothing.
    assert (stroke0.refused_reason, stroke0.by_wearer) == ("cancelled", True)
    assert (stroke1.refused_reason, stroke1.by_wearer) == ("paused", False)
    assert (stroke2.refused_reason, stroke2.by_wearer) == ("paused", False)
    assert told == [(0, "paused"), (0, "cancelled"), (1, "paused"), (2, "paused")]
    summary = outcome.summary()
    assert summary.text() == "The sleeve played 0 of 3 strokes, refused 3 (paused x2, cancelled)"
    # A copy of the stop delivered again is not told twice.
    outcome.on_message(None, None, message(cancelled(0, "wearer")))  # type: ignore[arg-type]
    assert len(told) == 4
