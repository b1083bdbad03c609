"""A sleeve without a broker, for dry runs: the events the real sleeve would publish for a
drawing, from its own planner, at once (no waiting for the strokes to play).

The real run sends through MQTT to ``feelmysign sleeve`` (or ``up``'s simulated
sleeve) and stores the events it publishes; this gives the same fields, so a
dry run's study file has the same shape as a real one.
"""

from __future__ import annotations

from typing import Any

from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.stroke import Stroke
from feelmysign.study.runner import Play


def offline_player(layout: Layout) -> Play:
    def play(strokes: list[Stroke]) -> list[dict[str, Any]]:
        events: list[dict[str, Any]] = []
        for stroke in strokes:
            base = {"drawing": stroke.drawing, "seq": stroke.seq, "simulated": True}
            try:
                schedule = plan(stroke, layout)
            except StrokeError as error:
                events.append({"type": "rejected", **base, "reason": error.reason})
                continue
            event: dict[str, Any] = {
                "type": "adjusted" if schedule.adjusted else "played",
                **base,
                "latency_ms": 0.0,
                "duration_ms": schedule.duration_ms,
                "commands": len(schedule.commands),
            }
            if schedule.adjusted:
                event["reason"] = schedule.adjusted.reason
                event["requested_duration_ms"] = schedule.adjusted.requested_duration_ms
            events.append(event)
        return events

    return play
