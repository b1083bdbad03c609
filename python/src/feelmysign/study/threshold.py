"""SQ2.2: the shortest stroke, and the briefest, whose direction a wearer can tell, by QUEST+.

Task: four alternatives (up, down, left, right: chance 25%). One stroke is sent
through the centre of the grid in a random direction; the wearer says which
way it moved. QUEST+ (Watson 2017, the ``questplus`` package) keeps a posterior
over a Weibull psychometric function

    p(x) = 1 - lapse - (1 - 0.25 - lapse) exp(-(x / threshold)^slope)

on log-spaced grids of threshold and slope (lapse fixed from the design) and
picks each next value by minimum expected entropy. ``threshold`` is where the
wearer is right about 71% of the time.

Stopping rule: after ``trials`` trials; or, when ``stop_width`` > 0, as soon as
(after at least ``MIN_TRIALS``) the 95% credible interval's width divided by the
threshold is below it, and at ``max_trials`` at the latest. The estimate is the
posterior mean of the threshold; the interval its 2.5% and 97.5% quantiles.
Every trial is stored; the state is rebuilt from them after any restart.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Literal

from feelmysign.errors import StudyError
from feelmysign.layout import Layout
from feelmysign.stroke import Stroke
from feelmysign.study.choices import DIRECTIONS, Dimension
from feelmysign.study.design import Threshold, ThresholdDimension

GUESS_RATE = 0.25  # four alternatives
SLOPES = (1.5, 2.0, 3.0, 4.5, 6.0)  # Weibull slopes QUEST+ considers
# The posterior's threshold grid is finer than the stimulus grid: its 95% interval is read
# between grid points, and a coarse grid makes it too narrow (on 25 points over 20-1500 ms,
# it covered a known threshold in 89.5% of 200 runs instead of 95%).
THRESHOLD_GRID_FACTOR = 4
MIN_TRIALS = 10  # before the interval can stop a run early
CREDIBLE = 0.95


# Where a run's 95% interval reaches an end of the tested range: the threshold was not
# measured there, only bounded ("above": it may lie beyond the longest or slowest stroke
# tested, as for a wearer who tells no direction; "below": the wearer told the direction
# even of the shortest or briefest).
Censored = Literal["above", "below"]


def censored(grid: ThresholdDimension, low: float, high: float) -> Censored | None:
    """Whether the 95% interval [low, high] reaches an end of ``grid``'s range: within the
    last step of the posterior's threshold grid (2.5% of the posterior or more lies there)."""
    steps = (grid.steps - 1) * THRESHOLD_GRID_FACTOR
    ratio = (grid.maximum / grid.minimum) ** (1 / steps)
    slack = 1e-9  # the grid's own rounding
    if high >= grid.maximum / ratio * (1 - slack):
        return "above"
    if low <= grid.minimum * ratio * (1 + slack):
        return "below"
    return None


def value_words(dimension: Dimension, value: float) -> str:
    """A length or a duration as the study's lines write it: 0.62 grid units, 118 ms,
    1454 ms (never 1.45e+03)."""
    if dimension == "length":
        return f"{value:.3g} grid units"
    return f"{value:.0f} ms" if value >= 100 else f"{value:.3g} ms"


@dataclass(frozen=True)
class Estimate:
    threshold: float
    low: float
    high: float
    trials: int
    censored: Censored | None = None

    def words(self, dimension: Dimension, grid: ThresholdDimension) -> str:
        """The result in a sentence: the threshold and its interval, or, where the interval
        reaches an end of the tested range, the bound the run gives and what to do."""
        interval = (
            f"95% interval {value_words(dimension, self.low)} to "
            f"{value_words(dimension, self.high)}, after {self.trials} trials"
        )
        if self.censored == "above":
            top = value_words(dimension, grid.maximum)
            return (
                f"not measured: the 95% interval reaches the top of the tested range ({top}; "
                f"{interval}), so the threshold may lie above it: the wearer told the "
                "direction hardly better than by chance. Check that the sleeve sits well and "
                "that the wearer knows the task, and run again (with a larger "
                f"threshold.{dimension}.maximum in the design if the sleeve allows it)"
            )
        if self.censored == "below":
            bottom = value_words(dimension, grid.minimum)
            return (
                f"at most {value_words(dimension, self.threshold)}: the wearer told the "
                f"direction even at the bottom of the tested range ({bottom}; {interval}), "
                "so the threshold lies at or below it (a bound, not a measurement; a limit "
                "the wearer feels)"
            )
        return f"{value_words(dimension, self.threshold)}, {interval}"


def dimension_settings(threshold: Threshold, dimension: Dimension) -> ThresholdDimension:
    return threshold.length if dimension == "length" else threshold.duration


def check_fits(layout: Layout, threshold: Threshold) -> None:
    """The longest stroke must fit through the grid's centre in all four directions."""
    room = min(layout.rows, layout.columns) - 1
    if threshold.length.maximum > room:
        raise StudyError(
            f"threshold.length.maximum is {threshold.length.maximum:g} grid units, but a "
            f"vertical stroke on this {layout.rows} x {layout.columns} sleeve can be at most "
            f"{room:g}; lower it"
        )
    if threshold.duration.fixed > room:
        raise StudyError(
            f"threshold.duration.fixed is {threshold.duration.fixed:g} grid units; at most "
            f"{room:g} on this sleeve"
        )


class Procedure:
    """QUEST+ for one dimension; ``replay`` the stored trials, then ``next_value``/``update``."""

    def __init__(self, threshold: Threshold, dimension: Dimension) -> None:
        self.settings = threshold
        self.dimension = dimension
        # numpy here, not at the top: the design check (check_fits, at every start of
        # 'up --study') needs none of it, and it takes a good part of a second to import.
        import numpy as np

        grid = dimension_settings(threshold, dimension)
        self.values = np.geomspace(grid.minimum, grid.maximum, grid.steps)
        self.thresholds = np.geomspace(
            grid.minimum, grid.maximum, (grid.steps - 1) * THRESHOLD_GRID_FACTOR + 1
        )
        import questplus  # scipy, xarray: seconds to import, and a design check needs none

        self._quest = questplus.QuestPlus(
            stim_domain={"intensity": self.values},
            param_domain={
                "threshold": self.thresholds,
                "slope": np.array(SLOPES),
                "lower_asymptote": GUESS_RATE,
                "lapse_rate": threshold.lapse_rate,
            },
            outcome_domain={"response": ["Correct", "Incorrect"]},
            func="weibull",
            stim_scale="linear",
            stim_selection_method="min_entropy",
            param_estimation_method="mean",
        )
        self.trials = 0

    def next_value(self) -> float:
        return float(self._quest.next_stim["intensity"])

    def update(self, value: float, correct: bool) -> None:
        import numpy as np

        nearest = float(self.values[np.argmin(np.abs(self.values - value))])
        self._quest.update(
            stim={"intensity": nearest}, outcome={"response": "Correct" if correct else "Incorrect"}
        )
        self.trials += 1

    def estimate(self) -> Estimate:
        import numpy as np

        marginal = np.asarray(self._quest.marginal_posterior["threshold"], dtype=float)
        cumulative = np.cumsum(marginal) / marginal.sum()
        tail = (1 - CREDIBLE) / 2
        logs = np.log(self.thresholds)
        low = math.exp(float(np.interp(tail, cumulative, logs)))
        high = math.exp(float(np.interp(1 - tail, cumulative, logs)))
        mean = float(np.sum(marginal * self.thresholds) / marginal.sum())
        grid = dimension_settings(self.settings, self.dimension)
        return Estimate(mean, low, high, self.trials, censored(grid, low, high))

    def stop_reason(self) -> str | None:
        """Why the run is over, or None to go on."""
        s = self.settings
        if s.stop_width > 0:
            if self.trials >= MIN_TRIALS:
                e = self.estimate()
                if (e.high - e.low) / e.threshold < s.stop_width:
                    return f"95% interval narrower than {s.stop_width:g} x the threshold"
            if self.trials >= s.max_trials:
                return f"{s.max_trials} trials (the most allowed)"
            return None
        return f"{s.trials} trials" if self.trials >= s.trials else None


def direction_for(run_id: int, position: int) -> str:
    """The direction of a trial: random, but the same after a restart."""
    return random.Random(f"{run_id}:{position}").choice(sorted(DIRECTIONS))


def threshold_stroke(
    layout: Layout,
    threshold: Threshold,
    dimension: Dimension,
    value: float,
    direction: str,
    drawing: str,
) -> Stroke:
    """A straight stroke through the grid's centre: ``value`` is its length or duration."""
    if dimension == "length":
        length, duration_ms = value, threshold.length.fixed
    else:
        length, duration_ms = threshold.duration.fixed, value
    dx, dy = DIRECTIONS[direction]
    cx, cy = (layout.columns - 1) / 2, (layout.rows - 1) / 2
    half = length / 2
    return Stroke(
        start=(cx - dx * half, cy - dy * half),
        end=(cx + dx * half, cy + dy * half),
        duration_ms=duration_ms,
        drawing=drawing,
        seq=0,
    )


@dataclass(frozen=True)
class SimulatedObserver:
    """A wearer with a known Weibull threshold, for dry runs and the recovery test."""

    threshold: float
    slope: float = 3.0
    lapse_rate: float = 0.02

    def probability(self, value: float) -> float:
        core = math.exp(-((value / self.threshold) ** self.slope))
        return 1 - self.lapse_rate - (1 - GUESS_RATE - self.lapse_rate) * core

    def respond(self, direction: str, value: float, rng: random.Random) -> str:
        # probability() already holds the lucky guesses (the 25% floor).
        if rng.random() < self.probability(value):
            return direction
        return rng.choice(sorted(d for d in DIRECTIONS if d != direction))
