"""The stroke: one straight line sent to the sleeve, in grid units and milliseconds."""

from __future__ import annotations

import math
from dataclasses import dataclass

Point = tuple[float, float]


@dataclass(frozen=True)
class Stroke:
    """A straight stroke from ``start`` to ``end``.

    Points are in grid units: x is the column index (0..columns-1), y the row
    index (0..rows-1); actuators sit at integer coordinates. ``intensity`` None
    means the sleeve's default. ``drawing`` and ``seq`` let the sleeve order and
    chain the strokes of one drawing; ``sent_at_ms`` is the sender's wall clock.
    """

    start: Point
    end: Point
    duration_ms: float
    intensity: float | None = None
    drawing: str | None = None
    seq: int | None = None
    sent_at_ms: float | None = None

    def __init__(
        self,
        start: Point,
        end: Point,
        duration_ms: float,
        intensity: float | None = None,
        drawing: str | None = None,
        seq: int | None = None,
        sent_at_ms: float | None = None,
    ) -> None:
        # A frozen dataclass's own __init__ sets each field through object.__setattr__;
        # the sleeve makes two strokes per message before its first motor command.
        self.__dict__.update(
            start=start,
            end=end,
            duration_ms=duration_ms,
            intensity=intensity,
            drawing=drawing,
            seq=seq,
            sent_at_ms=sent_at_ms,
        )

    @property
    def length(self) -> float:
        """Length in grid units."""
        return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])

    def reversed(self) -> Stroke:
        """The same stroke drawn from its end back to its start."""
        return Stroke(
            start=self.end,
            end=self.start,
            duration_ms=self.duration_ms,
            intensity=self.intensity,
            drawing=self.drawing,
            seq=self.seq,
            sent_at_ms=self.sent_at_ms,
        )
