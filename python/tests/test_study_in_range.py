"""The in-range simulated wearer: known needed resolutions inside the tested range, so that
a dry run of the paper's design gives point estimates with intervals (not bounds), and the
report and results.json show the truth beside them."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from study_helpers import PAPER_DESIGN, new_study, pilot_study

from feelmysign.shapes import shape_strokes
from feelmysign.study import load_design
from feelmysign.study.analysis.analyse import analyse_study
from feelmysign.study.analysis.psychometric import ESTIMATE, Fit, Population
from feelmysign.study.dry_run import dry_run
from feelmysign.study.simulated import InRangeWearer, in_range_truths, templates
from feelmysign.study.stimulus import stimulus_layout


def test_each_truth_lies_inside_its_shapes_tested_range_and_is_where_the_curve_reaches_it() -> None:
    design = load_design(PAPER_DESIGN)
    truths = in_range_truths(design)
    assert set(truths) == set(design.shape_names)
    for shape in design.shapes:
        truth = truths[shape.name]
        levels = sorted(level.strokes for level in shape.levels)
        assert levels[0] < truth.needed_strokes < levels[-1]
        population = Population(
            Fit(truth.midpoint_log2, truth.slope_per_doubling, truth.guess, truth.lapse),
            truth.spread_doublings,
        )
        reached = float(population.accuracy(truth.needed_strokes))
        assert reached == pytest.approx(design.criterion, abs=1e-4)


def test_the_wearers_share_correct_at_the_needed_strokes_is_the_criterion() -> None:
    design = load_design(PAPER_DESIGN)
    truth = in_range_truths(design)["square"]
    layout = stimulus_layout(design.stimulus, PAPER_DESIGN.parent)
    known = templates(design, layout, PAPER_DESIGN.parent)
    strokes = shape_strokes("square", layout=layout, segments=8)  # the square's truth: 8
    assert truth.needed_strokes == 8.0
    people = 600  # each with a shift of their own: the average participant's accuracy
    right = sum(
        InRangeWearer(seed, in_range_truths(design))
        .answer(strokes, layout, design, known, "t", sent="square", segments=8)
        .intended
        == "square"
        for seed in range(people)
    )
    # 600 draws at p = 0.75: SD 0.018; 0.69 to 0.81 is beyond 3 SDs either way.
    assert 0.69 < right / people < 0.81, right / people


def _export(folder: Path, seed: int, wearer: str) -> dict[str, bytes]:
    from feelmysign.study.export import export_study

    folder.mkdir()
    store = pilot_study(folder)
    dry_run(store, 2, seed=seed, wearer=wearer)
    files = export_study(store, folder / "export")
    truth = store.meta("simulated_truth")
    store.close()
    return {"truth": (truth or "").encode()} | {f.name: f.read_bytes() for f in files}


def test_the_study_file_keeps_the_truth_and_only_for_in_range_wearers(tmp_path: Path) -> None:
    # Byte-identical dry runs of either wearer: test_study_reproducible.py.
    in_range = _export(tmp_path / "a", 3, "in-range")
    template = _export(tmp_path / "b", 3, "template")
    assert template["truth"] == b"" and template["trials.csv"] != in_range["trials.csv"]
    truth = json.loads(in_range["truth"])
    assert truth["participants"] == [0, 1]  # by number, from 0
    assert truth["shapes"]["star"]["needed_strokes"] == pytest.approx(math.sqrt(5 * 10))


def test_a_dry_run_of_the_papers_design_gives_estimates_beside_the_truth(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    dry_run(store, 8, seed=5, wearer="in-range")
    analysis = analyse_study(store, tmp_path / "out", samples=60)
    assert {n.kind for n in analysis.needed.values()} == {ESTIMATE}, analysis.needed
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    truth = results["simulated_truth"]
    assert truth["participants"] == [f"P{n:02}" for n in range(1, 9)]
    for shape, needed in results["needed_strokes"].items():
        known = truth["shapes"][shape]["needed_strokes"]
        assert needed["lowest_tested"] < known < needed["highest_tested"]
        # Not a bound: a finite estimate inside the tested range, its interval around it.
        assert needed["low"] <= needed["strokes"] <= needed["high"]
        assert math.isfinite(needed["strokes"])
    report = (tmp_path / "out" / "report.md").read_text()
    assert "**Dry run: known truth.** 8 of the participants" in report
    assert "| square | 8.00 |" in report


def test_simulate_in_range_prints_the_truth(tmp_path: Path) -> None:
    def cli(*args: str) -> subprocess.CompletedProcess[str]:
        command = [sys.executable, "-m", "feelmysign", "study", *args]
        return subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, timeout=300)

    study = tmp_path / "s.sqlite"
    assert cli("new", str(PAPER_DESIGN), "--out", str(study)).returncode == 0
    ran = cli("simulate", str(study), "--participants", "1", "--wearer", "in-range")
    assert ran.returncode == 0, ran.stderr
    assert "Known truth of the in-range wearers" in ran.stdout
    assert "  line: 2.83 strokes (tested 1-8;" in ran.stdout
    bad = cli("simulate", str(study), "--wearer", "perfect")
    assert bad.returncode == 2 and "invalid choice: 'perfect'" in bad.stderr
