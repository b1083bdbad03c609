"""Speed as a factor of the design: trials played at their speed, a reproducible dry run,
speed_cm_s in every export, and an analysis per shape and speed with a test of speed."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from study_helpers import PILOT_DESIGN

from feelmysign.study import StudyStore, load_design
from feelmysign.study.analysis.models import (
    MIN_PARTICIPANTS,
    MIN_SPEED_PARTICIPANTS,
    speed_flip_test,
    speed_profiles,
)
from feelmysign.study.api import StudyApi
from feelmysign.study.dry_run import dry_run
from feelmysign.study.export import export_study
from feelmysign.study.runner import Session

SPEEDS = (4.0, 10.0)


def speeds_study(folder: Path, name: str = "speeds.sqlite") -> StudyStore:
    folder.mkdir(parents=True, exist_ok=True)
    design = folder / "speeds.toml"
    practice = '[[practice]]\nshape = "line"\n'
    design.write_text(PILOT_DESIGN + "[stimulus]\nspeed_cm_s = [4, 10]\n" + practice)
    return StudyStore.create(folder / name, design, load_design(design))


def _dry_run_export(folder: Path, seed: int) -> dict[str, bytes]:
    store = speeds_study(folder)
    dry_run(store, 2, seed=seed, wearer="in-range")
    files = export_study(store, folder / "export")
    store.close()
    return {str(f.relative_to(folder)): f.read_bytes() for f in files}


def test_a_dry_run_with_speeds_is_the_same_byte_for_byte_from_the_same_seed(
    tmp_path: Path,
) -> None:
    first = _dry_run_export(tmp_path / "a", seed=2)
    assert first == _dry_run_export(tmp_path / "b", seed=2)
    assert first != _dry_run_export(tmp_path / "c", seed=3)


def test_every_trial_is_played_at_its_speed_and_exported_with_it(tmp_path: Path) -> None:
    store = speeds_study(tmp_path)
    dry_run(store, 2, seed=1)
    code = store.participants()[0]["code"]
    main = [t for t in store.trials(code) if t["block"] == "main"]
    assert [t["speed_cm_s"] for t in store.trials(code) if t["block"] == "practice"] == [4.0]
    # 4 shapes x 2 resolutions x 2 speeds x 2 repetitions, each condition once per block.
    assert len(main) == 32
    conditions = {(t["shape"], t["level"], t["speed_cm_s"], t["repetition"]) for t in main}
    assert len(conditions) == 32 and {c[2] for c in conditions} == set(SPEEDS)
    # What was sent: the same shape and strokes, 2.5 times as long at 4 cm/s as at 10.
    drawn: dict[float, float] = {}
    for trial in main:
        if (trial["shape"], trial["level"], trial["repetition"]) == ("circle", 1, 1):
            (send,) = store.sends(trial["id"])
            strokes = json.loads(send["strokes_json"])
            assert len(strokes) == 8
            drawn[trial["speed_cm_s"]] = sum(s["duration_ms"] for s in strokes)
    assert drawn[4.0] == pytest.approx(2.5 * drawn[10.0], rel=1e-3)
    files = {f.name: f for f in export_study(store, tmp_path / "export")}
    with files["trials.csv"].open() as file:
        rows = list(csv.DictReader(file))
    header = list(rows[0])
    assert header[header.index("segments") + 1] == "speed_cm_s"
    assert {float(r["speed_cm_s"]) for r in rows if r["block"] == "main"} == set(SPEEDS)
    assert {float(r["speed_cm_s"]) for r in rows if r["block"] == "practice"} == {4.0}
    # BIDS: the same speeds in the participant's _beh.tsv, the column described in its sidecar.
    beh = pd.read_csv(files["sub-01_task-shapes_beh.tsv"], sep="\t")
    mine = [float(r["speed_cm_s"]) for r in rows if r["participant"] == "P01"]
    assert beh["speed_cm_s"].tolist() == mine
    sidecar = json.loads(files["sub-01_task-shapes_beh.json"].read_text())
    assert sidecar["speed_cm_s"]["Units"] == "cm/s" and sidecar["speed_cm_s"]["Description"]
    assert "2 drawing speeds (4, 10 cm/s)" in sidecar["TaskDescription"]
    assert json.loads(files["design.json"].read_text())["stimulus"]["speed_cm_s"] == [4.0, 10.0]


def test_the_page_is_told_the_speeds_and_each_trials_speed(tmp_path: Path) -> None:
    store = speeds_study(tmp_path)
    session = Session(store, None)
    api = StudyApi(session, tmp_path / "results")
    assert api.overview()["speeds_cm_s"] == list(SPEEDS)
    code = store.add_participant()
    session.consent(code, True)
    session.comfort(code, [True, True], adjusted=False)
    trials = store.trials(code)
    trial = session.state(code)["trial"]
    assert trial["block"] == "practice" and trial["speed_cm_s"] == 4.0
    store.record_send(trials[0]["id"], "d", [])
    session.answer(code, None, answer="line", felt_nothing=False, confidence=None)
    trial = session.state(code)["trial"]
    assert trial["speed_cm_s"] == trials[1]["speed_cm_s"] and trial["speed_cm_s"] in SPEEDS


def test_analyse_with_speeds_exits_0_and_reports_each_shape_at_each_speed(tmp_path: Path) -> None:
    store = speeds_study(tmp_path)
    dry_run(store, MIN_PARTICIPANTS, seed=1, wearer="in-range")
    store.close()
    out = tmp_path / "results"
    command = ["study", "analyse", str(store.path), "--out", str(out), "--bootstrap", "50"]
    result = subprocess.run(
        [sys.executable, "-m", "feelmysign", *command],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr
    # 6 participants: the shape test runs, the speed test says why it does not.
    assert "Test that shapes differ at equal strokes" in result.stdout
    assert "No test of whether speeds differ is reported" in result.stdout
    results = json.loads((out / "results.json").read_text())
    assert results["speeds_cm_s"] == list(SPEEDS)
    keys = [
        f"{shape} at {speed:g} cm/s"
        for shape in ("circle", "square", "triangle", "star")
        for speed in SPEEDS
    ]
    assert list(results["accuracy"]) == keys
    assert results["cells"]["star at 10 cm/s"] == {"shape": "star", "speed_cm_s": 10.0}
    # Each shape at each speed holds its own trials: 2 resolutions x 2 repetitions per person.
    for key in keys:
        assert sum(row["total"] for row in results["accuracy"][key]) == 4 * MIN_PARTICIPANTS
        needed = results["needed_strokes"][key]
        assert needed["speed_cm_s"] in SPEEDS and key.startswith(needed["shape"])
    model = results["shape_model"]
    assert model["speed_test"]["speeds"] == 2 and model["speed_test"]["p"] is None
    assert model["speed_test"]["participants_needed"] == MIN_SPEED_PARTICIPANTS
    assert [e["speed_cm_s"] for e in model["speed_effects"]] == [10.0]
    assert model["reference_speed_cm_s"] == 4.0
    report = (out / "report.md").read_text()
    assert "## Does speed matter?" in report and "| circle | 4 |" in report
    assert "2 speeds (4, 10 cm/s)" in report
    for row in results["per_participant"]:
        assert sum(n for _, n in row["by_speed"].values()) == row["coded"]


def _speed_answers(participants: int, rng: np.random.Generator, slow_odds: float) -> pd.DataFrame:
    """Answers at two speeds; the slow one ``slow_odds`` log odds easier (0: no effect)."""
    rows = []
    for person in range(participants):
        ability = rng.normal(0.0, 1.0)
        for shape, levels in {"circle": (4, 8), "line": (1, 2)}.items():
            for strokes in levels:
                for speed in SPEEDS:
                    for _ in range(4):
                        odds = 1.5 * (np.log2(strokes) - 1.5) + ability
                        odds += slow_odds if speed == SPEEDS[0] else 0.0
                        correct = float(rng.random() < 1 / (1 + np.exp(-odds)))
                        rows.append((f"P{person}", shape, strokes, speed, correct))
    frame = pd.DataFrame(rows, columns=["participant", "shape", "segments", "speed", "correct"])
    return frame.assign(log2_strokes=np.log2(frame["segments"].astype(float)))


def test_the_speed_test_finds_an_effect_all_show_and_rarely_one_that_is_not_there() -> None:
    found = speed_flip_test(_speed_answers(12, np.random.default_rng(1), slow_odds=3.0))
    assert found.flips == 2**12 and found.p == 2 / 2**12
    # 20 studies with no speed effect: a 5% test rejects in about 1; 4 or more: p = 0.016.
    rejected = sum(
        (speed_flip_test(_speed_answers(12, np.random.default_rng(s), 0.0)).p or 1) < 0.05
        for s in range(20)
    )
    assert rejected <= 3
    few = speed_flip_test(_speed_answers(MIN_SPEED_PARTICIPANTS - 1, np.random.default_rng(2), 3))
    assert few.p is None and few.refused is not None
    assert f"the speed test needs at least {MIN_SPEED_PARTICIPANTS}" in few.refused
    profile = speed_profiles(_speed_answers(8, np.random.default_rng(3), 1.0))
    assert profile.shape == (8, 2) and np.abs(profile.sum(axis=1)).max() < 1e-9


def test_the_calibration_bench_describes_itself_in_whole_sentences() -> None:
    import subprocess
    import sys

    shown = subprocess.run(
        [sys.executable, "-m", "feelmysign.bench.study_calibration", "--help"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert shown.returncode == 0, shown.stderr
    description = " ".join(shown.stdout.split("\n\n")[1].split())
    assert description.startswith("Calibration of the study analysis")
    assert "--speed-runs" in description and description.endswith(".")
