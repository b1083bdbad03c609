"""Does the study's analysis recover known parameters? Coverage of its 95% intervals over many
seeded simulated studies (the tests run a few of them).

Long (about 50 minutes of one core at 400 runs), so not part of ``make bench``:

    make bench-study                                  # 400 runs per case
    python -m feelmysign.bench.study_recovery [RUNS]
"""

from __future__ import annotations

import random
import sys
from collections.abc import Iterator

from feelmysign.study.analysis.recovery import coverage, describe, paper_truths
from feelmysign.study.analysis.wilson import wilson_interval
from feelmysign.study.choices import DIRECTIONS, Dimension
from feelmysign.study.design_file import parse_design
from feelmysign.study.threshold import Procedure, SimulatedObserver

RUNS = 400
_DESIGN = """
[study]
name = "recovery"
seed = 1
repetitions = 1
resolutions = ["one"]
[[shapes]]
name = "line"
segments = [1]
[questionnaire]
items = ["x"]
"""


def _threshold_coverage(dimension: Dimension, truth: float, runs: int) -> int:
    settings = parse_design(_DESIGN).threshold
    covered = 0
    for run in range(runs):
        procedure, observer, rng = (
            Procedure(settings, dimension),
            SimulatedObserver(truth),
            random.Random(run),
        )
        while procedure.stop_reason() is None:
            value, direction = procedure.next_value(), rng.choice(sorted(DIRECTIONS))
            procedure.update(value, observer.respond(direction, value, rng) == direction)
        estimate = procedure.estimate()
        covered += estimate.low <= truth <= estimate.high
    return covered


def report(runs: int = RUNS) -> Iterator[str]:
    yield (
        f"Study analysis: 95% interval coverage over {runs} seeded simulated studies "
        "(each share with its own 95% Wilson interval)"
    )
    truths = [(sd, item) for sd in (0.0, 0.3) for item in paper_truths(0.75, sd).items()]
    for sd, (name, truth) in truths:
        result = coverage(runs, truth=truth)
        yield (
            f"  needed resolution, {name}, participant SD {sd:g}: parametric bootstrap with the "
            f"participants' spread (reported) "
            f"{describe(result, 'bootstrap')}, profile likelihood {describe(result, 'profile')}, "
            f"cluster bootstrap {describe(result, 'cluster')}"
        )
    for dimension, known, unit in (("length", 0.6, "grid units"), ("duration", 150.0, "ms")):
        covered = _threshold_coverage(dimension, known, runs)  # type: ignore[arg-type]
        low, high = wilson_interval(covered, runs)
        yield (
            f"  QUEST+ {dimension} threshold (true {known:g} {unit}): {covered / runs:.1%} "
            f"({low:.1%} to {high:.1%})"
        )


if __name__ == "__main__":
    for line in report(int(sys.argv[1]) if len(sys.argv) > 1 else RUNS):
        print(line, flush=True)
