"""The export: the comfort check as yes/no, and BIDS behavioural files that read back."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
from study_helpers import pilot_study

from feelmysign.study.export import export_study


def test_the_comfort_check_is_exported_as_yes_and_no(tmp_path: Path) -> None:
    store = pilot_study(tmp_path)
    first, second = store.add_participant(), store.add_participant()
    for code in (first, second):
        store.set_consent(code, True)
    store.record_comfort(first, [True, False], adjusted=True)
    store.record_comfort(second, [True, True], adjusted=False)
    export_study(store, tmp_path / "out")
    with (tmp_path / "out" / "comfort.csv").open() as file:
        rows = [
            (r["participant"], r["item"], r["question"], r["answer"], r["adjusted"])
            for r in csv.DictReader(file)
        ]
    assert rows == [
        ("P01", "1", "Does the sleeve sit comfortably?", "yes", "yes"),
        ("P01", "2", "Can you feel every motor?", "no", "yes"),
        ("P02", "1", "Does the sleeve sit comfortably?", "yes", "no"),
        ("P02", "2", "Can you feel every motor?", "yes", "no"),
    ]


def test_the_bids_files_read_back_as_the_trials_with_every_column_described(
    tmp_path: Path,
) -> None:
    import json

    import pandas as pd

    from feelmysign.study.dry_run import dry_run

    store = pilot_study(tmp_path)
    dry_run(store, 2, seed=1)
    export_study(store, tmp_path / "out")
    bids = tmp_path / "out" / "bids"
    description = json.loads((bids / "dataset_description.json").read_text())
    assert description["BIDSVersion"] and description["Name"] == "Pilot"
    people = pd.read_csv(bids / "participants.tsv", sep="\t")
    assert list(people["participant_id"]) == ["sub-01", "sub-02"]
    trials = pd.read_csv(tmp_path / "out" / "trials.csv", keep_default_na=False, dtype=str)
    for label, sub in (("P01", "sub-01"), ("P02", "sub-02")):
        stem = bids / sub / "beh" / f"{sub}_task-shapes_beh"
        table = pd.read_csv(f"{stem}.tsv", sep="\t", na_values=["n/a"], keep_default_na=False)
        sidecar = json.loads(Path(f"{stem}.json").read_text())
        assert sidecar["TaskName"] == "shapes"
        for column in table.columns:
            assert sidecar[column]["Description"], column  # every column described
        mine = trials[trials["participant"] == label]
        assert len(table) == len(mine) == 16
        assert list(table["shape"]) == list(mine["shape"])
        assert list(table["segments"]) == [int(v) for v in mine["segments"]]
        assert list(table["correct"].fillna(-1)) == [int(v) if v else -1 for v in mine["correct"]]
        assert list(table["response_time"]) == [float(v) for v in mine["response_time_s"]]
        assert sidecar["response_time"]["Units"] == "s"


def test_the_response_time_counts_from_the_send_the_answer_follows(tmp_path: Path) -> None:
    from feelmysign.study.export import trial_rows
    from feelmysign.study.runner import Session
    from feelmysign.study.simulated_sleeve import offline_player

    store = pilot_study(tmp_path)
    now = [1_000_000]
    store.clock = lambda: now[0]
    session = Session(store, None)
    session = Session(store, offline_player(session.layout))
    code = store.add_participant()
    session.consent(code, True)
    session.comfort(code, [True, True], adjusted=False)
    session.send(code)
    now[0] += 70_000  # a restart, or a long wait: the shape is sent again
    session.send(code)
    now[0] += 4_500
    session.answer(code, None, answer="circle", felt_nothing=False, confidence=3)
    (row,) = trial_rows(store)
    assert row["sends"] == 2 and row["response_time_s"] == 4.5


def test_latency_ms_max_is_what_its_description_says(tmp_path: Path) -> None:
    import json

    from feelmysign.study.dry_run import dry_run

    store = pilot_study(tmp_path)
    dry_run(store, 1, seed=1)
    export_study(store, tmp_path / "out")
    (path,) = (tmp_path / "out" / "bids").glob("sub-*/beh/*_beh.json")
    sidecar = json.loads(path.read_text())
    described = sidecar["latency_ms_max"]["Description"]
    assert "arrival at the sleeve to its first motor command" in described
    assert "including its wait behind the strokes queued before it" in described
    with (tmp_path / "out" / "trials.csv").open() as file:
        rows = list(csv.DictReader(file))
    checked = 0
    for row, trial in zip(rows, store.query("SELECT * FROM trials ORDER BY id"), strict=True):
        last = store.sends(trial["id"])[-1]
        latencies = [
            e["latency_ms"] for e in store.events(last["id"]) if e["type"] in ("played", "adjusted")
        ]
        if latencies:
            assert float(row["latency_ms_max"]) == round(max(latencies), 3)
            checked += 1
    assert checked > 0


def test_threshold_trials_say_what_the_sleeve_played_and_each_run_its_result(
    tmp_path: Path,
) -> None:
    """threshold.csv says per trial whether its stroke was played, and slowed to the sleeve's
    floor (then not at the value asked: a duration below the floor); threshold-runs.csv gives
    each run's result as the report does."""
    import random

    from study_helpers import new_study

    from feelmysign.apparent_motion import shortest_planned_ms
    from feelmysign.study.runner import Session
    from feelmysign.study.simulated_sleeve import offline_player
    from feelmysign.study.threshold import SimulatedObserver
    from feelmysign.study.threshold_run import run_threshold

    store = new_study(tmp_path)
    code = store.add_participant(simulated=True)
    store.set_consent(code, True)
    layout = Session(store, None).layout
    observer, rng = SimulatedObserver(90.0), random.Random(3)  # near the floor: some below
    estimate = run_threshold(
        store,
        code,
        "duration",
        layout,
        offline_player(layout),
        lambda direction, value: observer.respond(direction, value, rng),
        simulated=True,
    )
    export_study(store, tmp_path / "out")
    with (tmp_path / "out" / "threshold.csv").open() as file:
        rows = list(csv.DictReader(file))
    floor_ms = shortest_planned_ms(layout.shortest_burst_ms)
    assert rows and all(row["played"] == "1" and row["refused"] == "" for row in rows)
    below = [row for row in rows if float(row["value"]) < floor_ms]
    assert below, [row["value"] for row in rows]  # the grid reaches below the floor
    for row in rows:
        slowed = float(row["value"]) < floor_ms
        assert row["slowed"] == str(int(slowed)), row
        played_ms = float(row["played_ms"])
        assert played_ms == (
            pytest.approx(floor_ms, abs=0.01) if slowed else pytest.approx(float(row["value"]))
        ), row
    with (tmp_path / "out" / "threshold-runs.csv").open() as file:
        (run,) = list(csv.DictReader(file))
    assert run["participant"] == "P01" and run["dimension"] == "duration"
    assert int(run["trials"]) == len(rows) == estimate.trials
    assert float(run["threshold"]) == pytest.approx(estimate.threshold)
    assert run["censored"] == (estimate.censored or "") and run["stop_reason"]
