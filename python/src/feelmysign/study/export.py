"""Export a study: anonymised long-format CSV (one row per trial), the questionnaire, the
comfort check, the threshold trials, and the design as JSON.

Anonymised: participant codes are replaced by P01, P02, ... in the order they
were added (the codes may be on signed consent forms; the export must not link
to them), no times of day are exported (only durations), and no comfort notes
exist to leak (the comfort check is yes/no). The free answers are exported:
they are what was coded, and a reader may re-code them.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

from feelmysign.study.bids import export_bids
from feelmysign.study.design import Design
from feelmysign.study.runner import events_summary
from feelmysign.study.store import StudyStore

TRIAL_COLUMNS = (
    "participant",
    "simulated",
    "trial",
    "block",
    "repetition",
    "shape",
    "resolution",
    "level",
    "segments",
    "answer",
    "felt_nothing",
    "confidence",
    "coded_status",
    "coded_shape",
    "coded_by",
    "decisions",
    "correct",
    "sends",
    "played",
    "adjusted",
    "rejected",
    "late",
    "compressed",
    "compressed_ms",
    "latency_ms_max",
    "felt_duration_ms",
    "response_time_s",
)


SPEED_COLUMN = "speed_cm_s"


def trial_columns(design: Design) -> tuple[str, ...]:
    """trials.csv's columns: with speed as a factor of the design, each trial's speed after its
    segments (a design of one speed keeps the columns it always had; its speed is in
    design.json)."""
    if not design.speed_is_factor:
        return TRIAL_COLUMNS
    at = TRIAL_COLUMNS.index("segments") + 1
    return (*TRIAL_COLUMNS[:at], SPEED_COLUMN, *TRIAL_COLUMNS[at:])


def anonymous_labels(store: StudyStore) -> dict[str, str]:
    rows = store.participants()
    width = max(2, len(str(len(rows))))
    return {row["code"]: f"P{row['number'] + 1:0{width}d}" for row in rows}


def trial_rows(store: StudyStore) -> list[dict[str, Any]]:
    """Every answered trial with its coding in force and its sleeve events, anonymised."""
    labels = anonymous_labels(store)
    codings = store.latest_codings()
    decisions = {
        int(r["trial"]): int(r["n"])
        for r in store.query("SELECT trial, COUNT(*) AS n FROM codings GROUP BY trial")
    }
    design = store.design
    starts = store.runner_starts()
    out = []
    for participant in store.participants():
        for trial in store.trials(participant["code"]):
            if trial["answered_at_ms"] is None:
                continue
            coding = codings.get(trial["id"])
            sends = store.sends(trial["id"])
            events = [json.loads(e["json"]) for s in sends[-1:] for e in store.events(s["id"])]
            strokes = len(json.loads(sends[-1]["strokes_json"])) if sends else 0
            summary = events_summary(events, strokes)
            status = coding["status"] if coding else "unclear"
            correct = (
                ""
                if status == "unclear"
                else int(coding is not None and coding["shape"] == trial["shape"])
            )
            level = trial["level"]
            # From the send the answer follows (a repeat send restarts the clock; so does a
            # restart of the session, which sends again).
            last_sent = sends[-1]["sent_at_ms"] if sends else trial["answered_at_ms"]
            answered = trial["answered_at_ms"]
            # A runner started between the send and the answer: it crashed or was stopped
            # with the shape felt and not answered. The time no runner ran is no response
            # time, and how long the participant took is not known: left out.
            resumed = any(last_sent < at <= answered for at in starts)
            response_s = "" if resumed else round((answered - last_sent) / 1000, 3)
            speed = {} if not design.speed_is_factor else {SPEED_COLUMN: trial["speed_cm_s"]}
            out.append(
                {
                    "participant": labels[participant["code"]],
                    "simulated": int(participant["simulated"]),
                    "trial": trial["position"] + 1,
                    "block": trial["block"],
                    "repetition": trial["repetition"],
                    "shape": trial["shape"],
                    "resolution": "" if level is None else design.resolutions[level],
                    "level": "" if level is None else level + 1,
                    "segments": trial["segments"],
                    **speed,
                    "answer": trial["answer"],
                    "felt_nothing": trial["felt_nothing"],
                    "confidence": "" if trial["confidence"] is None else trial["confidence"],
                    "coded_status": status,
                    "coded_shape": (coding["shape"] if coding else None) or "",
                    "coded_by": coding["decided_by"] if coding else "",
                    "decisions": decisions.get(trial["id"], 0),
                    "correct": correct,
                    "sends": len(sends),
                    "played": summary["played"],
                    "adjusted": summary["adjusted"],
                    "rejected": len(summary["rejected"]),
                    "late": summary["late"],
                    "compressed": summary["compressed"],
                    "compressed_ms": summary["compressed_ms"],
                    "latency_ms_max": ""
                    if summary["latency_ms_max"] is None
                    else summary["latency_ms_max"],
                    "felt_duration_ms": summary["felt_duration_ms"],
                    "response_time_s": response_s,
                }
            )
    return out


def questionnaire_rows(store: StudyStore) -> list[dict[str, Any]]:
    labels = anonymous_labels(store)
    items = store.design.questionnaire.items
    rows = store.query("SELECT * FROM questionnaire ORDER BY participant, item")
    return [
        {
            "participant": labels[r["participant"]],
            "item": r["item"] + 1,
            "text": items[r["item"]],
            "value": r["value"],
        }
        for r in sorted(rows, key=lambda r: (labels[r["participant"]], r["item"]))
    ]


COMFORT_COLUMNS = ("participant", "simulated", "item", "question", "answer", "adjusted")


def comfort_rows(store: StudyStore) -> list[dict[str, Any]]:
    """The comfort check (section 6.1 step 2), one row per participant and question: the
    answer yes/no, and whether the sleeve was adjusted (the same on each of their rows)."""
    labels = anonymous_labels(store)
    questions = store.design.comfort
    out = []
    for participant in store.participants():
        if participant["comfort_json"] is None:
            continue
        check = json.loads(participant["comfort_json"])
        for item, answer in enumerate(check["answers"]):
            out.append(
                {
                    "participant": labels[participant["code"]],
                    "simulated": int(participant["simulated"]),
                    "item": item + 1,
                    "question": questions[item] if item < len(questions) else "",
                    "answer": "yes" if answer else "no",
                    "adjusted": "yes" if check["adjusted"] else "no",
                }
            )
    return out


THRESHOLD_COLUMNS = (
    "participant",
    "run",
    "simulated",
    "dimension",
    "trial",
    "value",
    "direction",
    "response",
    "correct",
    "played",
    "slowed",
    "played_ms",
    "refused",
)
THRESHOLD_RUN_COLUMNS = (
    "participant",
    "run",
    "simulated",
    "dimension",
    "trials",
    "threshold",
    "low",
    "high",
    "censored",
    "stop_reason",
)


def _stroke_outcome(events_json: str) -> dict[str, Any]:
    """What the sleeve did with a threshold trial's one stroke: played (1/0), slowed to its
    floor (1/0: the stroke was not felt at the value asked), the duration it played, and a
    refusal's reason."""
    events = json.loads(events_json)
    played = [e for e in events if e.get("type") in ("played", "adjusted")]
    refused = [e for e in events if e.get("type") == "rejected"]
    if played:
        event = played[0]
        return {
            "played": 1,
            "slowed": int(event.get("type") == "adjusted"),
            "played_ms": event.get("duration_ms", ""),
            "refused": "",
        }
    return {
        "played": 0,
        "slowed": 0,
        "played_ms": "",
        "refused": refused[0].get("reason", "") if refused else "",
    }


def threshold_rows(store: StudyStore) -> list[dict[str, Any]]:
    """threshold.csv: every trial of every run, with what the sleeve did with its stroke."""
    labels = anonymous_labels(store)
    out = []
    for run in store.threshold_runs():
        for trial in store.threshold_trials(run["id"]):
            out.append(
                {
                    "participant": labels[run["participant"]],
                    "run": run["id"],
                    "simulated": int(run["simulated"]),
                    "dimension": run["dimension"],
                    "trial": trial["position"] + 1,
                    "value": trial["value"],
                    "direction": trial["direction"],
                    "response": trial["response"],
                    "correct": trial["correct"],
                    **_stroke_outcome(trial["events_json"]),
                }
            )
    return out


def threshold_run_rows(store: StudyStore) -> list[dict[str, Any]]:
    """threshold-runs.csv: one row per run, its result (as the report and results.json give
    it: empty while unfinished or discarded)."""
    from feelmysign.study.analysis.analyse import threshold_summaries

    runs = store.threshold_runs()
    return [
        {
            "participant": summary["participant"],
            "run": run["id"],
            "simulated": int(summary["simulated"]),
            "dimension": summary["dimension"],
            "trials": summary["trials"],
            "threshold": "" if summary["threshold"] is None else summary["threshold"],
            "low": "" if summary["low"] is None else summary["low"],
            "high": "" if summary["high"] is None else summary["high"],
            "censored": summary["censored"] or "",
            "stop_reason": summary["stop_reason"] or "",
        }
        for run, summary in zip(runs, threshold_summaries(store), strict=True)
    ]


def _write_csv(path: Path, rows: list[dict[str, Any]], columns: tuple[str, ...]) -> None:
    with path.open("w", newline="", encoding="utf-8") as file:
        writer = csv.DictWriter(file, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)


def export_study(store: StudyStore, out_dir: Path) -> list[Path]:
    """Write trials.csv, questionnaire.csv, comfort.csv, threshold.csv, threshold-runs.csv and
    design.json into ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    files = {
        "trials.csv": (trial_rows(store), trial_columns(store.design)),
        "questionnaire.csv": (questionnaire_rows(store), ("participant", "item", "text", "value")),
        "comfort.csv": (comfort_rows(store), COMFORT_COLUMNS),
        "threshold.csv": (threshold_rows(store), THRESHOLD_COLUMNS),
        "threshold-runs.csv": (threshold_run_rows(store), THRESHOLD_RUN_COLUMNS),
    }
    written = []
    trials = files["trials.csv"][0]
    for name, (rows, columns) in files.items():
        _write_csv(out_dir / name, rows, columns)
        written.append(out_dir / name)
    design = out_dir / "design.json"
    design.write_text(json.dumps(store.design.to_json(), indent=2) + "\n", encoding="utf-8")
    written.append(design)
    written += export_bids(store, trials, out_dir / "bids")
    return written
