"""A needed resolution is a number only within the tested range; elsewhere a bound."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from study_helpers import pilot_study

from feelmysign.study.analysis import analyse_study
from feelmysign.study.analysis.psychometric import (
    ABOVE,
    AT_OR_BELOW,
    ESTIMATE,
    LAPSE,
    Fit,
    Interval,
    Needed,
    bias_corrected_interval,
    threshold_with_interval,
    truncated,
    within_tested,
)
from feelmysign.study.analysis.recovery import Truth, synthetic_counts
from feelmysign.study.dry_run import dry_run

LEVELS = np.array([4.0, 8.0, 12.0, 16.0])


def _needed(midpoint_strokes: float, seed: int = 1):  # type: ignore[no-untyped-def]
    truth = Truth(Fit(math.log2(midpoint_strokes), 3.0, 0.0, LAPSE), 0.75)
    data = synthetic_counts(
        truth, LEVELS, participants=6, repetitions=3, rng=np.random.default_rng(seed)
    )
    threshold = threshold_with_interval(data, LEVELS, criterion=0.75, samples=60)
    k = np.sum([c for c, _ in data], axis=0)
    n = np.sum([t for _, t in data], axis=0)
    return threshold, within_tested(threshold, (4.0, 16.0), list(k / n), 0.75)


def test_at_ceiling_the_answer_is_at_or_below_the_lowest_tested() -> None:
    threshold, needed = _needed(1.5)  # 75% at about 2 strokes: every tested level above it
    assert threshold.strokes < 4  # the curve alone would extrapolate below the data
    assert needed.kind == AT_OR_BELOW and needed.strokes is None
    assert needed.interval.low == 4.0 and needed.interval.low_open


def test_at_floor_the_answer_is_above_the_highest_tested() -> None:
    _, needed = _needed(60.0)
    assert needed.kind == ABOVE and needed.strokes is None
    assert needed.interval.high == 16.0 and needed.interval.high_open


def test_a_bracketed_criterion_gives_a_number_inside_the_range() -> None:
    _, needed = _needed(6.0)
    assert needed.kind == ESTIMATE and needed.strokes is not None
    assert 4.0 <= needed.strokes <= 16.0
    assert 4.0 <= needed.interval.low <= needed.strokes <= needed.interval.high <= 16.0


def test_intervals_are_truncated_never_extrapolated() -> None:
    assert truncated(0.4, 3.1e7, (4.0, 16.0)) == truncated(1.0, math.inf, (4.0, 16.0))
    wide = truncated(0.4, 3.1e7, (4.0, 16.0))
    assert (wide.low, wide.high, wide.low_open, wide.high_open) == (4.0, 16.0, True, True)
    below = truncated(0.3, 2.8, (4.0, 16.0))  # wholly below the range
    assert (below.low, below.high, below.low_open, below.high_open) == (4.0, 4.0, True, False)
    inside = truncated(5.0, 9.0, (4.0, 16.0))
    assert (inside.low, inside.high, inside.low_open, inside.high_open) == (5.0, 9.0, False, False)


def test_a_pilot_reports_every_needed_resolution_within_what_it_tested(tmp_path: Path) -> None:
    store = pilot_study(tmp_path)
    dry_run(store, 2, seed=5)
    analyse_study(store, tmp_path / "out", samples=50)
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    for shape, needed in results["needed_strokes"].items():
        lowest, highest = needed["lowest_tested"], needed["highest_tested"]
        assert needed["kind"] in (ESTIMATE, AT_OR_BELOW, ABOVE), shape
        if needed["kind"] == ESTIMATE:
            assert lowest <= needed["strokes"] <= highest, shape
        else:
            assert needed["strokes"] is None, shape
        # Two participants: the cluster bootstrap is not estimable, its ends null.
        assert needed["cluster_bootstrap_not_estimable"] is not None, shape
        assert needed["cluster_bootstrap_low"] is None, shape
        for prefix in ("", "profile_"):
            assert lowest <= needed[f"{prefix}low"] <= needed[f"{prefix}high"] <= highest, shape
    report = (tmp_path / "out" / "report.md").read_text()
    assert "e+" not in report  # no astronomically large number anywhere


def _reaches_its_estimate(needed: Needed, interval: Interval) -> bool:
    """A bound's interval reaches the bound's side; an estimate's holds the estimate."""
    if needed.kind == AT_OR_BELOW:
        return interval.low_open
    if needed.kind == ABOVE:
        return interval.high_open
    assert needed.strokes is not None
    return (interval.low_open or interval.low <= needed.strokes) and (
        interval.high_open or needed.strokes <= interval.high
    )


def test_a_shape_named_every_time_gets_a_bound_and_an_interval_that_stays_there(
    tmp_path: Path,
) -> None:
    # Two simulated participants (seed 1) name every triangle of the pilot, at 3 and at 6
    # strokes: the data say 3 strokes are enough. The reported interval was built from
    # bootstrap values relative to the needed resolutions of curves extrapolated far below
    # the range, around the fit's own extrapolated value (0.78 strokes), and read
    # "<= 3 - >= 6": a bound below the range with an interval reaching above it. Censored
    # at the range as the estimate is, it stays at the bound.
    store = pilot_study(tmp_path)
    dry_run(store, 2, seed=1)
    analysis = analyse_study(store, tmp_path / "out")
    assert all(k == n > 0 for _, k, n, _, _ in analysis.accuracy["triangle"])
    needed = analysis.needed["triangle"]
    assert needed.kind == AT_OR_BELOW
    for interval in (needed.interval, needed.profile, needed.cluster):
        assert interval.low_open and not interval.high_open, interval
        assert interval.high < 6.0
    report = (tmp_path / "out" / "report.md").read_text()
    assert "disagrees" not in report


@pytest.mark.parametrize(("wearer", "seed"), [("template", 1), ("template", 7), ("in-range", 2)])
def test_every_interval_reaches_its_own_estimate_or_bound(
    tmp_path: Path, wearer: str, seed: int
) -> None:
    # Two participants: estimates land beyond the range's ends, bootstrap values pile up at
    # the fit's bounds, and the bias correction is at its most extreme. Template seed 7: the
    # circle's shares all reach the criterion while its curve crosses inside the range.
    store = pilot_study(tmp_path)
    dry_run(store, 2, seed=seed, wearer=wearer)
    analysis = analyse_study(store, tmp_path / "out", samples=200)
    for shape, needed in analysis.needed.items():
        for interval in (needed.interval, needed.profile, needed.cluster):
            assert _reaches_its_estimate(needed, interval), (shape, needed)


def test_the_bias_corrected_interval_holds_its_estimate_when_the_values_lie_to_one_side() -> None:
    # Every bootstrap value above the estimate (a fit at its bound, values a grid step away):
    # uncorrected for that, both percentiles moved to the far tail, away from the estimate.
    values = np.concatenate([np.full(990, 3.1), np.geomspace(20.0, 1e6, 10)])
    low, high = bias_corrected_interval(values, 3.0)
    assert low <= 3.0 <= high
    assert high < 20.0  # not the outliers' tail
    low, high = bias_corrected_interval(-values, -3.0)  # and mirrored
    assert low <= -3.0 <= high and low > -20.0


@pytest.mark.parametrize(
    "correct",
    [
        # Every participant wrong at 4 strokes and below, right from 6: complete separation.
        [[1, 0, 1, 4, 4, 4], [0, 1, 1, 4, 4, 4], [1, 1, 0, 4, 4, 4], [0, 0, 1, 4, 4, 4]],
        # The same answers for everyone: every resampled study is the real one.
        [[0, 0, 0, 4, 4, 4]] * 5,
    ],
)
def test_answers_that_jump_between_two_resolutions_place_it_only_between_them(
    correct: list[list[int]],
) -> None:
    # Resampled studies all jump where the real one does and fit the same value: the cluster
    # interval had no width (4.92 - 4.92) although nothing was measured between 4 and 6.
    levels = np.array([2.0, 3.0, 4.0, 6.0, 8.0, 12.0])
    data = [(np.array(k, dtype=float), np.full(6, 4.0)) for k in correct]
    threshold = threshold_with_interval(data, levels, criterion=0.625, guess=0.25, samples=200)
    assert 4.0 < threshold.strokes < 6.0
    for low, high in (
        (threshold.boot_low, threshold.boot_high),
        (threshold.low, threshold.high),
        (threshold.cluster_low, threshold.cluster_high),
    ):
        assert low <= 4.0 and high >= 6.0, (low, high)


def test_a_measured_slope_keeps_its_intervals_narrower_than_the_tested_step() -> None:
    # Answers that climb level by level: a slope was measured, so nothing is widened to the
    # neighbouring resolutions.
    levels = np.array([2.0, 3.0, 4.0, 6.0, 8.0, 12.0])
    correct = [[1, 1, 2, 3, 4, 4], [0, 1, 2, 4, 3, 4], [1, 2, 2, 3, 4, 4], [1, 1, 3, 3, 4, 4]]
    data = [(np.array(k, dtype=float), np.full(6, 4.0)) for k in correct]
    threshold = threshold_with_interval(data, levels, criterion=0.625, guess=0.25, samples=200)
    assert threshold.cluster_high - threshold.cluster_low < 6.0 - 4.0
