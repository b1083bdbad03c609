"""Does the analysis recover what it should? Synthetic answers drawn from a psychometric
function with a known needed resolution, analysed as a study would be, many times.

``coverage`` counts how often each 95% interval (the reported parametric bootstrap
with the participants' spread, the profile likelihood, the cluster bootstrap)
contains the true needed resolution; a trustworthy interval does so in about 95%
of seeded runs. With ``participant_sd`` the participants differ: each one's curve
is shifted by a normal amount (SD in doublings of strokes), and the truth is where
the average participant's accuracy reaches the criterion. Used by the tests (a few
runs) and by ``make bench-study`` / ``python -m feelmysign.study.analysis.recovery``
(many runs; prints each share with its own 95% Wilson interval).

    python -m feelmysign.study.analysis.recovery --runs 400
    python -m feelmysign.study.analysis.recovery --runs 400 --participant-sd 0.3
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from feelmysign.study.analysis.psychometric import (
    LAPSE,
    Fit,
    Population,
    threshold_with_interval,
)
from feelmysign.study.analysis.wilson import wilson_interval

# The paper's design for one shape: 4 resolutions, 3 repetitions, 12 participants.
PAPER_LEVELS = (4.0, 6.0, 8.0, 16.0)


@dataclass(frozen=True)
class Truth:
    fit: Fit
    criterion: float
    participant_sd: float = 0.0  # doublings of strokes between participants' midpoints

    def accuracy(self, strokes: float) -> float:
        """The average participant's accuracy."""
        return float(Population(self.fit, self.participant_sd).accuracy(strokes))

    @property
    def strokes(self) -> float:
        return Population(self.fit, self.participant_sd).strokes_at(self.criterion)


def synthetic_counts(
    truth: Truth,
    levels: NDArray[np.float64],
    *,
    participants: int,
    repetitions: int,
    rng: np.random.Generator,
) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Per participant: correct and total per level, each trial a Bernoulli draw."""
    totals = np.full(len(levels), float(repetitions))
    out = []
    for _ in range(participants):
        shift = rng.normal(0.0, truth.participant_sd) if truth.participant_sd > 0 else 0.0
        own = Fit(truth.fit.midpoint + shift, truth.fit.slope, truth.fit.guess, truth.fit.lapse)
        out.append((rng.binomial(repetitions, own.accuracy(levels)).astype(float), totals))
    return out


@dataclass(frozen=True)
class Coverage:
    runs: int
    bootstrap: int  # runs whose interval covers the truth
    profile: int
    cluster: int

    def share(self, name: str) -> float:
        return int(getattr(self, name)) / self.runs


def coverage(
    runs: int,
    *,
    truth: Truth,
    levels: tuple[float, ...] = PAPER_LEVELS,
    participants: int = 12,
    repetitions: int = 3,
    samples: int = 1000,
    seed: int = 0,
) -> Coverage:
    """How many of ``runs`` seeded synthetic studies each interval covers the truth in."""
    grid = np.array(levels)
    target = truth.strokes
    counts = {"bootstrap": 0, "profile": 0, "cluster": 0}
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
        counts["bootstrap"] += int(result.boot_low <= target <= result.boot_high)
        counts["profile"] += int(result.low <= target <= result.high)
        counts["cluster"] += int(result.cluster_low <= target <= result.cluster_high)
    return Coverage(runs, **counts)


def paper_truths(criterion: float = 0.75, participant_sd: float = 0.0) -> dict[str, Truth]:
    """Known needed resolutions inside the paper's range, steep and shallow."""
    steep = Truth(Fit(np.log2(5.0), 3.0, 0.0, LAPSE), criterion, participant_sd)
    shallow = Truth(Fit(np.log2(6.0), 1.5, 0.0, LAPSE), criterion, participant_sd)
    return {
        f"steep, {steep.strokes:.1f} strokes": steep,
        f"shallow, {shallow.strokes:.1f} strokes": shallow,
    }


def describe(result: Coverage, name: str) -> str:
    low, high = wilson_interval(getattr(result, name), result.runs)
    return f"{result.share(name):.1%} ({low:.1%} to {high:.1%})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=400, help="seeded runs per truth (default 400)")
    parser.add_argument(
        "--samples", type=int, default=1000, help="bootstrap samples (default 1000)"
    )
    parser.add_argument(
        "--participant-sd",
        type=float,
        default=0.0,
        help="SD of the participants' curves in doublings of strokes (default 0: all alike)",
    )
    args = parser.parse_args()
    for name, truth in paper_truths(participant_sd=args.participant_sd).items():
        result = coverage(args.runs, truth=truth, samples=args.samples)
        print(
            f"needed resolution ({name} at {truth.criterion:.0%}, participant SD "
            f"{args.participant_sd:g}), {args.runs} runs, 95% intervals cover it in: parametric "
            f"bootstrap with the participants' spread {describe(result, 'bootstrap')}, profile "
            f"likelihood {describe(result, 'profile')}, cluster bootstrap "
            f"{describe(result, 'cluster')}",
            flush=True,
        )


if __name__ == "__main__":
    main()
