"""The analysis recovers known parameters, and a dry run of the paper's design is analysed."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
from study_helpers import new_study

from feelmysign.study.analysis import analyse_study
from feelmysign.study.analysis.psychometric import LAPSE, Fit, fit
from feelmysign.study.analysis.recovery import coverage, paper_truths
from feelmysign.study.analysis.wilson import wilson_interval
from feelmysign.study.dry_run import dry_run


def test_wilson_interval_matches_the_published_example() -> None:
    # Brown, Cai & DasGupta (2001): 0 of 10 gives [0, 0.278]; 5 of 10 gives [0.237, 0.763].
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-3)
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-3)


def test_the_fit_finds_the_curve_that_made_noise_free_counts() -> None:
    truth = Fit(math.log2(6.0), 2.5, 0.0, LAPSE)
    levels = np.array([3.0, 4.0, 6.0, 8.0, 16.0])
    total = np.full(5, 10_000.0)
    found = fit(levels, truth.accuracy(levels) * total, total)
    assert found.strokes_at(0.75) == pytest.approx(truth.strokes_at(0.75), rel=0.01)
    assert found.slope == pytest.approx(2.5, rel=0.02)


@pytest.mark.parametrize("name", list(paper_truths()))
def test_intervals_cover_the_true_needed_resolution_about_95_percent(name: str) -> None:
    # 40 seeded studies of 12 participants; `make bench` runs 400. With 40 runs a 95%
    # interval covers in 34 or more with probability 0.99 (and an interval that covered
    # only 85% would pass with probability 0.5).
    result = coverage(40, truth=paper_truths()[name], samples=200, seed=7)
    assert result.bootstrap >= 34
    assert result.profile >= 34


def test_a_dry_run_of_the_papers_design_gives_tables_plots_and_report(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    dry_run(store, 4, seed=2)
    analysis = analyse_study(store, tmp_path / "out", samples=60)
    names = {p.name for p in analysis.files}
    assert {"trials.csv", "design.json", "accuracy.png", "report.md", "results.json"} <= names
    with (tmp_path / "out" / "trials.csv").open() as file:
        rows = list(csv.DictReader(file))
    assert len(rows) == 4 * 74
    assert {r["participant"] for r in rows} == {"P01", "P02", "P03", "P04"}
    assert not any(r["participant"].startswith("P-") for r in rows)  # no codes in the export
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    circle = results["accuracy"]["circle"]
    assert [r["strokes"] for r in circle] == [4, 6, 8, 16]
    assert sum(r["total"] for r in circle) + analysis.unclear >= 4 * 12 - analysis.unclear
    assert "Do shapes differ?" in (tmp_path / "out" / "report.md").read_text()
    assert analysis.model is not None and analysis.model.wald_df == 5
