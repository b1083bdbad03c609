"""Commands and schedules: what the planner produces and the player plays."""

from __future__ import annotations

from dataclasses import dataclass

from feelmysign.stroke import Stroke


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


@dataclass(frozen=True)
class Adjustment:
    """Why and how the planner changed a stroke (today: slowed it so every burst is long enough)."""

    reason: str
    requested_duration_ms: float
    duration_ms: float


@dataclass(frozen=True)
class Schedule:
    """The commands of one stroke, sorted by start time, then row, then column.

    No two commands on one actuator overlap in time. ``duration_ms`` is the
    stroke's duration after any adjustment: the last command ends there.
    """

    stroke: Stroke
    commands: tuple[Command, ...]
    duration_ms: float
    adjusted: Adjustment | None = None
