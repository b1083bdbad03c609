"""How a drawing is felt: each stroke planned as the sleeve plans it, played back to back.

The sleeve's player starts a stroke when it arrives or when the one before
it has finished, whichever is later, and the stroke then lasts its planned
duration: the sleeve's queue (:class:`feelmysign.sleeve.queue.Queue`), used
here as the player uses it. Here a stroke arrives when the simplifier let it go
(``emitted_at_ms``; the network is taken as instant), and each is planned by
the real planner on the sleeve's layout. From that:

- time on the skin: the planned durations of the strokes sent, added up,
  against the drawing time (press to release, added up over the paths);
- release to felt end: from the pointer's release to the end of the last
  motor command of the path's last stroke;
- pen to skin: for each stroke, from the moment its start was drawn to the
  moment the sleeve starts it;
- the schedules played, in order: what ``felt`` reads the felt path from.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.schedule import Schedule
from feelmysign.simplify.registry import PathSegment
from feelmysign.simplify.segment import Sample
from feelmysign.sleeve.queue import Queue
from feelmysign.stroke import Stroke


@dataclass(frozen=True)
class Playback:
    drawing_ms: float
    skin_ms: float
    release_to_felt_end_ms: tuple[float, ...]  # one per path that sent a stroke
    pen_to_skin_ms: tuple[float, ...]  # one per stroke played
    refused: int  # strokes the planner refused (too long for the sleeve)
    schedules: tuple[Schedule, ...] = ()  # of the strokes played, in the order they play

    @property
    def skin_ratio(self) -> float:
        return self.skin_ms / self.drawing_ms if self.drawing_ms > 0 else float("nan")


def simulate(
    segments: Sequence[PathSegment], paths: Sequence[Sequence[Sample]], layout: Layout
) -> Playback:
    """Plan and play the sent segments of one recording, in the order they were let go."""
    drawing_ms = sum(path[-1].t_ms - path[0].t_ms for path in paths if path)
    queue = Queue()
    skin_ms = 0.0
    felt_end: dict[int, float] = {}
    pen_to_skin: list[float] = []
    schedules: list[Schedule] = []
    refused = 0
    for item in segments:
        segment = item.segment
        if segment.dropped is not None:
            continue
        try:
            schedule = plan(Stroke(segment.start, segment.end, segment.duration_ms), layout)
        except StrokeError:
            refused += 1
            continue
        start_ms = queue.place(segment.emitted_at_ms, schedule.duration_ms)
        last_command_ms = max((c.end_ms for c in schedule.commands), default=0.0)
        felt_end[item.path] = start_ms + max(schedule.duration_ms, last_command_ms)
        skin_ms += schedule.duration_ms
        pen_to_skin.append(start_ms - segment.start_ms)
        schedules.append(schedule)
    release = [
        felt_end[index] - paths[index][-1].t_ms for index in sorted(felt_end) if paths[index]
    ]
    return Playback(
        drawing_ms, skin_ms, tuple(release), tuple(pen_to_skin), refused, tuple(schedules)
    )
