"""What the timeline tests share: a sleeve whose duty-cycle cap is quick to reach, and a
record of everything a timeline gave as it played."""

from __future__ import annotations

from feelmysign.layout import Layout
from feelmysign.timeline import Change, Due, Timeline

# A 2 s duty-cycle window: a few strokes reach its budget, where the paper's minute takes dozens.
TIGHT_WINDOW_MS = 2000.0


def tight_layout(max_duty_cycle: float) -> Layout:
    """The paper's 3 x 4 grid, strokes of at most 1 s, and a cap of ``max_duty_cycle`` of
    :data:`TIGHT_WINDOW_MS` at full drive."""
    return Layout(
        rows=3,
        columns=4,
        spacing_cm=3.0,
        max_stroke_duration_ms=1000,
        max_on_time_ms=1000,
        duty_cycle_window_ms=TIGHT_WINDOW_MS,
        max_duty_cycle=max_duty_cycle,
    )


class Played:
    """Every intensity change, started tag and capped tag a timeline gave, in order."""

    def __init__(self) -> None:
        self.changes: list[Change] = []
        self.started: list[object] = []
        self.capped: list[object] = []

    def take(self, due: Due) -> None:
        self.changes += due.changes
        self.started += due.started
        self.capped += [c.tag for c in due.capped]

    def play_out(self, timeline: Timeline) -> tuple[list[Change], list[object], list[object]]:
        """Pop the timeline at each of its next times until nothing is left; all it gave."""
        while (t_ms := timeline.next_ms()) is not None:
            self.take(timeline.pop_due(t_ms))
        return self.changes, self.started, self.capped
