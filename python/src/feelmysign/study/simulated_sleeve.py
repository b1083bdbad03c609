"""A sleeve without a broker, for dry runs: the events the real sleeve would publish for a
drawing, from its own planner, at once (no waiting for the strokes to play).

The real run sends through MQTT to ``feelmysign sleeve`` (or ``up``'s simulated
sleeve) and stores the events it publishes; this gives the same fields, so a
dry run's study file has the same shape as a real one.
"""

from __future__ import annotations

import time
from typing import Any

from feelmysign.errors import StrokeError
from feelmysign.events import Adjusted, Event, Played, Rejected, StrokeRef
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.stroke import Stroke
from feelmysign.study.runner import Play


def offline_player(layout: Layout) -> Play:
    def play(strokes: list[Stroke]) -> list[dict[str, Any]]:
        # Every stroke is received now and played at once, so each starts as it arrives:
        # no latency, no queue, no start error (the figures a dry run reports as 0).
        received_at_ms = round(time.time() * 1000, 3)
        events: list[dict[str, Any]] = []
        for stroke in strokes:
            ref = StrokeRef(
                drawing=stroke.drawing,
                seq=stroke.seq,
                sent_at_ms=stroke.sent_at_ms,
                received_at_ms=received_at_ms,
            )
            event: Event
            try:
                schedule = plan(stroke, layout)
            except StrokeError as error:
                event = Rejected(reason=error.reason, message=error.message, stroke=ref)
                events.append(event.to_json())
                continue
            played: dict[str, Any] = {
                "stroke": ref,
                "start_at_ms": received_at_ms,
                "first_command_at_ms": received_at_ms,
                "latency_ms": 0.0,
                "start_error_ms": 0.0,
                "queued_ms": 0.0,
                "duration_ms": schedule.duration_ms,
                "commands": len(schedule.commands),
            }
            if schedule.adjusted:
                event = Adjusted(
                    **played,
                    reason=schedule.adjusted.reason,
                    requested_duration_ms=schedule.adjusted.requested_duration_ms,
                )
            else:
                event = Played(**played)
            events.append(event.to_json())
        return events

    return play
