"""Do shapes differ? A test over participants that holds at every size, or none with its reason."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import statsmodels.api as sm
import statsmodels.formula.api as smf
from study_helpers import pilot_study

from feelmysign.study.analysis import analyse_study
from feelmysign.study.analysis.analyse import main_trials
from feelmysign.study.analysis.models import (
    MIN_PARTICIPANTS,
    NULL_FORMULA,
    null_design,
    shape_profiles,
    sign_flip_test,
)
from feelmysign.study.dry_run import dry_run

LEVELS = {"circle": (4, 8), "square": (4, 8), "triangle": (3, 6), "star": (5, 10)}


def _answers(participants: int, rng: np.random.Generator, *, star_odds: float) -> pd.DataFrame:
    """Trials of the pilot's shapes; the star is ``star_odds`` log odds harder (0: no effect)."""
    rows = []
    for person in range(participants):
        ability = rng.normal(0.0, 1.0)
        for shape, levels in LEVELS.items():
            for strokes in levels:
                for _ in range(6):
                    odds = 1.5 * (math.log2(strokes) - 2.0) + ability
                    odds -= star_odds if shape == "star" else 0.0
                    correct = float(rng.random() < 1 / (1 + math.exp(-odds)))
                    rows.append((f"P{person}", shape, strokes, correct))
    frame = pd.DataFrame(rows, columns=["participant", "shape", "segments", "correct"])
    return frame.assign(log2_strokes=np.log2(frame["segments"].astype(float)))


def test_a_difference_every_participant_shows_is_found_at_the_smallest_possible_p() -> None:
    test = sign_flip_test(_answers(8, np.random.default_rng(1), star_odds=4.0))
    assert test.refused is None and test.flips == 2**8
    assert test.p == 2 / 2**8  # only the data and their mirror image are as extreme


def test_no_effect_gives_no_small_p_in_most_studies() -> None:
    # 20 seeded studies of 8 participants with no shape effect: a valid 5% test rejects in
    # about 1 of them; 4 or more has probability 0.016 for a calibrated test, while the
    # cluster-robust Wald test it replaces rejected in about a third of such studies.
    rejected = sum(
        (sign_flip_test(_answers(8, np.random.default_rng(seed), star_odds=0.0)).p or 1) < 0.05
        for seed in range(20)
    )
    assert rejected <= 3


def test_below_the_minimum_no_test_is_run_and_the_reason_is_given() -> None:
    test = sign_flip_test(_answers(MIN_PARTICIPANTS - 1, np.random.default_rng(2), star_odds=4.0))
    assert test.p is None and test.statistic is None and test.flips == 0
    assert test.refused is not None and f"at least {MIN_PARTICIPANTS}" in test.refused


def test_a_two_participant_pilot_is_analysed_without_a_test_and_says_why(tmp_path: Path) -> None:
    store = pilot_study(tmp_path)
    dry_run(store, 2, seed=3)
    analysis = analyse_study(store, tmp_path / "out", samples=50)
    assert analysis.model is not None and analysis.model.test.p is None
    report = (tmp_path / "out" / "report.md").read_text()
    assert "No test of whether shapes differ is reported" in report
    assert f"Run at least {MIN_PARTICIPANTS} participants" in report
    assert "chi2" not in report
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    test = results["shape_model"]["test"]
    assert test["p"] is None and test["participants_needed"] == MIN_PARTICIPANTS
    # The per-participant table adds up to the accuracy table.
    table = results["per_participant"]
    assert [row["participant"] for row in table] == ["P01", "P02"]
    for shape, levels in results["accuracy"].items():
        assert sum(row["by_shape"][shape][0] for row in table) == sum(r["correct"] for r in levels)
        assert sum(row["by_shape"][shape][1] for row in table) == sum(r["total"] for r in levels)
    assert "## Per participant" in report and "| P02 | yes | 16 |" in report


def test_a_profile_holds_nothing_the_shape_free_model_fits() -> None:
    """Each participant's profile sums to zero over the shapes (their own level is their
    intercept's) and has no part along the shapes' mean log2(strokes) (the shared slope's):
    what sign flips would count as spread while the data's mean cannot vary there."""
    data = _answers(8, np.random.default_rng(4), star_odds=1.0)
    profile = shape_profiles(data)
    levels = data.groupby("shape")["log2_strokes"].mean().sort_index().to_numpy(float)
    assert profile.shape == (8, len(LEVELS))
    assert np.abs(profile.sum(axis=1)).max() < 1e-9
    assert np.abs(profile @ (levels - levels.mean())).max() < 1e-9
    assert np.abs(profile).max() > 0.01  # and something is left to test


def test_the_direct_design_is_the_formulas_to_the_last_bit(tmp_path: Path) -> None:
    # A real study's answers (a dry run of 7 in-range wearers), as the analysis passes them.
    store = pilot_study(tmp_path)
    dry_run(store, 7, seed=4, wearer="in-range")
    frame = main_trials(store)
    data = frame[frame["coded_status"] != "unclear"][["participant", "shape", "segments"]]
    data = data.assign(
        correct=frame["correct"].astype(float),
        log2_strokes=np.log2(frame["segments"].astype(float)),
    )
    family = sm.families.Binomial()
    formula = smf.glm(NULL_FORMULA, data, family=family)
    assert np.array_equal(formula.exog, null_design(data))
    by_formula = formula.fit().fittedvalues.to_numpy()
    direct = sm.GLM(data["correct"].to_numpy(float), null_design(data), family=family).fit()
    assert np.array_equal(by_formula, np.asarray(direct.fittedvalues))
