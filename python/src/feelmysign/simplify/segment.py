"""What simplifiers take (samples) and give (segments)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from feelmysign.stroke import Point

NOT_ENOUGH_DISTANCE = "not_enough_distance"  # the paper's NotEnoughDistanceException
NOT_ENOUGH_DURATION = "not_enough_duration"  # the paper's NotEnoughDurationException


@dataclass(frozen=True)
class Sample:
    """One pointer reading: canvas pixels (origin top-left, y down), ms, pressure 0..1."""

    t_ms: float
    x: float
    y: float
    pressure: float = 0.5


@dataclass(frozen=True)
class Segment:
    """A straight piece of a path, in grid units, and when the simplifier let it go.

    ``dropped`` is None for a stroke to send, else the reason it is too short
    or too brief to feel. Sent and dropped segments of a path together join
    end to start, so a dropped one leaves a gap no longer than itself.
    """

    start: Point
    end: Point
    start_ms: float
    end_ms: float
    emitted_at_ms: float
    dropped: str | None = None
    # How many pieces too short to send were merged into this one (the window simplifier's).
    merged: int = 0
    # How long the sleeve is to play it, when not as long as it took to draw (the window
    # simplifier's: a stroke briefer than the sleeve's floor lasts the floor, and the strokes
    # after it give that time back; ``feelmysign.simplify.window.Merger``). None: as drawn.
    play_ms: float | None = None

    @property
    def duration_ms(self) -> float:
        """How long the stroke lasts on the sleeve: as drawn (end_ms - start_ms) unless paced."""
        return self.end_ms - self.start_ms if self.play_ms is None else self.play_ms

    @property
    def drawn_ms(self) -> float:
        """How long the piece took to draw."""
        return self.end_ms - self.start_ms

    @property
    def length(self) -> float:
        dx, dy = self.end[0] - self.start[0], self.end[1] - self.start[1]
        return math.sqrt(dx * dx + dy * dy)


def finish_segment(
    start: Point,
    end: Point,
    start_ms: float,
    end_ms: float,
    emitted_at_ms: float,
    *,
    min_length: float,
    min_duration_ms: float,
) -> Segment:
    """A finished piece of a path: sent, or dropped as too short (first) or too brief to feel.

    Length is tested first, as the paper does: a tap is "not enough distance".
    """
    segment = Segment(start, end, start_ms, end_ms, emitted_at_ms)
    if segment.length < min_length:
        return replace(segment, dropped=NOT_ENOUGH_DISTANCE)
    if segment.duration_ms < min_duration_ms:
        return replace(segment, dropped=NOT_ENOUGH_DURATION)
    return segment
