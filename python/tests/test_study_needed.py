"""A needed resolution is a number only within the tested range; elsewhere a bound."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
from study_helpers import pilot_study

from feelmysign.study.analysis import analyse_study
from feelmysign.study.analysis.psychometric import (
    ABOVE,
    AT_OR_BELOW,
    ESTIMATE,
    LAPSE,
    Fit,
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
        for prefix in ("", "profile_", "cluster_bootstrap_"):
            assert lowest <= needed[f"{prefix}low"] <= needed[f"{prefix}high"] <= highest, shape
    report = (tmp_path / "out" / "report.md").read_text()
    assert "e+" not in report  # no astronomically large number anywhere
