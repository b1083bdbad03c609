"""How a drawing is felt: each stroke planned as the sleeve plans it, played back to back.

The sleeve's player starts a stroke when it arrives or when the one before
it has finished, whichever is later, and the stroke then lasts its planned
duration, shorter when it arrived behind the strokes of its drawing (the
catch-up rule): the sleeve's queue (:class:`feelmysign.sleeve.queue.Queue`),
used here as the player uses it, after the sleeve's pace rules
(:class:`feelmysign.pace.PacePolicy`), which skip a stroke as ``late`` only when
even catching up leaves the sleeve too far behind. A recording is one drawing.
Here a stroke arrives when the simplifier let it go (``emitted_at_ms``; the
network is taken as instant), and each is planned by the real planner on the
sleeve's layout. From that:

- time on the skin: the planned durations of the strokes sent, added up,
  against the drawing time (press to release, added up over the paths);
- release to felt end: from the pointer's release to the end of the last
  motor command of the path's last stroke;
- pen to skin: for each stroke, from the moment its start was drawn to the
  moment the sleeve starts it;
- the schedules played, in order: what ``felt`` reads the felt path from;
- how much was caught up (the drawn durations less those played, and the
  strokes played faster) and how much skipped (``late``: strokes and their
  drawn durations).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.pace import PacePolicy
from feelmysign.planner import outline
from feelmysign.player import caught_up
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
    compressed: int = 0  # strokes played faster to catch up
    compressed_ms: float = 0.0  # by how much in all
    skipped: int = 0  # strokes skipped as late (the pace rule)
    skipped_ms: float = 0.0  # their planned durations, added up
    slowed: int = 0  # strokes the planner made longer than sent (briefer than the sleeve can play)

    @property
    def skin_ratio(self) -> float:
        return self.skin_ms / self.drawing_ms if self.drawing_ms > 0 else float("nan")


# A planned duration longer than the sent one by more than this was slowed (not rounding).
SLOWED_TOLERANCE_MS = 1e-6

DRAWING = "recording"  # one drawing per recording: its strokes catch up with each other


def simulate(
    segments: Sequence[PathSegment], paths: Sequence[Sequence[Sample]], layout: Layout
) -> Playback:
    """Plan and play the sent segments of one recording, in the order they were let go."""
    drawing_ms = sum(path[-1].t_ms - path[0].t_ms for path in paths if path)
    queue = Queue()
    pace = PacePolicy()
    floor_ms = shortest_planned_ms(layout.shortest_burst_ms)
    skin_ms = compressed_ms = skipped_ms = 0.0
    compressed = skipped = refused = slowed = 0
    felt_end: dict[int, float] = {}
    pen_to_skin: list[float] = []
    schedules: list[Schedule] = []
    for seq, item in enumerate(segments):
        segment = item.segment
        if segment.dropped is not None:
            continue
        try:
            given = outline(Stroke(segment.start, segment.end, segment.duration_ms), layout)
        except StrokeError:
            refused += 1
            continue
        if given.duration_ms > segment.duration_ms + SLOWED_TOLERANCE_MS:
            slowed += 1
        arrival_ms = segment.emitted_at_ms
        verdict = pace.check(  # as the sleeve's admission does, the network taken as instant
            drawing=DRAWING,
            seq=seq,
            sent_at_ms=arrival_ms,
            received_wall_ms=arrival_ms,
            start_wall_ms=arrival_ms + queue.wait_ms(arrival_ms),
            duration_ms=given.duration_ms,
        )
        if verdict.reason is not None:
            skipped += 1
            skipped_ms += given.duration_ms
            continue
        fast_ms = queue.catch_up_ms(arrival_ms, given.duration_ms, floor_ms, DRAWING)
        faster = caught_up(given, fast_ms, layout) if fast_ms < given.duration_ms else None
        if faster is not None:
            compressed += 1
            compressed_ms += given.duration_ms - faster.duration_ms
            given = faster
        schedule = given.schedule()
        start_ms = queue.place(arrival_ms, schedule.duration_ms, DRAWING, seq)
        last_command_ms = max((c.end_ms for c in schedule.commands), default=0.0)
        felt_end[item.path] = start_ms + max(schedule.duration_ms, last_command_ms)
        skin_ms += schedule.duration_ms
        pen_to_skin.append(start_ms - segment.start_ms)
        schedules.append(schedule)
    release = [
        felt_end[index] - paths[index][-1].t_ms for index in sorted(felt_end) if paths[index]
    ]
    return Playback(
        drawing_ms,
        skin_ms,
        tuple(release),
        tuple(pen_to_skin),
        refused,
        tuple(schedules),
        compressed,
        compressed_ms,
        skipped,
        skipped_ms,
        slowed,
    )
