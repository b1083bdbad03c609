"""Which of a design's trials the sleeve would slow: strokes briefer than its floor.

The sleeve plays no stroke faster than its floor (``apparent_motion.shortest_planned_ms`` of
the layout's shortest burst: 73.701 ms on the paper's ERM motors); a briefer one is slowed
to it, so the trial no longer plays at the design's speed. Allowed (a researcher may want
it), but said: ``study check`` warns, ``study new`` says so in one line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.plural import plural
from feelmysign.study.design import Design
from feelmysign.study.stimulus import stimulus_layout, trial_strokes

# The fastest unslowed speed is rounded down to this step, so that it truly plays unslowed.
SPEED_STEP_CM_S = 0.1


@dataclass(frozen=True)
class Slowed:
    """One shape level at one speed whose strokes the sleeve would slow."""

    shape: str
    level: str  # "at resolution 'fine'" or "in practice trial 2"
    speed_cm_s: float
    slowed: int  # strokes briefer than the floor
    strokes: int
    floor_ms: float
    fastest_cm_s: float | None  # the fastest speed at which the level plays unslowed

    def message(self) -> str:
        fastest = (
            f"it plays unslowed at {self.fastest_cm_s:g} cm/s or slower"
            if self.fastest_cm_s is not None and self.fastest_cm_s >= SPEED_STEP_CM_S
            else "no speed plays it unslowed"
        )
        return (
            f"{self.shape} {self.level} ({plural(self.strokes, 'stroke')}) at "
            f"{self.speed_cm_s:g} cm/s: {self.slowed} of its "
            f"{plural(self.strokes, 'stroke')} would be slowed by the sleeve (briefer than "
            f"its floor, {self.floor_ms:g} ms), so the "
            f"trial is not played at {self.speed_cm_s:g} cm/s; {fastest} (or give it fewer "
            "segments)"
        )


def slowed_trials(design: Design, base_dir: Path) -> list[Slowed]:
    """Every shape level x speed of the design, and every practice trial, with strokes the
    sleeve would slow.

    A recorded drawing played at the hand's timing (a design of one speed) has no speed to
    change: it is not checked here; the simplifier's floor setting keeps its strokes long."""
    layout = stimulus_layout(design.stimulus, base_dir)
    floor_ms = shortest_planned_ms(layout.shortest_burst_ms)

    def check(name: str, label: str, level: int | None, segments: int | None, speed: float) -> None:
        strokes = trial_strokes(
            design,
            base_dir,
            name,
            level=level,
            segments=segments,
            drawing="-",
            layout=layout,
            speed_cm_s=speed,
        )
        brief = sum(1 for s in strokes if s.duration_ms < floor_ms)
        if not brief:
            return
        # A stroke lasts its length over the speed; a point keeps its own duration.
        moving = [s.duration_ms for s in strokes if s.length > 0]
        fastest = None
        if moving and all(s.length > 0 or s.duration_ms >= floor_ms for s in strokes):
            exact = min(moving) * speed / floor_ms
            fastest = round(math.floor(exact / SPEED_STEP_CM_S) * SPEED_STEP_CM_S, 6)
        found.append(Slowed(name, label, speed, brief, len(strokes), floor_ms, fastest))

    found: list[Slowed] = []
    for shape in design.shapes:
        if shape.recording is not None and not design.speed_is_factor:
            continue
        for level, resolution in enumerate(design.resolutions):
            for speed in design.speeds:
                check(shape.name, f"at resolution {resolution!r}", level, None, speed)
    for index, practice in enumerate(design.practice):
        recorded = practice.level is not None
        if recorded and practice.speed_cm_s is None and not design.speed_is_factor:
            continue
        label = f"in practice trial {index + 1}"
        segments = None if recorded else practice.segments
        speed = design.practice_speed_cm_s(practice)
        check(practice.shape, label, practice.level, segments, speed)
    return found
