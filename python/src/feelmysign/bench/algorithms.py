"""Planner strokes per second and simplifier frames per second.

Baselines: parsing the stroke's legacy payload (what the sleeve does before
planning) for the planner; for the simplifier, the least per-frame work any
simplifier does (one distance per frame).
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence

from feelmysign.bench._timing import Rate, best_rate, each, row
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.protocol import format_legacy, parse
from feelmysign.simplify import AngleParams, AngleSimplifier, Sample, frames_from_samples
from feelmysign.stroke import Stroke

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
FRAME_BUDGET_US = 1e6 / 60  # one frame of a 60 fps drawing loop


def _strokes(count: int, seed: int = 7) -> list[Stroke]:
    rng = random.Random(seed)
    return [
        Stroke(
            (rng.uniform(0, 3), rng.uniform(0, 2)),
            (rng.uniform(0, 3), rng.uniform(0, 2)),
            rng.uniform(150, 2000),
        )
        for _ in range(count)
    ]


def _frames(count: int, seed: int = 11) -> list[Sample]:
    """A long wandering pen path at pointer-event rate, resampled at 60 fps."""
    rng = random.Random(seed)
    x, y, heading, samples = 600.0, 400.0, 0.0, []
    for k in range(count * 2):
        heading += rng.gauss(0, 0.15)
        x = min(max(x + 3 * math.cos(heading), 0), 1200)
        y = min(max(y + 3 * math.sin(heading), 0), 800)
        samples.append(Sample(k * 8.0, x, y))
    return frames_from_samples(samples, 60.0)[:count]


def one_distance_per_frame(frames: Sequence[Sample]) -> int:
    """The simplifiers' baseline: the least per-frame work any of them does. Returns the count."""
    total, last = 0.0, frames[0]
    for f in frames:
        total += math.sqrt((f.x - last.x) ** 2 + (f.y - last.y) ** 2)
        last = f
    return len(frames)


def planner_rates(count: int = 2000) -> tuple[Rate, Rate]:
    strokes = _strokes(count)
    payloads = [format_legacy(s) for s in strokes]
    # Each result let go at once, as the sleeve does: a list of 2,000 schedules kept alive
    # would have the garbage collector walk them again on every pass (a fifth of the time).
    baseline = best_rate(
        "baseline: parse legacy payload", lambda: each(lambda p: parse(p, PAPER), payloads)
    )
    planned = best_rate(
        "planner: plan one stroke (3 x 4 grid)", lambda: each(lambda s: plan(s, PAPER), strokes)
    )
    return baseline, planned


def simplifier_rates(count: int = 20_000) -> tuple[Rate, Rate]:
    frames = _frames(count)
    params = AngleParams(canvas_width_px=1200, canvas_height_px=800)

    def angle() -> int:
        simplifier = AngleSimplifier(params)
        for f in frames:
            simplifier.push(f)
        simplifier.end()
        return len(frames)

    return best_rate(
        "baseline: one distance per frame", lambda: one_distance_per_frame(frames)
    ), best_rate("angle simplifier: push one frame", angle)


def report() -> list[str]:
    lines = ["Algorithms (Python reference)"]
    base, planned = planner_rates()
    lines += [row(base, base), row(planned, base)]
    base, angle = simplifier_rates()
    lines += [row(base, base), row(angle, base)]
    lines.append(
        f"  angle simplifier uses {angle.us_per_item / FRAME_BUDGET_US:.4%} of a 60 fps frame"
    )
    return lines
