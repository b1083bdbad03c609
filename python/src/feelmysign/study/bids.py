"""The trials in BIDS, the community layout for behavioural data (Brain Imaging Data Structure,
behavioural files: https://bids-specification.readthedocs.io, "Behavioral experiments").

    bids/dataset_description.json
    bids/participants.tsv, participants.json
    bids/sub-01/beh/sub-01_task-shapes_beh.tsv    one row per answered trial
    bids/sub-01/beh/sub-01_task-shapes_beh.json   every column described, with units and levels

The same rows as ``trials.csv`` (anonymised the same way: P01 is sub-01), tab-separated,
``n/a`` for a value that does not apply, and the response time in seconds as
``response_time`` (BIDS's own name for it).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

from feelmysign.study.design import Design
from feelmysign.study.store import StudyStore

BIDS_VERSION = "1.9.0"
TASK = "shapes"

# Every column of the _beh.tsv, as its sidecar describes it (BIDS: Description, Units, Levels).
COLUMNS: dict[str, dict[str, Any]] = {
    "trial": {"Description": "Position of the trial in the participant's session, from 1."},
    "block": {
        "Description": "Practice trials come first and are not analysed.",
        "Levels": {"practice": "told the shape beforehand", "main": "measured"},
    },
    "repetition": {"Description": "Repetition block of the measured trials, from 1; 0: practice."},
    "shape": {"Description": "The shape sent to the sleeve (the design's name for it)."},
    "resolution": {"Description": "The resolution's label in the design, coarse to fine."},
    "level": {"Description": "The resolution's index in the design, from 1 (coarsest)."},
    "segments": {"Description": "Straight strokes the shape was sent as.", "Units": "strokes"},
    # Only in a design with speed as a factor (beh_columns).
    "speed_cm_s": {
        "Description": (
            "Drawing speed of the trial: every stroke lasts its length on the sleeve at this "
            "speed (a factor of the design, crossed with shape, resolution and repetition)."
        ),
        "Units": "cm/s",
    },
    "answer": {"Description": "The participant's free answer, as typed by the researcher."},
    "felt_nothing": {
        "Description": "The participant felt nothing.",
        "Levels": {"0": "felt something", "1": "felt nothing"},
    },
    "confidence": {"Description": "Confidence in the answer, 1 (guess) to 5 (certain)."},
    "coded_status": {
        "Description": "The coding of the answer in force.",
        "Levels": {
            "shape": "coded as one of the design's shapes",
            "none": "no shape named (felt nothing, don't know, or decided so)",
            "unclear": "awaits the researcher's review; left out of the analysis",
        },
    },
    "coded_shape": {"Description": "The shape the answer was coded as."},
    "coded_by": {
        "Description": "Who made the coding in force.",
        "Levels": {"auto": "synonym rules", "researcher": "the researcher's blind review"},
    },
    "decisions": {"Description": "Coding decisions made for this answer (all kept)."},
    "correct": {
        "Description": "The coded shape is the shape sent.",
        "Levels": {"0": "wrong or none", "1": "correct"},
    },
    "sends": {"Description": "Times the shape was sent (a repeat send plays it again)."},
    "played": {"Description": "Strokes the sleeve reported played, last send.", "Units": "strokes"},
    "adjusted": {
        "Description": "Strokes the sleeve slowed to its shortest felt duration, last send.",
        "Units": "strokes",
    },
    "rejected": {"Description": "Strokes the sleeve refused, last send.", "Units": "strokes"},
    "late": {
        "Description": (
            "Strokes the sleeve skipped as too late to catch up with the drawing (counted "
            "under rejected too), last send."
        ),
        "Units": "strokes",
    },
    "compressed": {
        "Description": (
            "Strokes the sleeve played faster than sent, to catch up with the drawing after a "
            "queue (by 5 % of their duration or more), last send."
        ),
        "Units": "strokes",
    },
    "compressed_ms": {
        "Description": "How much shorter those strokes played, in all, last send.",
        "Units": "ms",
    },
    "latency_ms_max": {
        "Description": (
            "Longest time of a stroke from its arrival at the sleeve to its first motor "
            "command, last send, including its wait behind the strokes queued before it "
            "(feelmysign up's 'start delay' leaves that wait out, so it is shorter)."
        ),
        "Units": "ms",
    },
    "felt_duration_ms": {
        "Description": "Total vibration time of the strokes played, last send.",
        "Units": "ms",
    },
    "response_time": {
        "Description": "From the last send of the shape (the one answered) to the answer.",
        "Units": "s",
    },
    "simulated": {
        "Description": "A simulated participant (a dry run), not a person.",
        "Levels": {"0": "a person", "1": "simulated"},
    },
}


def beh_columns(design: Design) -> dict[str, dict[str, Any]]:
    """The _beh.tsv's columns, as ``COLUMNS``: speed_cm_s only when speed is a factor of the
    design (a design of one speed gives it in the task description)."""
    if design.speed_is_factor:
        return COLUMNS
    return {name: column for name, column in COLUMNS.items() if name != "speed_cm_s"}


PARTICIPANT_COLUMNS: dict[str, dict[str, Any]] = {
    "participant_id": {"Description": "sub-<number>: P<number> in the study's other files."},
    "simulated": COLUMNS["simulated"],
}


def subject(label: str) -> str:
    """``P01`` -> ``sub-01`` (BIDS labels are alphanumeric)."""
    return f"sub-{label.removeprefix('P')}"


def _cell(value: Any) -> str:
    return "n/a" if value is None or value == "" else str(value)


def _write_tsv(path: Path, rows: list[dict[str, Any]], columns: list[str]) -> None:
    with path.open("w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file, delimiter="\t", lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            # A tab or newline inside a free answer would break the table: BIDS has no quoting.
            writer.writerow([_cell(row[c]).replace("\t", " ").replace("\n", " ") for c in columns])


def _write_json(path: Path, data: dict[str, Any]) -> None:
    path.write_text(json.dumps(data, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")


def export_bids(store: StudyStore, rows: list[dict[str, Any]], out_dir: Path) -> list[Path]:
    """``rows``: ``export.trial_rows``. Writes the dataset into ``out_dir``; the files made."""
    out_dir.mkdir(parents=True, exist_ok=True)
    written = [out_dir / "dataset_description.json"]
    _write_json(
        written[0],
        {
            "Name": store.design.name,
            "BIDSVersion": BIDS_VERSION,
            "DatasetType": "raw",
            "GeneratedBy": [{"Name": "feelmysign study export"}],
        },
    )
    by_participant: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        by_participant.setdefault(row["participant"], []).append(row)
    people = [
        {"participant_id": subject(label), "simulated": group[0]["simulated"]}
        for label, group in by_participant.items()
    ]
    _write_tsv(out_dir / "participants.tsv", people, list(PARTICIPANT_COLUMNS))
    _write_json(out_dir / "participants.json", PARTICIPANT_COLUMNS)
    written += [out_dir / "participants.tsv", out_dir / "participants.json"]
    for label, group in by_participant.items():
        folder = out_dir / subject(label) / "beh"
        folder.mkdir(parents=True, exist_ok=True)
        stem = f"{subject(label)}_task-{TASK}_beh"
        table = [{**r, "response_time": r["response_time_s"]} for r in group]
        columns = beh_columns(store.design)
        _write_tsv(folder / f"{stem}.tsv", table, list(columns))
        _write_json(
            folder / f"{stem}.json",
            {"TaskName": TASK, "TaskDescription": _task(store), **columns},
        )
        written += [folder / f"{stem}.tsv", folder / f"{stem}.json"]
    return written


def _task(store: StudyStore) -> str:
    design = store.design
    speeds = ", ".join(f"{speed:g}" for speed in design.speeds)
    at_speeds = f" x {len(design.speeds)} drawing speeds ({speeds} cm/s)"
    return (
        f"{design.name}: shapes drawn on the forearm by a grid of vibration motors, each at "
        f"{len(design.resolutions)} resolutions ({', '.join(design.resolutions)})"
        f"{at_speeds if design.speed_is_factor else ''} x "
        f"{design.repetitions} repetitions; the participant names each shape freely, and the "
        "answers are coded to shapes by synonyms or the researcher's blind review."
    )
