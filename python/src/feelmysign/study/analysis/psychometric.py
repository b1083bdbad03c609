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

Three 95% intervals are given; the reported one is the **parametric bootstrap
with the participants' spread** (Wichmann & Hill 2001b; Efron & Tibshirani 1993,
ch. 6): participants may differ, each one's curve shifted along log2(strokes) by a
normal amount of SD ``spread`` (doublings). The curve and the spread are fitted by
maximum marginal likelihood of each participant's counts (Gauss-Hermite
quadrature over the shift). The SD is known only from the participants at hand,
so each new study of the same design (participants, trials per level) first draws
an SD from its profile likelihood (``spread_profile``: a flat prior, the posterior
on a grid) and takes the curve most likely at that SD; every simulated participant
then gets a shift of their own. Each study is pooled and refitted as the real data
were, and the bias-corrected percentiles of their needed resolutions, each taken
relative to the needed resolution of the population it was drawn from, are put
around the estimate. On synthetic studies of the paper's design it covers the true
value in 96 to 98% of seeded runs, whether participants are alike or differ
(``recovery``; a little wide: 12 participants never rule out an SD near 0). Beside it:

- the profile-likelihood interval (every needed resolution whose best curve is
  within chi2(1)/2 = 1.92 log-likelihood units of the best fit; Venzon &
  Moolgavkar 1988), about as good;
- the cluster bootstrap (participants resampled with replacement), which also
  carries any difference between participants but, with 12 of them, is too
  narrow: resampling n participants keeps only (n - 1)/n of their variance, and
  the needed resolution's skew does the rest (about 89-91% in the same runs).

When participants differ more than chance allows (the dispersion, Pearson
chi-square per degree of freedom of the per-participant counts, well above 1),
the profile and cluster intervals are too narrow; the reported one carries the
fitted spread.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq, minimize
from scipy.special import expit, logsumexp
from scipy.stats import norm

from feelmysign.study.choices import BOOTSTRAP_SAMPLES

LAPSE = 0.02  # Wichmann & Hill 2001: a small fixed lapse keeps the slope unbiased
SLOPE_BOUNDS = (0.05, 40.0)  # per doubling of strokes; 40 is a step, 0.05 is flat


def is_step(slope: float) -> bool:
    """The fit's slope at its upper bound (or not finite): the answers change from wrong to
    right between two tested resolutions (or never change), so no slope was measured."""
    return not math.isfinite(slope) or slope >= SLOPE_BOUNDS[1] * 0.999


def step_bracket(estimate: float, levels: NDArray[np.float64]) -> tuple[float, float]:
    """The tested resolutions on either side of ``estimate``: where the answers of a step
    (``is_step``) change, all that the data say of where the criterion is reached."""
    below, above = levels[levels < estimate], levels[levels > estimate]
    return (
        float(below.max()) if below.size else estimate,
        float(above.min()) if above.size else estimate,
    )


SPREAD_BOUNDS = (0.0, 3.0)  # SD of the participants' shifts, doublings of strokes


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


# Standard normal shifts and their weights, for averaging over participants.
_NODES, _WEIGHTS = np.polynomial.hermite_e.hermegauss(40)
_WEIGHTS = _WEIGHTS / _WEIGHTS.sum()
_FIT_NODES, _FIT_WEIGHTS = np.polynomial.hermite_e.hermegauss(20)
_FIT_LOG_WEIGHTS = np.log(_FIT_WEIGHTS / _FIT_WEIGHTS.sum())


@dataclass(frozen=True)
class Population:
    """Participants whose curves are ``fit`` shifted along log2(strokes) by a normal amount
    of SD ``spread`` (doublings of strokes); its accuracy is the average participant's."""

    fit: Fit
    spread: float = 0.0

    def accuracy(self, strokes: NDArray[np.float64] | float) -> NDArray[np.float64]:
        x = np.log2(np.asarray(strokes, dtype=float))
        if self.spread == 0:
            return self.fit.accuracy(strokes)
        shifted = _probability(
            x[..., None],
            self.fit.midpoint + self.spread * _NODES,
            np.asarray(self.fit.slope),
            self.fit.guess,
            self.fit.lapse,
        )
        return np.asarray(shifted @ _WEIGHTS)

    def strokes_at(self, criterion: float) -> float:
        """Strokes at which the average participant reaches ``criterion`` (inf: never)."""
        if self.spread == 0:
            return self.fit.strokes_at(criterion)
        f = self.fit
        if not f.guess < criterion < 1.0 - f.lapse:
            return math.inf
        reach = 40.0 / f.slope + 10.0 * self.spread + 1.0  # log2 strokes either side

        def gap(x: float) -> float:
            return float(self.accuracy(2.0**x)) - criterion

        low, high = f.midpoint - reach, f.midpoint + reach
        if gap(low) >= 0 or gap(high) <= 0:
            return math.inf
        return float(2.0 ** brentq(gap, low, high, xtol=1e-6))


# Each fit is a coarse grid search of (midpoint, slope), for many data sets at once (a matrix
# product), then a finer local grid around each best point: 1/128 doubling in midpoint (half a
# percent in strokes) and a slope step of 1%, finer than any study resolves. ``fit`` polishes
# the best fit of the real data further with L-BFGS-B.
MIDPOINT_STEP = 1 / 16
SLOPE_STEPS = 48
_LOCAL_STEPS = 17  # per parameter, across one coarse step either side
_CHUNK = 256


@dataclass(frozen=True)
class _Grid:
    midpoints: NDArray[np.float64]
    slopes: NDArray[np.float64]
    log_p: NDArray[np.float64]  # (levels, grid points)
    log_q: NDArray[np.float64]
    low: float  # midpoint bounds
    high: float


def _midpoint_bounds(x: NDArray[np.float64]) -> tuple[float, float]:
    # The midpoint may lie beyond the tested range, but not without limit: a flat curve
    # would otherwise drift to infinity.
    span = float(x.max() - x.min()) or 1.0
    return float(x.min()) - 2 * span, float(x.max()) + 2 * span


def _probability(
    x: NDArray[np.float64],
    midpoint: NDArray[np.float64],
    slope: NDArray[np.float64],
    guess: float,
    lapse: float,
) -> NDArray[np.float64]:
    core = expit(slope * (x - midpoint))
    return np.asarray(np.clip(guess + (1.0 - guess - lapse) * core, 1e-12, 1 - 1e-12))


def _grid(
    x: NDArray[np.float64],
    guess: float,
    lapse: float,
    step: float = MIDPOINT_STEP,
    slope_steps: int = SLOPE_STEPS,
) -> _Grid:
    low, high = _midpoint_bounds(x)
    midpoints = np.arange(low, high + step / 2, step)
    slopes = np.geomspace(*SLOPE_BOUNDS, slope_steps)
    m, s = np.meshgrid(midpoints, slopes, indexing="ij")
    m, s = m.ravel(), s.ravel()
    p = _probability(x[:, None], m[None, :], s[None, :], guess, lapse)
    return _Grid(m, s, np.log(p), np.log1p(-p), low, high)


def fit_many(
    strokes: NDArray[np.float64],
    correct: NDArray[np.float64],
    total: NDArray[np.float64],
    *,
    guess: float = 0.0,
    lapse: float = LAPSE,
) -> list[Fit]:
    """Maximum-likelihood fits of many data sets over the same levels: ``correct`` and
    ``total`` are (data sets, levels)."""
    x = np.log2(strokes)
    grid = _grid(x, guess, lapse)
    slope_ratio = math.log(SLOPE_BOUNDS[1] / SLOPE_BOUNDS[0]) / (SLOPE_STEPS - 1)
    local_m, local_s = np.meshgrid(
        np.linspace(-MIDPOINT_STEP, MIDPOINT_STEP, _LOCAL_STEPS),
        np.linspace(-slope_ratio, slope_ratio, _LOCAL_STEPS),
        indexing="ij",
    )
    dm, ds = local_m.ravel(), local_s.ravel()
    fits: list[Fit] = []
    for start in range(0, len(correct), _CHUNK):  # chunks keep the matrices small
        k, n = correct[start : start + _CHUNK], total[start : start + _CHUNK]
        best = np.argmax(k @ grid.log_p + (n - k) @ grid.log_q, axis=1)
        m = np.clip(grid.midpoints[best][:, None] + dm[None, :], grid.low, grid.high)
        s = np.clip(grid.slopes[best][:, None] * np.exp(ds[None, :]), *SLOPE_BOUNDS)
        p = _probability(x[None, None, :], m[:, :, None], s[:, :, None], guess, lapse)
        likelihood = np.einsum("bl,bgl->bg", k, np.log(p)) + np.einsum(
            "bl,bgl->bg", n - k, np.log1p(-p)
        )
        local = np.argmax(likelihood, axis=1)
        rows = np.arange(len(k))
        fits += [
            Fit(float(mm), float(ss), guess, lapse)
            for mm, ss in zip(m[rows, local], s[rows, local], strict=True)
        ]
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

    bounds = [_midpoint_bounds(x), SLOPE_BOUNDS]
    result = minimize(
        negative_log_likelihood,
        np.array([start.midpoint, start.slope]),
        method="L-BFGS-B",
        bounds=bounds,
    )
    return Fit(float(result.x[0]), float(result.x[1]), guess, lapse)


def _marginal_negative_log_likelihood(
    per_participant: list[tuple[NDArray[np.float64], NDArray[np.float64]]],
    levels: NDArray[np.float64],
    guess: float,
    lapse: float,
) -> tuple[Callable[[float, float, float], float], NDArray[np.float64]]:
    """-log L(midpoint, slope, spread) of each participant's counts per level, every
    participant's curve shifted by a normal amount (integrated out by Gauss-Hermite
    quadrature); and the log2 levels it uses (those with a trial)."""
    ks = np.array([k for k, _ in per_participant])
    ns = np.array([n for _, n in per_participant])
    used = ns.sum(axis=0) > 0
    x, ks, ns = np.log2(levels[used]), ks[:, used], ns[:, used]

    def negative_log_likelihood(midpoint: float, slope: float, spread: float) -> float:
        p = _probability(
            x[None, :], midpoint + spread * _FIT_NODES[:, None], np.asarray(slope), guess, lapse
        )  # (nodes, levels)
        per_node = ks @ np.log(p).T + (ns - ks) @ np.log1p(-p).T  # (participants, nodes)
        return float(-np.sum(logsumexp(per_node + _FIT_LOG_WEIGHTS[None, :], axis=1)))

    return negative_log_likelihood, x


def fit_population(
    per_participant: list[tuple[NDArray[np.float64], NDArray[np.float64]]],
    levels: NDArray[np.float64],
    *,
    guess: float = 0.0,
    lapse: float = LAPSE,
    start: Fit | None = None,
) -> Population:
    """Maximum marginal likelihood of each participant's counts per level, every participant's
    curve shifted by a normal amount (the shift integrated out by Gauss-Hermite quadrature):
    the participants' curve and the SD of their shifts. Levels without a trial are ignored."""
    negative_log_likelihood, x = _marginal_negative_log_likelihood(
        per_participant, levels, guess, lapse
    )
    if start is None:
        ks = np.array([k for k, _ in per_participant]).sum(axis=0)
        ns = np.array([n for _, n in per_participant]).sum(axis=0)
        start = fit(levels[ns > 0], ks[ns > 0], ns[ns > 0], guess=guess, lapse=lapse)
    bounds = [_midpoint_bounds(x), SLOPE_BOUNDS, SPREAD_BOUNDS]
    best: tuple[float, NDArray[np.float64]] | None = None
    for spread in (0.0, 0.3):  # from alike and from differing participants; the better wins
        result = minimize(
            lambda theta: negative_log_likelihood(*theta),
            np.array([start.midpoint, start.slope, spread]),
            method="L-BFGS-B",
            bounds=bounds,
        )
        if best is None or result.fun < best[0]:
            best = (float(result.fun), result.x)
    assert best is not None
    midpoint, slope, spread = best[1]
    return Population(Fit(float(midpoint), float(slope), guess, lapse), float(spread))


SPREAD_GRID = np.linspace(0.0, 1.2, 16)  # doublings; the profile's points


def spread_profile(
    per_participant: list[tuple[NDArray[np.float64], NDArray[np.float64]]],
    levels: NDArray[np.float64],
    start: Fit,
    *,
    guess: float = 0.0,
    lapse: float = LAPSE,
) -> tuple[list[Population], NDArray[np.float64]]:
    """At each SD of ``SPREAD_GRID``, the participants' curve of the highest marginal
    likelihood; and how plausible each SD is (the profile likelihood, normalised: with a flat
    prior on the SD, its posterior on the grid)."""
    negative_log_likelihood, x = _marginal_negative_log_likelihood(
        per_participant, levels, guess, lapse
    )
    bounds = [_midpoint_bounds(x), SLOPE_BOUNDS]
    theta = np.array([start.midpoint, start.slope])
    populations, log_likelihood = [], []
    for spread in SPREAD_GRID:
        result = minimize(
            lambda t, sd=float(spread): negative_log_likelihood(t[0], t[1], sd),
            theta,
            method="L-BFGS-B",
            bounds=bounds,
        )
        theta = result.x
        populations.append(
            Population(Fit(float(theta[0]), float(theta[1]), guess, lapse), float(spread))
        )
        log_likelihood.append(-float(result.fun))
    weights = np.exp(np.array(log_likelihood) - max(log_likelihood))
    return populations, weights / weights.sum()


@dataclass(frozen=True)
class Threshold:
    fit: Fit
    strokes: float  # at the criterion; inf when not reached
    boot_low: float  # parametric bootstrap 95% interval with the participants' spread
    boot_high: float  # (bias-corrected): the reported one
    low: float  # profile-likelihood 95% interval
    high: float
    cluster_low: float  # cluster bootstrap over participants, 95% (bias-corrected)
    cluster_high: float
    dispersion: float  # Pearson chi2 / df of the per-participant counts (1: as chance allows)
    samples: int
    population: Population  # the participants' curve and spread the bootstrap draws from


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
    # Finer than the fitting grid: the interval's ends are read off the grid itself.
    grid = _grid(np.log2(strokes), guess, lapse, step=1 / 64, slope_steps=96)
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


def dispersion(
    per_participant: list[tuple[NDArray[np.float64], NDArray[np.float64]]],
    best: Fit,
    levels: NDArray[np.float64],
) -> float:
    """How much more the participants differ than chance allows: the Pearson chi-square per
    degree of freedom of each participant's number of correct answers (over all levels)
    against what the fitted curve expects of anyone. About 1 when they differ only by chance;
    above 1 when they differ (overdispersion; Wichmann & Hill 2001a)."""
    p = best.accuracy(levels)
    chi2, people = 0.0, 0
    for k, n in per_participant:
        variance = float(np.sum(n * p * (1 - p)))
        if variance > 0:
            chi2 += (float(k.sum()) - float(np.sum(n * p))) ** 2 / variance
            people += 1
    return chi2 / (people - 1) if people > 1 else math.nan


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
    """Fit to all participants' counts; the parametric bootstrap (with the participants'
    spread), profile and cluster intervals."""
    ks = np.array([k for k, _ in per_participant])
    ns = np.array([n for _, n in per_participant])
    k_all, n_all = ks.sum(axis=0), ns.sum(axis=0)
    used = n_all > 0
    x, k_used, n_used = levels[used], k_all[used], n_all[used]
    best = fit(x, k_used, n_used, guess=guess, lapse=lapse)
    estimate = best.strokes_at(criterion)
    rng = np.random.default_rng(seed)
    # Parametric: the same participants and numbers of trials per level. Each study draws an SD
    # of the participants' shifts from its profile likelihood, and each simulated participant
    # answers by the curve most likely at that SD, shifted by a draw of their own; pooled and
    # refitted as the real data were. The bootstrap's needed resolutions relative to their
    # populations' are put around the estimate.
    population = fit_population(per_participant, levels, guess=guess, lapse=lapse, start=best)
    populations, weights = spread_profile(per_participant, levels, best, guess=guess, lapse=lapse)
    picks = rng.choice(len(populations), samples, p=weights)
    midpoints = np.array([populations[i].fit.midpoint for i in picks])[:, None, None]
    slopes = np.array([populations[i].fit.slope for i in picks])[:, None, None]
    spreads = np.array([populations[i].spread for i in picks])[:, None, None]
    shifts = spreads * rng.standard_normal((samples, len(per_participant), 1))
    p = _probability(np.log2(x)[None, None, :], midpoints + shifts, slopes, guess, lapse)
    drawn = rng.binomial(ns[:, used].astype(np.int64)[None, :, :], p).sum(axis=1)
    parametric = fit_many(
        x, drawn.astype(float), np.tile(n_used, (samples, 1)), guess=guess, lapse=lapse
    )
    # Every needed resolution, the estimate's and the bootstrap's, is censored at the tested
    # range's ends before the interval is read off: beyond them the curve's shape is a guess
    # (a fit pinned at the midpoint's bound, a flat curve whose 75% lies at millions of
    # strokes), and the report gives such an estimate only as a bound. Uncensored, an
    # estimate far below the range sat beyond nearly all of its bootstrap values, and the
    # bias correction then moved both percentiles into the far tail of the other side: an
    # estimate "<= 3" with an interval wholly ">= 12".
    tested = (float(x[0]), float(x[-1]))
    censored = float(censor(estimate, tested))
    values = np.array([f.strokes_at(criterion) for f in parametric])
    world = np.array([p.strokes_at(criterion) for p in populations])[picks]
    if np.all(np.isfinite(world)) and tested[0] < estimate < tested[1]:
        # The pivot (each bootstrap value relative to the needed resolution of the population
        # it was drawn from) holds only where the estimate is a measured value; at a bound
        # the drawn values themselves, censored as the estimate is, say what the data allow.
        boot_low, boot_high = bias_corrected_interval(values / world, 1.0)
        boot_low, boot_high = censor_interval(
            boot_low * estimate, boot_high * estimate, estimate, tested
        )
    else:
        boot_low, boot_high = bias_corrected_interval(censor(values, tested), censored)
    # Cluster: participants resampled with replacement. Levels without a trial in a resample
    # count as no data (0 of 0): the likelihood ignores them.
    picks = rng.integers(0, len(per_participant), (samples, len(per_participant)))
    clustered = fit_many(
        x, ks[picks].sum(axis=1)[:, used], ns[picks].sum(axis=1)[:, used], guess=guess, lapse=lapse
    )
    cluster_low, cluster_high = bias_corrected_interval(
        censor(np.array([f.strokes_at(criterion) for f in clustered]), tested), censored
    )
    low, high = censor_interval(
        *profile_interval(x, k_used, n_used, criterion=criterion, guess=guess, lapse=lapse),
        estimate,
        tested,
    )
    if is_step(best.slope) and tested[0] < estimate < tested[1]:
        # Every participant's answers jump from wrong to right between the same two tested
        # resolutions: the likelihood hardly prefers any point between them, yet every
        # resampled study jumps there too and its fit lands on the same value (a cluster
        # interval of zero width). The data place the needed resolution only between the
        # two, so each interval spans at least them.
        bracket_low, bracket_high = step_bracket(estimate, x)
        boot_low, boot_high = min(boot_low, bracket_low), max(boot_high, bracket_high)
        low, high = min(low, bracket_low), max(high, bracket_high)
        cluster_low, cluster_high = min(cluster_low, bracket_low), max(cluster_high, bracket_high)
    return Threshold(
        best,
        estimate,
        boot_low,
        boot_high,
        low,
        high,
        cluster_low,
        cluster_high,
        dispersion(per_participant, best, levels),
        samples,
        population,
    )


def censor(values: NDArray[np.float64] | float, tested: tuple[float, float]) -> NDArray[np.float64]:
    """Needed resolutions censored at the tested range: below it becomes the lowest tested
    resolution ("at or below"), above it or never reached (inf) the highest ("at or above")."""
    return np.asarray(np.clip(np.asarray(values, dtype=float), *tested), dtype=float)


def censor_interval(
    low: float, high: float, estimate: float, tested: tuple[float, float]
) -> tuple[float, float]:
    """An interval censored as its estimate is, and reaching it (``bias_corrected_interval``)."""
    at = float(censor(estimate, tested))
    low, high = (float(v) for v in censor(np.array([low, high]), tested))
    return min(low, at), max(high, at)


def bias_corrected_interval(
    values: NDArray[np.float64], estimate: float, level: float = 0.95
) -> tuple[float, float]:
    """The bias-corrected percentile interval (Efron 1981): the percentiles shifted by how far
    the bootstrap distribution's median sits from the estimate. A skewed, biased statistic
    such as a threshold on a log scale needs it; the plain percentile interval undercovers.

    Where fewer than (1 - level) / 2 of the values lie on one side of the estimate, the
    shift would carry both percentiles past the estimate into the other side's tail (the
    interval would not hold its own estimate): the shift is then capped there, and the
    interval always reaches the estimate."""
    if len(values) == 0:
        return math.nan, math.nan
    below = (np.sum(values < estimate) + 0.5 * np.sum(values == estimate)) / len(values)
    z = float(norm.ppf(0.5 + level / 2))
    z0 = min(max(float(norm.ppf(min(max(below, 1e-6), 1 - 1e-6))), -z), z)
    percentiles = 100 * norm.cdf([2 * z0 - z, 2 * z0 + z])
    low, high = np.percentile(values, percentiles)
    return min(float(low), estimate), max(float(high), estimate)


@dataclass(frozen=True)
class Interval:
    """A 95% interval truncated to the tested range; an open end reaches beyond it."""

    low: float
    high: float
    low_open: bool  # the interval goes below the lowest tested resolution
    high_open: bool  # ... above the highest (or the curve may never reach the criterion)


@dataclass(frozen=True)
class Needed:
    """A needed resolution as far as the data can say: a number only where the tested
    resolutions bracket the criterion, else a bound at the tested range's end."""

    kind: str  # "estimate" | "at_or_below_lowest_tested" | "above_highest_tested"
    strokes: float | None  # the estimate, when ``kind`` is "estimate"
    lowest_tested: float
    highest_tested: float
    interval: Interval  # the reported one (parametric bootstrap with the spread)
    profile: Interval
    cluster: Interval


ESTIMATE, AT_OR_BELOW, ABOVE = "estimate", "at_or_below_lowest_tested", "above_highest_tested"


def truncated(low: float, high: float, tested: tuple[float, float]) -> Interval:
    """``low``-``high`` cut to the tested range; NaN (no interval) counts as open both ways.
    An end at the range's end is open: the intervals are censored there (``censor``), so
    an end at the lowest tested resolution stands for "at or below" it."""
    lowest, highest = tested
    low_open = not math.isfinite(low) or low <= lowest
    high_open = not math.isfinite(high) or high >= highest
    # An end beyond the range on the other side (an interval wholly below or above what
    # was tested) is put at the nearer end: the interval is then "<= lowest" or ">= highest".
    return Interval(
        lowest if low_open else min(low, highest),
        highest if high_open else max(high, lowest),
        low_open,
        high_open,
    )


def within_tested(
    threshold: Threshold,
    tested: tuple[float, float],
    shares: list[float],
    criterion: float,
) -> Needed:
    """The needed resolution of ``threshold`` within the ``tested`` range (lowest, highest
    resolution with answers), given the share correct at each tested resolution: when every
    share reaches the criterion, the data say only that the lowest tested one is enough;
    when none does, only that the highest is not; a fitted value beyond either end is
    the same bound (the curve's shape there is a guess, not data)."""
    lowest, highest = tested
    value = threshold.strokes
    if (shares and all(s >= criterion for s in shares)) or value <= lowest:
        kind: str = AT_OR_BELOW
    elif (shares and all(s < criterion for s in shares)) or not value <= highest:
        kind = ABOVE
    else:
        kind = ESTIMATE
    # A bound's intervals reach the bound, as the estimate's reach the estimate: when the
    # shares alone decide the bound (the curve crosses inside the range, every share on one
    # side of the criterion), the interval is widened to the range's end the bound names.
    low_end = lowest if kind == AT_OR_BELOW else math.inf
    high_end = highest if kind == ABOVE else -math.inf

    def reaching(low: float, high: float) -> Interval:
        return truncated(min(low, low_end), max(high, high_end), tested)

    return Needed(
        kind,
        value if kind == ESTIMATE else None,
        lowest,
        highest,
        reaching(threshold.boot_low, threshold.boot_high),
        reaching(threshold.low, threshold.high),
        reaching(threshold.cluster_low, threshold.cluster_high),
    )
