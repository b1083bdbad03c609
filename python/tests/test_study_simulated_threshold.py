"""A threshold dry run is stored as one, and never shown as a measurement; old files migrate."""

from __future__ import annotations

import csv
import json
import sqlite3
import subprocess
import sys
from pathlib import Path

from study_helpers import REPO

from feelmysign.study import StudyStore, load_design
from feelmysign.study.analysis import analyse_study

QUICK = REPO / "deploy" / "studies" / "quick.toml"


def test_a_simulated_observer_run_is_flagged_everywhere(tmp_path: Path) -> None:
    store = StudyStore.create(tmp_path / "s.sqlite", QUICK, load_design(QUICK))
    code = store.add_participant()  # a real participant: only the observer is simulated
    store.set_consent(code, True)
    result = subprocess.run(
        [
            *(sys.executable, "-m", "feelmysign", "study", "threshold", str(store.path)),
            *("--participant", code, "--dimension", "length", "--simulated-observer", "0.6"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    assert "Simulated length threshold (a dry run, stored as one): " in result.stdout
    assert ") (" not in result.stdout
    (run,) = store.threshold_runs(code)
    assert run["simulated"] == 1 and run["threshold"] is not None
    status = subprocess.run(
        [sys.executable, "-m", "feelmysign", "study", "status", str(store.path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert f"simulated threshold run (dry run) {run['id']} (length): 12 trials, finished" in (
        status.stdout
    )
    analyse_study(store, tmp_path / "out", samples=50)
    with (tmp_path / "out" / "threshold.csv").open() as file:
        rows = list(csv.DictReader(file))
    assert rows and {r["simulated"] for r in rows} == {"1"}
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert [r["simulated"] for r in results["thresholds"]] == [True]
    report = (tmp_path / "out" / "report.md").read_text()
    measured, _, simulated = report.partition("Simulated runs (dry runs, not measurements): 1")
    assert "No measured run." in measured and "| P01 | length |" in simulated
    assert "| P01 | length |" not in measured


def test_an_unknown_participant_is_said_before_any_broker_is_needed(tmp_path: Path) -> None:
    store = StudyStore.create(tmp_path / "s.sqlite", QUICK, load_design(QUICK))
    result = subprocess.run(
        [
            *(sys.executable, "-m", "feelmysign", "study", "threshold", str(store.path)),
            *("--participant", "P-NOPE", "--dimension", "length"),
            *("--broker", "mqtt://127.0.0.1:9"),  # nothing listens: never reached
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 1
    assert result.stderr.startswith("Error: no participant 'P-NOPE' in ")
    assert "study status" in result.stderr and "broker" not in result.stderr


def test_a_dry_run_never_continues_a_measured_run(tmp_path: Path) -> None:
    from feelmysign.study.threshold_run import open_run

    store = StudyStore.create(tmp_path / "s.sqlite", QUICK, load_design(QUICK))
    code = store.add_participant()
    store.set_consent(code, True)
    measured, _ = open_run(store, code, "length")
    dry, _ = open_run(store, code, "length", simulated=True)
    assert dry != measured
    assert open_run(store, code, "length")[0] == measured


def test_a_study_file_of_the_first_version_is_migrated_after_a_backup(tmp_path: Path) -> None:
    store = StudyStore.create(tmp_path / "old.sqlite", QUICK, load_design(QUICK))
    code = store.add_participant()
    store.set_consent(code, True)
    store.start_threshold_run(code, "length", {})
    store.close()
    db = sqlite3.connect(tmp_path / "old.sqlite")  # as the first version made it
    db.execute("ALTER TABLE threshold_runs DROP COLUMN simulated")
    db.execute("ALTER TABLE trials DROP COLUMN speed_cm_s")
    db.execute("UPDATE meta SET value = '1' WHERE key = 'schema_version'")
    db.commit()
    db.close()
    reopened = StudyStore(tmp_path / "old.sqlite")
    backup = tmp_path / "old.sqlite.schema-1.bak"
    assert reopened.migrated_from == backup and backup.is_file()
    assert reopened.meta("schema_version") == "3"
    (run,) = reopened.threshold_runs(code)
    assert run["simulated"] == 0  # a run of the old file is what it was: a measured one
    old = sqlite3.connect(backup)
    assert old.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone() == ("1",)
    assert old.execute("SELECT COUNT(*) FROM threshold_runs").fetchone() == (1,)
