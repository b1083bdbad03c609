"""A study file made before speed could be a factor (schema 2) opens: migrated after a backup,
every trial given the speed it was played at, and its export the same as the old version's."""

from __future__ import annotations

import csv
import json
import shutil
import sqlite3
from pathlib import Path

from study_helpers import zigzag_recording

from feelmysign.study import StudyStore, load_design
from feelmysign.study.export import export_study

# Made by feelmysign at schema 2 (study new tests/study_files/schema-2/pilot.toml, study
# simulate --participants 2 --seed 5, study export), before trials had a speed: the file and
# the export that version wrote from it.
OLD = Path(__file__).parent / "study_files" / "schema-2"
# The trials' columns added since that version, and their values for its file.
ADDED = {"late": "0", "compressed": "0", "compressed_ms": "0.0"}


def test_a_file_of_schema_2_is_migrated_after_a_backup_and_exports_as_before(
    tmp_path: Path,
) -> None:
    path = tmp_path / "old.sqlite"
    shutil.copy(OLD / "schema-2.sqlite", path)
    store = StudyStore(path)
    backup = tmp_path / "old.sqlite.schema-2.bak"
    assert store.migrated_from == backup and store.meta("schema_version") == "3"
    assert not store.design.speed_is_factor and store.design.speeds == (8.0,)
    trials = [t for p in store.participants() for t in store.trials(p["code"])]
    assert len(trials) == 10 and {t["speed_cm_s"] for t in trials} == {8.0}
    export = export_study(store, tmp_path / "export")
    names = {path.name: path for path in export}
    assert names["design.json"].read_bytes() == (OLD / "design.json").read_bytes()
    # The same columns with the same values, and the columns added since: the sleeve's
    # catching up (all 0: a study's shape is sent at once and plays at its own pace).
    for name, delimiter in (("trials.csv", ","), ("sub-01_task-shapes_beh.tsv", "\t")):
        rows, old_rows = (
            list(csv.DictReader(path.read_text().splitlines(), delimiter=delimiter))
            for path in (names[name], OLD / name)
        )
        assert len(rows) == len(old_rows) > 0
        for row, old_row in zip(rows, old_rows, strict=True):
            assert {k: row[k] for k in old_row} == old_row, name
            assert {k: row[k] for k in row.keys() - old_row.keys()} == ADDED, name
    sidecar = json.loads(names["sub-01_task-shapes_beh.json"].read_text())
    old_sidecar = json.loads((OLD / "sub-01_task-shapes_beh.json").read_text())
    assert {k: sidecar[k] for k in old_sidecar} == old_sidecar
    assert sidecar.keys() - old_sidecar.keys() == ADDED.keys()
    store.close()
    old = sqlite3.connect(backup)  # the backup is the file as the old version left it
    assert old.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone() == ("2",)
    assert "speed_cm_s" not in [row[1] for row in old.execute("PRAGMA table_info(trials)")]
    old.close()
    assert StudyStore(path).migrated_from is None  # opened again: nothing more to do


def test_a_recorded_drawing_of_an_old_file_keeps_its_own_timing(tmp_path: Path) -> None:
    """Version 2 played a recorded drawing at the hand's timing: its trials get no speed."""
    zigzag_recording(tmp_path / "zigzag.json")
    design = tmp_path / "design.toml"
    design.write_text(
        (OLD / "pilot.toml").read_text()
        + '[[shapes]]\nname = "zigzag"\nrecording = "zigzag.json"\nsimplifier = "window"\n'
        "settings = [{max_error = 1.5, max_stroke_ms = 400}, {max_error = 0.05}]\n"
    )
    store = StudyStore.create(tmp_path / "s.sqlite", design, load_design(design))
    store.add_participant()
    store.close()
    db = sqlite3.connect(tmp_path / "s.sqlite")  # as version 2 made it
    db.execute("ALTER TABLE trials DROP COLUMN speed_cm_s")
    db.execute("UPDATE meta SET value = '2' WHERE key = 'schema_version'")
    db.commit()
    db.close()
    store = StudyStore(tmp_path / "s.sqlite")
    speeds = {(t["shape"], t["speed_cm_s"]) for t in store.trials(store.participants()[0]["code"])}
    assert speeds == {("line", 8.0), ("circle", 8.0), ("triangle", 8.0), ("zigzag", None)}
