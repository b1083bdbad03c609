"""Does the analysis recover what it should? Synthetic answers drawn from a psychometric
function with a known needed resolution, analysed as a study would be, many times.

``coverage`` counts how often the reported (profile-likelihood) interval, and the
bootstrap one, contain the true needed resolution; a trustworthy interval does
so in about 95% of seeded runs. Used by
the tests (a few runs) and by ``make bench`` / ``python -m feelmysign.study.analysis.recovery``
(many runs).

    python -m feelmysign.study.analysis.recovery --runs 200
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from feelmysign.study.analysis.psychometric import LAPSE, Fit, threshold_with_interval

# The paper's design for one shape: 4 resolutions, 3 repetitions, 12 participants.
PAPER_LEVELS = (4.0, 6.0, 8.0, 16.0)


@dataclass(frozen=True)
class Truth:
    fit: Fit
    criterion: float

    @property
    def strokes(self) -> float:
        return self.fit.strokes_at(self.criterion)


def synthetic_counts(
    truth: Truth,
    levels: NDArray[np.float64],
    *,
    participants: int,
    repetitions: int,
    rng: np.random.Generator,
) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Per participant: correct and total per level, each trial a Bernoulli draw."""
    p = truth.fit.accuracy(levels)
    totals = np.full(len(levels), float(repetitions))
    return [(rng.binomial(repetitions, p).astype(float), totals) for _ in range(participants)]


def coverage(
    runs: int,
    *,
    truth: Truth,
    levels: tuple[float, ...] = PAPER_LEVELS,
    participants: int = 12,
    repetitions: int = 3,
    samples: int = 200,
    seed: int = 0,
) -> tuple[float, float]:
    """Shares of ``runs`` seeded runs whose (profile, bootstrap) interval covers the truth."""
    grid = np.array(levels)
    covered = booted = 0
    for run in range(runs):
        rng = np.random.default_rng([seed, run])
        data = synthetic_counts(
            truth, grid, participants=participants, repetitions=repetitions, rng=rng
        )
        result = threshold_with_interval(
            data,
            grid,
            criterion=truth.criterion,
            guess=truth.fit.guess,
            lapse=truth.fit.lapse,
            samples=samples,
            seed=run,
        )
        covered += int(result.low <= truth.strokes <= result.high)
        booted += int(result.boot_low <= truth.strokes <= result.boot_high)
    return covered / runs, booted / runs


def paper_truths(criterion: float = 0.75) -> dict[str, Truth]:
    """Known needed resolutions inside the paper's range, steep and shallow."""
    return {
        "steep, 6 strokes": Truth(Fit(np.log2(5.0), 3.0, 0.0, LAPSE), criterion),
        "shallow, 8 strokes": Truth(Fit(np.log2(6.0), 1.5, 0.0, LAPSE), criterion),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200, help="seeded runs per truth (default 200)")
    parser.add_argument("--samples", type=int, default=300, help="bootstrap samples (default 300)")
    args = parser.parse_args()
    for name, truth in paper_truths().items():
        profile, boot = coverage(args.runs, truth=truth, samples=args.samples)
        print(
            f"needed resolution ({name}; true {truth.strokes:.2f} strokes at "
            f"{truth.criterion:.0%}), {args.runs} runs: profile-likelihood 95% interval covers it "
            f"in {profile:.1%}, cluster bootstrap in {boot:.1%}",
            flush=True,
        )


if __name__ == "__main__":
    main()
