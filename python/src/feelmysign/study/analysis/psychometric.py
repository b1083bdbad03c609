"""Psychometric function of accuracy against resolution, fitted per shape, and the resolution
needed for a criterion accuracy with a participant bootstrap interval (SQ2.3).

    p(n) = guess + (1 - guess - lapse) / (1 + exp(-slope * (log2(n) - midpoint)))

n is the number of strokes; resolution acts on a log scale (doubling the strokes of a
circle matters as much at 4 -> 8 as at 8 -> 16). ``guess`` is the chance of naming
the shape by luck (the design's guess_rate; free answers: about 0) and ``lapse`` the
rate of errors at any resolution (attention, a sneeze), fixed as in Wichmann & Hill
(2001) so that two parameters are fitted by maximum likelihood from per-level counts.
The needed resolution is where p reaches ``criterion``:

    log2(n_c) = midpoint + logit((criterion - guess) / (1 - guess - lapse)) / slope

Two 95% intervals are given. The profile-likelihood interval (every needed
resolution whose best curve is within chi2(1)/2 = 1.92 log-likelihood units of the
best fit; Venzon & Moolgavkar 1988) is the one reported: on the paper's design it
covers the true value in about 95% of simulated studies. The cluster bootstrap
(resampling participants, since one person's answers are not independent; bias-
corrected percentiles) is given beside it; with 12 participants it is too narrow
when the fitted slope comes out steep, and covers the truth in only about 87% of
runs (``python -m feelmysign.study.analysis.recovery`` prints both).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize
from scipy.stats import norm

LAPSE = 0.02  # Wichmann & Hill 2001: a small fixed lapse keeps the slope unbiased
SLOPE_BOUNDS = (0.05, 40.0)  # per doubling of strokes; 40 is a step, 0.05 is flat
BOOTSTRAP_SAMPLES = 1000


@dataclass(frozen=True)
class Fit:
    midpoint: float  # log2 strokes at the curve's midpoint
    slope: float  # per doubling
    guess: float
    lapse: float

    def accuracy(self, strokes: NDArray[np.float64] | float) -> NDArray[np.float64]:
        x = np.log2(strokes)
        core = 1.0 / (1.0 + np.exp(-self.slope * (x - self.midpoint)))
        return np.asarray(self.guess + (1.0 - self.guess - self.lapse) * core)

    def strokes_at(self, criterion: float) -> float:
        """Strokes needed for ``criterion`` accuracy (inf when the curve never reaches it)."""
        q = (criterion - self.guess) / (1.0 - self.guess - self.lapse)
        if not 0.0 < q < 1.0:
            return math.inf
        return float(2.0 ** (self.midpoint + math.log(q / (1 - q)) / self.slope))


# The likelihood is evaluated on a grid of (midpoint, slope), for every bootstrap sample at
# once (a matrix product), then the best point of the full data is polished by L-BFGS-B.
# A midpoint step of 1/64 doubling is 1% in strokes: finer than any study resolves.
MIDPOINT_STEP = 1 / 64
SLOPE_STEPS = 96


@dataclass(frozen=True)
class _Grid:
    midpoints: NDArray[np.float64]
    slopes: NDArray[np.float64]
    log_p: NDArray[np.float64]  # (levels, grid points)
    log_q: NDArray[np.float64]


def _grid(x: NDArray[np.float64], guess: float, lapse: float) -> _Grid:
    span = float(x.max() - x.min()) or 1.0
    # The midpoint may lie beyond the tested range, but not without limit: a flat curve
    # would otherwise drift to infinity.
    low, high = float(x.min()) - 2 * span, float(x.max()) + 2 * span
    midpoints = np.arange(low, high + MIDPOINT_STEP, MIDPOINT_STEP)
    slopes = np.geomspace(*SLOPE_BOUNDS, SLOPE_STEPS)
    m, s = np.meshgrid(midpoints, slopes, indexing="ij")
    m, s = m.ravel(), s.ravel()
    core = 1.0 / (1.0 + np.exp(-s[None, :] * (x[:, None] - m[None, :])))
    p = np.clip(guess + (1.0 - guess - lapse) * core, 1e-12, 1 - 1e-12)
    return _Grid(m, s, np.log(p), np.log1p(-p))


def fit_many(
    strokes: NDArray[np.float64],
    correct: NDArray[np.float64],
    total: NDArray[np.float64],
    *,
    guess: float = 0.0,
    lapse: float = LAPSE,
) -> list[Fit]:
    """Maximum-likelihood fits (on the grid) of many data sets over the same levels:
    ``correct`` and ``total`` are (data sets, levels)."""
    grid = _grid(np.log2(strokes), guess, lapse)
    fits: list[Fit] = []
    for start in range(0, len(correct), 64):  # chunks keep the matrix small
        k, n = correct[start : start + 64], total[start : start + 64]
        likelihood = k @ grid.log_p + (n - k) @ grid.log_q
        best = np.argmax(likelihood, axis=1)
        fits += [Fit(float(grid.midpoints[b]), float(grid.slopes[b]), guess, lapse) for b in best]
    return fits


def fit(
    strokes: NDArray[np.float64],
    correct: NDArray[np.float64],
    total: NDArray[np.float64],
    *,
    guess: float = 0.0,
    lapse: float = LAPSE,
) -> Fit:
    """Maximum-likelihood fit to per-level counts (``correct`` of ``total`` at ``strokes``)."""
    start = fit_many(strokes, correct[None, :], total[None, :], guess=guess, lapse=lapse)[0]
    x = np.log2(strokes)

    def negative_log_likelihood(theta: NDArray[np.float64]) -> float:
        midpoint, slope = theta
        core = 1.0 / (1.0 + np.exp(-slope * (x - midpoint)))
        p = np.clip(guess + (1.0 - guess - lapse) * core, 1e-12, 1 - 1e-12)
        return float(-np.sum(correct * np.log(p) + (total - correct) * np.log1p(-p)))

    span = float(x.max() - x.min()) or 1.0
    bounds = [(float(x.min()) - 2 * span, float(x.max()) + 2 * span), SLOPE_BOUNDS]
    result = minimize(
        negative_log_likelihood,
        np.array([start.midpoint, start.slope]),
        method="L-BFGS-B",
        bounds=bounds,
    )
    return Fit(float(result.x[0]), float(result.x[1]), guess, lapse)


@dataclass(frozen=True)
class Threshold:
    fit: Fit
    strokes: float  # at the criterion; inf when not reached
    low: float  # profile-likelihood 95% interval
    high: float
    boot_low: float  # cluster bootstrap 95% interval (bias-corrected percentiles)
    boot_high: float
    samples: int


PROFILE_DROP = 1.92  # chi2(1) at 95% / 2


def profile_interval(
    strokes: NDArray[np.float64],
    correct: NDArray[np.float64],
    total: NDArray[np.float64],
    *,
    criterion: float,
    guess: float,
    lapse: float,
) -> tuple[float, float]:
    """Needed resolutions of every curve within ``PROFILE_DROP`` of the best log-likelihood."""
    grid = _grid(np.log2(strokes), guess, lapse)
    q = (criterion - guess) / (1.0 - guess - lapse)
    needed = grid.midpoints + math.log(q / (1 - q)) / grid.slopes
    likelihood = correct @ grid.log_p + (total - correct) @ grid.log_q
    inside = needed[likelihood >= likelihood.max() - PROFILE_DROP]
    return float(2.0 ** inside.min()), float(2.0 ** inside.max())


def counts_by_level(
    strokes: NDArray[np.float64], correct: NDArray[np.float64], levels: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Correct and total per level, for one participant's or all answers."""
    k = np.array([correct[strokes == level].sum() for level in levels], dtype=float)
    n = np.array([(strokes == level).sum() for level in levels], dtype=float)
    return k, n


def threshold_with_interval(
    per_participant: list[tuple[NDArray[np.float64], NDArray[np.float64]]],
    levels: NDArray[np.float64],
    *,
    criterion: float,
    guess: float = 0.0,
    lapse: float = LAPSE,
    samples: int = BOOTSTRAP_SAMPLES,
    seed: int = 0,
) -> Threshold:
    """Fit to all participants' counts, and a cluster bootstrap over participants."""
    k_all = np.sum([k for k, _ in per_participant], axis=0)
    n_all = np.sum([n for _, n in per_participant], axis=0)
    used = n_all > 0
    best = fit(levels[used], k_all[used], n_all[used], guess=guess, lapse=lapse)
    rng = np.random.default_rng(seed)
    ks = np.array([k for k, _ in per_participant])
    ns = np.array([n for _, n in per_participant])
    picks = rng.integers(0, len(per_participant), (samples, len(per_participant)))
    k_boot, n_boot = ks[picks].sum(axis=1), ns[picks].sum(axis=1)
    # Levels without a trial in a resample count as no data (0 of 0): the likelihood ignores them.
    fits = fit_many(levels[used], k_boot[:, used], n_boot[:, used], guess=guess, lapse=lapse)
    estimates = [f.strokes_at(criterion) for f in fits]
    boot_low, boot_high = bias_corrected_interval(np.array(estimates), best.strokes_at(criterion))
    low, high = profile_interval(
        levels[used], k_all[used], n_all[used], criterion=criterion, guess=guess, lapse=lapse
    )
    return Threshold(
        best, best.strokes_at(criterion), low, high, boot_low, boot_high, len(estimates)
    )


def bias_corrected_interval(
    values: NDArray[np.float64], estimate: float, level: float = 0.95
) -> tuple[float, float]:
    """The bias-corrected percentile interval (Efron 1981): the percentiles shifted by how far
    the bootstrap distribution's median sits from the estimate. A skewed, biased statistic
    such as a threshold on a log scale needs it; the plain percentile interval undercovers."""
    if len(values) == 0:
        return math.nan, math.nan
    below = (np.sum(values < estimate) + 0.5 * np.sum(values == estimate)) / len(values)
    z0 = float(norm.ppf(min(max(below, 1e-6), 1 - 1e-6)))
    z = float(norm.ppf(0.5 + level / 2))
    percentiles = 100 * norm.cdf([2 * z0 - z, 2 * z0 + z])
    low, high = np.percentile(values, percentiles)
    return float(low), float(high)
