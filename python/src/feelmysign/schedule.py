"""Commands and schedules: what the planner produces and the player plays."""

from __future__ import annotations

from dataclasses import dataclass

from feelmysign.frozen_init import dict_init
from feelmysign.stroke import Stroke


@dict_init
@dataclass(frozen=True)
class Command:
    """One physical actuator on at a constant intensity, times relative to the stroke's start."""

    row: int
    column: int
    start_ms: float
    duration_ms: float
    intensity: float

    @property
    def end_ms(self) -> float:
        return self.start_ms + self.duration_ms


@dict_init
@dataclass(frozen=True)
class Burst:
    """One virtual actuator of a stroke: a point in grid units felt around its peak time.

    ``start_ms`` and ``duration_ms`` are the burst's onset and length, shared by
    the physical actuators that render it (funneling).
    """

    x: float
    y: float
    peak_ms: float
    start_ms: float
    duration_ms: float
    intensity: float


@dataclass(frozen=True)
class Adjustment:
    """Why and how the planner changed a stroke's duration: slowed to the least it plays in."""

    reason: str
    requested_duration_ms: float
    duration_ms: float


@dict_init
@dataclass(frozen=True)
class Schedule:
    """The commands of one stroke, sorted by start time, then row, then column.

    No two commands on one actuator overlap in time. ``duration_ms`` is the
    stroke's duration after any adjustment: the last command ends there.
    ``bursts`` are the virtual actuators the commands render, in stroke order;
    ``thinned`` counts those left out so that the stroke keeps its time.
    """

    stroke: Stroke
    commands: tuple[Command, ...]
    duration_ms: float
    adjusted: Adjustment | None = None
    bursts: tuple[Burst, ...] = ()
    thinned: int = 0


def stroke_to_json(stroke: Stroke) -> dict[str, object]:
    """A stroke as the JSON the CLI and the vectors use (optional fields only when set)."""
    data: dict[str, object] = {
        "start": list(stroke.start),
        "end": list(stroke.end),
        "duration_ms": stroke.duration_ms,
    }
    optional = {
        "intensity": stroke.intensity,
        "drawing": stroke.drawing,
        "seq": stroke.seq,
        "sent_at_ms": stroke.sent_at_ms,
    }
    data.update({k: v for k, v in optional.items() if v is not None})
    return data


def command_to_json(command: Command) -> dict[str, object]:
    return {
        "row": command.row,
        "column": command.column,
        "start_ms": command.start_ms,
        "duration_ms": command.duration_ms,
        "intensity": command.intensity,
    }


def schedule_to_json(schedule: Schedule, *, bursts: bool = False) -> dict[str, object]:
    """``{"stroke", "duration_ms", "commands", "adjusted", "thinned"}`` (and ``bursts``)."""
    adjusted = schedule.adjusted
    data: dict[str, object] = {
        "stroke": stroke_to_json(schedule.stroke),
        "duration_ms": schedule.duration_ms,
        "commands": [command_to_json(c) for c in schedule.commands],
        "adjusted": None
        if adjusted is None
        else {
            "reason": adjusted.reason,
            "requested_duration_ms": adjusted.requested_duration_ms,
            "duration_ms": adjusted.duration_ms,
        },
        "thinned": schedule.thinned,
    }
    if bursts:
        data["bursts"] = [
            {
                "x": b.x,
                "y": b.y,
                "peak_ms": b.peak_ms,
                "start_ms": b.start_ms,
                "duration_ms": b.duration_ms,
                "intensity": b.intensity,
            }
            for b in schedule.bursts
        ]
    return data
