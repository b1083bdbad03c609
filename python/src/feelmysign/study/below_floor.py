"""Which of a study's conditions send strokes below the floor the sleeve advertises.

A sleeve started with a wearer's measured limits (``sleeve --wearer``) advertises them in its
retained status's ``floor`` (docs/protocol.md); senders keep their strokes at or above it. The
study does not: its strokes are its design, and a trial below the floor is still sent as
designed. The sleeve plays a stroke below a wearer's limits as sent (the wearer may not feel
it) and slows one briefer than its motors' own floor. The runner says once, before the first
trial, which conditions are below it and what to do (``feelmysign study run``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from feelmysign.events import StatusFloor
from feelmysign.plural import plural
from feelmysign.study.design import Design
from feelmysign.study.order import participant_order
from feelmysign.study.stimulus import stimulus_layout, trial_strokes


@dataclass(frozen=True)
class BelowFloor:
    """One condition (shape, resolution, speed; or a practice trial) with strokes below it."""

    condition: str  # "square at resolution 'fine', 30 cm/s", "practice trial 1 (line, ...)"
    below: int  # its strokes briefer than the floor's duration or shorter than its length
    strokes: int


def below_floor(design: Design, base_dir: Path, floor: StatusFloor) -> list[BelowFloor]:
    """Every condition of ``design`` (each shape x resolution x speed, and each practice
    trial) with strokes briefer than ``floor.min_duration_ms`` or shorter than
    ``floor.min_length``, made exactly as its trials are (``stimulus.trial_strokes``)."""
    layout = stimulus_layout(design.stimulus, base_dir)
    found: list[BelowFloor] = []
    seen: set[tuple[object, ...]] = set()
    practice = 0
    for planned in participant_order(design, 0):
        if planned.block == "practice":
            practice += 1
        else:
            key = (planned.shape, planned.level, planned.segments, planned.speed_cm_s)
            if key in seen:  # the same condition in a later repetition
                continue
            seen.add(key)
        strokes = trial_strokes(
            design,
            base_dir,
            planned.shape,
            level=planned.level,
            segments=planned.segments,
            drawing="-",
            layout=layout,
            speed_cm_s=planned.speed_cm_s,
        )
        below = sum(
            1
            for s in strokes
            if s.duration_ms < floor.min_duration_ms or math.dist(s.start, s.end) < floor.min_length
        )
        if not below:
            continue
        what = (
            f"{planned.shape} at resolution {design.resolutions[planned.level]!r}"
            if planned.level is not None
            else f"{planned.shape}, {plural(planned.segments, 'segment')}"
        )
        speed = "" if planned.speed_cm_s is None else f", {planned.speed_cm_s:g} cm/s"
        condition = f"{what}{speed}"
        if planned.block == "practice":
            condition = f"practice trial {practice} ({condition})"
        found.append(BelowFloor(condition, below, len(strokes)))
    return found


def below_floor_message(found: list[BelowFloor], floor: StatusFloor, sleeve_id: str) -> str:
    """The runner's one paragraph: the wearer's floor, the conditions below it, what the sleeve
    does with their strokes, and what to do."""
    listed = "; ".join(f"{b.condition}: {b.below} of {plural(b.strokes, 'stroke')}" for b in found)
    return (
        f"Warning: sleeve {sleeve_id}'s floor with wearer {floor.wearer}'s limits is strokes of "
        f"at least {floor.min_duration_ms:g} ms and {floor.min_length:g} grid units, and "
        f"{plural(len(found), 'condition')} of this study send strokes below it ({listed}). "
        "The study sends them as designed and the sleeve plays them as sent (it slows only what "
        "its motors cannot play), so the wearer may not feel them. To keep every trial within "
        "the wearer's limits, make a new study file from a design with fewer segments or a "
        "slower speed for these conditions; if these limits are not this participant's, start "
        "the sleeve without --wearer (or with theirs)."
    )
