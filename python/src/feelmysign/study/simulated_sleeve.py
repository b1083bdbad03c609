"""A sleeve without a broker, for dry runs: the events the real sleeve would publish for a
drawing, from its own rules, at once (no waiting for the strokes to play).

The real run sends through MQTT to ``feelmysign sleeve`` (or ``up``'s simulated
sleeve) and stores the events it publishes; this gives the same fields, so a
dry run's study file has the same shape as a real one. The strokes arrive as
the study's sleeve link sends them: at drawing pace (each when the one before
would have ended, as ``feelmysign send --pace realtime``), stamped with
``sent_at_ms`` then, over a network taken as instant. The sleeve's admission
(:mod:`feelmysign.sleeve.admission`) decides each one, and its queue
(:class:`feelmysign.sleeve.queue.Simulation`) says when it starts: a stroke
slowed to be felt delays the ones after it, and its ``latency_ms`` and
``queued_ms`` are that wait (the sleeve's own processing time taken as none).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import replace
from typing import Any

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.events import Event, Rejected
from feelmysign.layout import Layout
from feelmysign.player import PlannedStroke, caught_up, played_event
from feelmysign.protocol import QUEUE_FULL, format_json
from feelmysign.sleeve.admission import (
    MAX_BACKLOG_MS,
    MAX_PENDING,
    Admission,
    Admitted,
    Refused,
    queue_full,
)
from feelmysign.sleeve.queue import Simulation
from feelmysign.stroke import Stroke
from feelmysign.study.runner import Play


def offline_player(layout: Layout) -> Play:
    def play(strokes: list[Stroke]) -> list[dict[str, Any]]:
        admission = Admission(layout)
        simulation = Simulation()
        first_ms = round(time.time() * 1000, 3)
        offsets_ms = itertools.accumulate((s.duration_ms for s in strokes), initial=0.0)
        events: list[dict[str, Any]] = []
        # One offset more than strokes: the end of the last one.
        for index, (stroke, offset_ms) in enumerate(zip(strokes, offsets_ms, strict=False)):
            arrival_ms = first_ms + offset_ms  # sent and received at once: one clock for both
            payload = format_json(replace(stroke, sent_at_ms=round(arrival_ms)))
            verdict = admission.admit(
                payload,
                None,
                legacy=False,
                retained=False,
                holdable=True,
                received_at_ms=arrival_ms,
                received_wall_ms=arrival_ms,
                queue=simulation,
            )
            event = _placed(verdict, index, arrival_ms, simulation, layout)
            events.append(event.to_json())
        return events

    return play


def _placed(
    verdict: Admitted | Refused,
    index: int,
    arrival_ms: float,
    simulation: Simulation,
    layout: Layout,
) -> Event:
    """The event for an admitted stroke placed in the queue as the player places it (refused
    when the queue is full; played faster when it waits behind its drawing, as the player
    catches up), or for a refused one."""
    if isinstance(verdict, Refused):
        return Rejected(reason=verdict.reason, message=verdict.message, stroke=verdict.ref)
    outline, ref = verdict
    waiting = sum(1 for start, *_ in simulation.planned.values() if start > arrival_ms)
    full = queue_full(waiting, simulation.wait_ms(arrival_ms), MAX_PENDING, MAX_BACKLOG_MS)
    if full is not None:
        return Rejected(reason=QUEUE_FULL, message=full, stroke=ref)
    stroke = PlannedStroke(outline.schedule(), arrival_ms, ref)
    floor_ms = shortest_planned_ms(layout.shortest_burst_ms)
    fast_ms = simulation.queue.catch_up_ms(
        arrival_ms, stroke.planned().duration_ms, floor_ms, ref.drawing
    )
    faster = caught_up(outline, fast_ms, layout) if fast_ms < outline.duration_ms else None
    if faster is not None:
        stroke.compressed_ms = round(outline.duration_ms - faster.duration_ms, 3)
        stroke.schedule = faster.schedule()
    stroke.start_ms = simulation.place(
        index, arrival_ms, stroke.planned().duration_ms, ref.drawing, ref.seq
    )
    return played_event(stroke, stroke.start_ms)  # its first command at its start
