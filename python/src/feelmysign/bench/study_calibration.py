"""Calibration of the study analysis at 4, 8, 12 and 24 participants, on simulated studies of the
paper's design with a known truth:

- the shape test's false-positive rate: no shape effect (each trial's accuracy depends only
  on its number of strokes and the participant), the share of studies with p < 0.05
  (a calibrated test: 0.05); below the test's minimum it is refused, never run;
- the coverage of the needed resolution's reported 95% interval (the parametric bootstrap
  with the participants' spread), a true curve inside the paper's range (75% at 6.9
  strokes, participants' SD 0.3 doublings).

Each share with its own 95% Wilson interval. Not part of ``make test`` or ``make bench``:

    make bench-study-calibration                           # 400 and 100 runs per size
    python -m feelmysign.bench.study_calibration [TEST_RUNS] [COVERAGE_RUNS] [--sizes 12 24]
    python -m feelmysign.bench.study_calibration 0 0 --speed-runs 200 --sizes 8 12

``--speed-runs``: with speed as a factor of the design, the speed test's false-positive rate
(no speed effect) and the shape test's with a speed effect (no shape effect).

A column with 0 runs is left out (``0 100``: the coverage alone). Each size's studies are
seeded by the size and the run's number, so a size measured alone gives the same figures
as in the full table.
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Iterator

# One BLAS thread, set before numpy loads it (the user's own setting wins). The shape test's
# model has a column per participant, wide enough for OpenBLAS to start its threads on every
# small product, which then spin: 5 to 7 times the CPU of one thread for the same studies on
# a shared 2-core machine, and the same p-values (they differ only in the statistic's last
# bits, far inside the test's 1e-9 tie tolerance).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # after the thread setting
import pandas as pd

from feelmysign.study.analysis.models import sign_flip_test, speed_flip_test
from feelmysign.study.analysis.recovery import coverage, describe, paper_truths
from feelmysign.study.analysis.wilson import wilson_interval

SIZES = (4, 8, 12, 24)
# The paper design's strokes per shape and resolution (deploy/studies/paper.toml).
PAPER_SHAPES = {
    "circle": (4, 6, 8, 16),
    "square": (4, 8, 12, 16),
    "triangle": (3, 6, 9, 12),
    "star": (5, 10, 15, 20),
    "heart": (4, 6, 8, 16),
    "line": (1, 2, 4, 8),
}
REPETITIONS = 3
PARTICIPANT_SD_LOG_ODDS = 1.0  # how much participants differ, as a random intercept
LAPSE = 0.02


def null_study(participants: int, rng: np.random.Generator) -> pd.DataFrame:
    """Answers with no shape effect: log odds 1.5 per doubling of strokes (75% near 4.7
    strokes, inside the tested ranges) plus each participant's own intercept."""
    rows = []
    for person in range(participants):
        own = rng.normal(0.0, PARTICIPANT_SD_LOG_ODDS)
        for shape, levels in PAPER_SHAPES.items():
            for strokes in levels:
                odds = 1.5 * (math.log2(strokes) - 2.5) + own
                p = LAPSE / 2 + (1 - LAPSE) / (1 + math.exp(-odds))
                for correct in rng.random(REPETITIONS) < p:
                    rows.append((f"P{person}", shape, strokes, float(correct)))
    frame = pd.DataFrame(rows, columns=["participant", "shape", "segments", "correct"])
    return frame.assign(log2_strokes=np.log2(frame["segments"].astype(float)))


def false_positives(participants: int, runs: int) -> tuple[int, int]:
    """(studies with p < 0.05, studies the test ran in) of ``runs`` seeded null studies."""
    rejected = ran = 0
    for run in range(runs):
        rng = np.random.default_rng([participants, run])
        test = sign_flip_test(null_study(participants, rng), seed=run)
        if test.p is not None:
            ran += 1
            rejected += test.p < 0.05
    return rejected, ran


SPEEDS_CM_S = (3.0, 6.0, 12.0)
SPEED_REPETITIONS = 2  # deploy/studies/speeds.toml's; the paper's shapes and resolutions


def speed_study(
    participants: int, rng: np.random.Generator, *, shape_odds: float, speed_odds: float
) -> pd.DataFrame:
    """The paper's shapes and resolutions at three speeds: log odds 1.5 per doubling of
    strokes plus each participant's own intercept, shapes spread over +-``shape_odds`` and
    each faster speed ``speed_odds`` log odds harder."""
    rows = []
    for person in range(participants):
        own = rng.normal(0.0, PARTICIPANT_SD_LOG_ODDS)
        for index, (shape, levels) in enumerate(PAPER_SHAPES.items()):
            easier = shape_odds * (2 * index / (len(PAPER_SHAPES) - 1) - 1)
            for strokes in levels:
                for step, speed in enumerate(SPEEDS_CM_S):
                    odds = 1.5 * (math.log2(strokes) - 2.5) + own + easier - speed_odds * step
                    p = LAPSE / 2 + (1 - LAPSE) / (1 + math.exp(-odds))
                    for correct in rng.random(SPEED_REPETITIONS) < p:
                        rows.append((f"P{person}", shape, strokes, speed, float(correct)))
    columns = ["participant", "shape", "segments", "speed", "correct"]
    frame = pd.DataFrame(rows, columns=columns)
    return frame.assign(log2_strokes=np.log2(frame["segments"].astype(float)))


def speed_false_positives(participants: int, runs: int) -> tuple[tuple[int, int], tuple[int, int]]:
    """Of ``runs`` seeded studies: (p < 0.05, ran) for the speed test with no speed effect
    (shapes differing), and for the shape test with no shape effect (speeds differing)."""
    speed = shape = ran = 0
    for run in range(runs):
        rng = np.random.default_rng([participants, run, 1])
        data = speed_study(participants, rng, shape_odds=1.0, speed_odds=0.0)
        speed_test = speed_flip_test(data, seed=run)
        data = speed_study(participants, rng, shape_odds=0.0, speed_odds=0.8)
        shape_test = sign_flip_test(data, seed=run)
        if speed_test.p is not None and shape_test.p is not None:
            ran += 1
            speed += speed_test.p < 0.05
            shape += shape_test.p < 0.05
    return (speed, ran), (shape, ran)


def report(
    test_runs: int,
    coverage_runs: int,
    sizes: tuple[int, ...] = SIZES,
    speed_runs: int = 0,
) -> Iterator[str]:
    if test_runs > 0:
        yield from _test_report(test_runs, sizes)
    if coverage_runs > 0:
        yield from _coverage_report(coverage_runs, sizes)
    if speed_runs > 0:
        yield from _speed_report(speed_runs, sizes)


def _speed_report(runs: int, sizes: tuple[int, ...]) -> Iterator[str]:
    yield (
        f"Speed as a factor (paper's shapes x 3 speeds x {SPEED_REPETITIONS} repetitions), "
        f"{runs} studies per size: share with p < 0.05 (nominal 0.05) of the speed test with no "
        "speed effect (shapes differing), and of the shape test with no shape effect (each "
        "faster speed 0.8 log odds harder)"
    )
    for size in sizes:
        (speed, ran), (shape, _) = speed_false_positives(size, runs)
        if not ran:
            yield f"  {size:>2} participants: refused in every study (below the minimum)"
            continue
        speed_low, speed_high = wilson_interval(speed, ran)
        shape_low, shape_high = wilson_interval(shape, ran)
        yield (
            f"  {size:>2} participants: speed test {speed / ran:.3f} ({speed_low:.3f} to "
            f"{speed_high:.3f}); shape test {shape / ran:.3f} ({shape_low:.3f} to {shape_high:.3f})"
        )


def _test_report(test_runs: int, sizes: tuple[int, ...]) -> Iterator[str]:
    yield (
        f"Shape test (sign-flip over participants), paper design, no shape effect, "
        f"{test_runs} studies per size: share with p < 0.05 (nominal 0.05)"
    )
    for size in sizes:
        rejected, ran = false_positives(size, test_runs)
        if not ran:
            yield f"  {size:>2} participants: refused in every study (below the minimum)"
            continue
        low, high = wilson_interval(rejected, ran)
        yield f"  {size:>2} participants: {rejected / ran:.3f} ({low:.3f} to {high:.3f})"


def _coverage_report(coverage_runs: int, sizes: tuple[int, ...]) -> Iterator[str]:
    name, truth = next(iter(paper_truths(0.75, 0.3).items()))
    yield (
        f"Needed resolution ({name}, participants' SD 0.3 doublings), {coverage_runs} studies "
        "per size, 200 bootstrap samples: share whose reported 95% interval covers the truth"
    )
    for size in sizes:
        result = coverage(coverage_runs, truth=truth, participants=size, samples=200)
        yield f"  {size:>2} participants: {describe(result, 'bootstrap')}"


DESCRIPTION = (
    "Calibration of the study analysis on simulated studies of the paper's design with a "
    "known truth: the shape test's false-positive rate, the coverage of the needed "
    "resolution's reported 95% interval and, with --speed-runs, the speed test's "
    "false-positive rate and the shape test's with a speed effect; each share with its 95% "
    "Wilson interval (docs/research.md, docs/study.md)."
)


def main() -> None:
    parser = argparse.ArgumentParser(description=DESCRIPTION)
    parser.add_argument(
        "test_runs", type=int, nargs="?", default=400, help="studies per size for the shape test"
    )
    parser.add_argument(
        "coverage_runs",
        type=int,
        nargs="?",
        default=100,
        help="studies per size for the interval's coverage",
    )
    parser.add_argument(
        "--sizes",
        type=int,
        nargs="+",
        default=list(SIZES),
        metavar="PARTICIPANTS",
        help=f"numbers of participants (default: {' '.join(map(str, SIZES))})",
    )
    parser.add_argument(
        "--speed-runs",
        type=int,
        default=0,
        metavar="N",
        help="studies per size for the tests with speed as a factor (default 0: not run)",
    )
    args = parser.parse_args()
    if min(args.test_runs, args.coverage_runs) < 0 or min(args.sizes) < 1:
        parser.error("runs must be 0 or more and every size at least 1 participant")
    if args.speed_runs < 0:
        parser.error("--speed-runs must be 0 or more")
    for line in report(args.test_runs, args.coverage_runs, tuple(args.sizes), args.speed_runs):
        print(line, flush=True)


if __name__ == "__main__":
    main()
