"""The order of one participant's trials: practice first, then every shape x resolution (x speed,
when the design lists several) once per repetition block, balanced across participants and
reproducible from the study's seed.

Two schemes (``[study] randomisation``):

- ``latin-square``: a balanced Latin square (Williams 1949) over the N = shapes x
  resolutions (x speeds) conditions. Participant p's block r follows row (p x R + r) mod N,
  so over N/R participants every condition appears equally often at every
  position, and follows every other condition equally often (first-order
  carry-over balanced; for odd N the square and its mirror are alternated).
- ``shuffled-blocks``: each block is the N conditions in a random order drawn
  from the study seed and the participant's number.

The order is stored with the participant when they are added, so a later change
of this code cannot change a running study.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from feelmysign.study.design import Design


@dataclass(frozen=True)
class PlannedTrial:
    block: str  # "practice" or "main"
    repetition: int  # 0 for practice; 1..R for main
    shape: str
    level: int | None  # index into the shape's levels; None for a library practice shape
    segments: int  # strokes the trial sends (a recording's: what its simplifier gives)
    # cm/s the shape is drawn at; None: a recorded drawing at its own (the hand's) timing, in a
    # design of one speed
    speed_cm_s: float | None = None


def williams_rows(n: int) -> list[list[int]]:
    """A balanced Latin square: n rows (n even) or 2n rows (n odd), each a permutation of 0..n-1."""
    first = [0]
    low, high = 1, n - 1
    take_low = True
    while len(first) < n:
        if take_low:
            first.append(low)
            low += 1
        else:
            first.append(high)
            high -= 1
        take_low = not take_low
    rows = [[(c + shift) % n for c in first] for shift in range(n)]
    if n % 2 == 1:
        rows += [list(reversed(row)) for row in rows]
    return rows


def participant_order(design: Design, number: int) -> list[PlannedTrial]:
    """Every trial of participant ``number`` (0 for the first one added), in order."""
    # Speed innermost: with one speed the conditions, and so every order, are those of a
    # design without speed as a factor.
    conditions = [
        (shape.name, level, shape.levels[level].strokes, _speed(design, shape.name, speed))
        for shape in design.shapes
        for level in range(len(design.resolutions))
        for speed in design.speeds
    ]
    trials = [
        PlannedTrial(
            "practice",
            0,
            p.shape,
            p.level,
            p.segments,
            p.speed_cm_s if p.speed_cm_s is not None else _speed(design, p.shape, design.speeds[0]),
        )
        for p in design.practice
    ]
    rng = random.Random(f"{design.seed}:{number}")
    rows = williams_rows(len(conditions))
    for repetition in range(1, design.repetitions + 1):
        if design.randomisation == "latin-square":
            row = rows[(number * design.repetitions + repetition - 1) % len(rows)]
            block = [conditions[i] for i in row]
        else:
            block = list(conditions)
            rng.shuffle(block)
        trials += [PlannedTrial("main", repetition, s, lv, n, v) for s, lv, n, v in block]
    return trials


def _speed(design: Design, shape: str, speed: float) -> float | None:
    """A trial's speed; None for a recorded drawing in a design of one speed, which keeps the
    timing it was recorded with (``stimulus.trial_strokes``)."""
    recorded = any(s.name == shape and s.recording is not None for s in design.shapes)
    return None if recorded and not design.speed_is_factor else speed
