"""The planner on real strokes: the LASA drawings' strokes, timed and compared with their drawing.

Every one of the 210 LASA demonstrations (``feelmysign.research.lasa``) goes
through each simplifier at its defaults, on the paper's sleeve; every stroke it
sends is planned as the sleeve plans it. LASA pens move slowly, so the same
strokes are also planned as if drawn 2 and 4 times faster (durations divided).
Printed per simplifier and speed: how much longer the strokes play than they
were drawn (planned / drawn duration per stroke, mean and 95th percentile), how
many are slowed and how many thinned; then the cost of planning one of them
beside the legacy-payload parse of ``bench.algorithms``.

``python -m feelmysign.bench.planner_lasa`` prints this group alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from feelmysign.bench._timing import Rate, best_rate, each, row
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.planner import plan
from feelmysign.protocol import format_legacy, parse
from feelmysign.research.lasa import LasaDemo, load_lasa
from feelmysign.research.rerun import rerun
from feelmysign.simplify import ALGORITHMS
from feelmysign.simplify.registry import params_for
from feelmysign.stroke import Stroke

PERCENTILE = 95
SPEEDS = (1.0, 2.0, 4.0)  # drawing speed, as a multiple of the LASA pen's
# The cost of planning one stroke is timed on at most this many of a simplifier's strokes,
# spread evenly over all of them (every k-th): the window simplifier's 5,273 strokes give
# the same mean within the run-to-run spread, in a quarter of the time.
TIMED_STROKES = 1500
# Best of 3 runs, not 5: each run plans over a thousand strokes, so the best of more runs
# moves the figure less than the machine's noise does, and costs a minute.
TIMED_REPEATS = 3


@dataclass(frozen=True)
class TimeKept:
    """Planned against drawn duration over one simplifier's strokes."""

    strokes: int
    ratio_mean: float
    ratio_p95: float
    slowed: int
    thinned: int


def lasa_strokes(algorithm: str, demos: list[LasaDemo] | None = None) -> list[Stroke]:
    """The strokes one simplifier sends for all 210 drawings (``demos``: as loaded), at its
    defaults."""
    strokes = []
    for demo in load_lasa() if demos is None else demos:
        params = params_for(ALGORITHMS[algorithm], demo.recording, {})
        for item in rerun(demo.recording, params).segments:
            segment = item.segment
            if segment.dropped is None:
                strokes.append(Stroke(segment.start, segment.end, segment.duration_ms))
    return strokes


def time_kept(strokes: list[Stroke]) -> TimeKept:
    schedules = [plan(s, PAPER_SLEEVE) for s in strokes]
    ratios = np.array(
        [p.duration_ms / s.duration_ms for p, s in zip(schedules, strokes, strict=True)]
    )
    return TimeKept(
        strokes=len(strokes),
        ratio_mean=float(ratios.mean()),
        ratio_p95=float(np.percentile(ratios, PERCENTILE)),
        slowed=sum(p.adjusted is not None for p in schedules),
        thinned=sum(p.thinned > 0 for p in schedules),
    )


def report() -> list[str]:
    lines = ["Planner on the LASA strokes (210 drawings, each simplifier at its defaults)"]
    demos = load_lasa()  # read once for every simplifier
    for name in ALGORITHMS:
        strokes = lasa_strokes(name, demos)
        for speed in SPEEDS:
            kept = time_kept([faster(s, speed) for s in strokes])
            lines.append(
                f"  {name} x{speed:g} speed: {kept.strokes} strokes, planned / drawn duration "
                f"mean {kept.ratio_mean:.3f}, p{PERCENTILE} {kept.ratio_p95:.3f}; "
                f"slowed {kept.slowed}, thinned {kept.thinned}"
            )
        timed = evenly(strokes, TIMED_STROKES)
        which = "all" if len(timed) == len(strokes) else f"{len(timed)} evenly spread"
        lines.append(
            f"  {name}: planning timed on {which} of its {len(strokes)} strokes,"
            f" best of {TIMED_REPEATS} runs"
        )
        for speed in (SPEEDS[0], SPEEDS[-1]):
            base, planned = planner_rates(f"{name} x{speed:g}", [faster(s, speed) for s in timed])
            lines += [row(base, base), row(planned, base)]
    return lines


def evenly(strokes: list[Stroke], most: int) -> list[Stroke]:
    """At most ``most`` of ``strokes``, every k-th from the first (all of them if few)."""
    return strokes[:: -(-len(strokes) // most)] if strokes else strokes


def faster(stroke: Stroke, speed: float) -> Stroke:
    return Stroke(stroke.start, stroke.end, stroke.duration_ms / speed)


def planner_rates(name: str, strokes: list[Stroke]) -> tuple[Rate, Rate]:
    """Planning these strokes, beside parsing their legacy payloads (the sleeve's step before),
    each result let go at once as the sleeve does (``each``)."""
    payloads = [format_legacy(s) for s in strokes]
    baseline = best_rate(
        f"baseline: parse legacy payload ({name})",
        lambda: each(lambda p: parse(p, PAPER_SLEEVE), payloads),
        repeats=TIMED_REPEATS,
    )
    planned = best_rate(
        f"planner: plan one LASA stroke ({name})",
        lambda: each(lambda s: plan(s, PAPER_SLEEVE), strokes),
        repeats=TIMED_REPEATS,
    )
    return baseline, planned


if __name__ == "__main__":
    print("\n".join(report()))
