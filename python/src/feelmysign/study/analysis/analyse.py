"""Analyse a study file: accuracy tables, psychometric fits, the shape model, plots, report.

Only main trials with a coded answer count; unclear answers still waiting for
review are left out and counted in the report (so a report is never silently
incomplete). Simulated participants are analysed like real ones but the report
says how many there were.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from feelmysign.study.analysis.models import ModelResult, shape_differences
from feelmysign.study.analysis.plots import accuracy_plot, threshold_plot
from feelmysign.study.analysis.psychometric import (
    Interval,
    Needed,
    Threshold,
    counts_by_level,
    threshold_with_interval,
    within_tested,
)
from feelmysign.study.analysis.report import (
    cluster_not_estimable,
    dispersion_not_estimable,
    model_sd_not_estimable,
    slope_not_estimable,
    spread_not_estimable,
    write_report,
)
from feelmysign.study.analysis.wilson import wilson_interval
from feelmysign.study.choices import BOOTSTRAP_SAMPLES
from feelmysign.study.export import SPEED_COLUMN, anonymous_labels, export_study, trial_rows
from feelmysign.study.simulated import simulated_truth
from feelmysign.study.store import StudyStore


@dataclass(frozen=True)
class Analysis:
    participants: int
    simulated: int
    trials: int
    unclear: int
    accuracy: dict[str, list[tuple[int, int, int, float, float]]]  # strokes, k, n, low, high
    thresholds: dict[str, Threshold]
    needed: dict[str, Needed]  # the thresholds as far as the tested range can say
    model: ModelResult | None
    criterion: float
    files: list[Path]
    threshold_runs: list[dict[str, Any]]
    per_participant: list[dict[str, Any]]  # one row per participant (anonymised)
    # A dry run's known truth (in-range simulated wearers), None for a study without one.
    simulated_truth: dict[str, Any] | None = None
    # Speed a factor of the design: its speeds, and for each key of accuracy, thresholds and
    # needed (then "circle at 3 cm/s") the shape and speed it is of. A design of one speed:
    # () and the keys are the shapes' names.
    speeds: tuple[float, ...] = ()
    cells: dict[str, tuple[str, float | None]] = field(default_factory=dict)

    def shape_of(self, key: str) -> str:
        return self.cells[key][0] if key in self.cells else key


def cell_label(shape: str, speed: float) -> str:
    """A shape at one speed, as the report, the figures and results.json name it."""
    return f"{shape} at {speed:g} cm/s"


def main_trials(store: StudyStore) -> pd.DataFrame:
    rows = [r for r in trial_rows(store) if r["block"] == "main"]
    return pd.DataFrame(rows)


def analyse_study(
    store: StudyStore, out_dir: Path, *, samples: int = BOOTSTRAP_SAMPLES, seed: int = 0
) -> Analysis:
    """Export, then analyse into ``out_dir``: CSVs, design.json, PNGs, report.md, results.json."""
    files = export_study(store, out_dir)
    design = store.design
    frame = main_trials(store)
    unclear = int((frame["coded_status"] == "unclear").sum()) if len(frame) else 0
    coded = frame[frame["coded_status"] != "unclear"].copy() if len(frame) else frame
    if len(coded):
        coded["correct"] = coded["correct"].astype(int)
    accuracy: dict[str, list[tuple[int, int, int, float, float]]] = {}
    thresholds: dict[str, Threshold] = {}
    # Speed a factor: each shape at each speed is read on its own, by the same rules.
    speeds = design.speeds if design.speed_is_factor else ()
    cells: dict[str, tuple[str, float | None]] = {}
    for shape in design.shapes:
        for speed in speeds or (None,):
            key = shape.name if speed is None else cell_label(shape.name, speed)
            cells[key] = (shape.name, speed)
    for key, (name, speed) in cells.items():
        shape = design.shape(name)
        levels = np.array(sorted({lv.strokes for lv in shape.levels}), dtype=float)
        mine = coded[coded["shape"] == shape.name] if len(coded) else coded
        if speed is not None and len(mine):
            mine = mine[mine[SPEED_COLUMN] == speed]
        rows = []
        for strokes in levels:
            at = mine[mine["segments"] == strokes] if len(mine) else mine
            k, n = int(at["correct"].sum()) if len(at) else 0, len(at)
            rows.append((int(strokes), k, n, *wilson_interval(k, n)))
        accuracy[key] = rows
        if len(mine) and len(levels) > 1:
            per_participant = [
                counts_by_level(
                    group["segments"].to_numpy(float), group["correct"].to_numpy(float), levels
                )
                for _, group in mine.groupby("participant")
            ]
            thresholds[key] = threshold_with_interval(
                per_participant,
                levels,
                criterion=design.criterion,
                guess=design.guess_rate,
                samples=samples,
                seed=seed,
            )
    needed = {}
    for name, threshold in thresholds.items():
        answered = [(strokes, k / n) for strokes, k, n, _, _ in accuracy[name] if n]
        tested = (float(answered[0][0]), float(answered[-1][0]))
        needed[name] = within_tested(
            threshold, tested, [share for _, share in answered], design.criterion
        )
    model = None
    if len(coded) and coded["shape"].nunique() > 1:
        columns = ["participant", "shape", "segments", "correct"]
        if speeds:
            columns.append(SPEED_COLUMN)
        model = shape_differences(coded[columns].rename(columns={SPEED_COLUMN: "speed"}), seed=seed)
    participants = store.participants()
    analysis = Analysis(
        participants=int(frame["participant"].nunique()) if len(frame) else 0,
        simulated=sum(1 for p in participants if p["simulated"]),
        trials=len(frame),
        unclear=unclear,
        accuracy=accuracy,
        thresholds=thresholds,
        needed=needed,
        model=model,
        criterion=design.criterion,
        files=files,
        threshold_runs=threshold_summaries(store),
        per_participant=participant_table(frame, [s.name for s in design.shapes], speeds),
        simulated_truth=_truth_with_labels(store),
        speeds=speeds,
        cells=cells if speeds else {},
    )
    panels = {f"{speed:g} cm/s": [k for k, c in cells.items() if c[1] == speed] for speed in speeds}
    files.append(
        accuracy_plot(
            out_dir / "accuracy.png", accuracy, thresholds, design.criterion, panels or None
        )
    )
    if needed:
        path = out_dir / "needed-resolution.png"
        files.append(threshold_plot(path, needed, design.criterion))
    files.append(_results_json(out_dir / "results.json", analysis))
    files.append(write_report(out_dir / "report.md", store, analysis))
    return analysis


def _truth_with_labels(store: StudyStore) -> dict[str, Any] | None:
    """A dry run's known truth, its participants named as in the export (P01, ...)."""
    truth = simulated_truth(store)
    if truth is None:
        return None
    numbers, labels = set(truth["participants"]), anonymous_labels(store)
    named = [labels[p["code"]] for p in store.participants() if p["number"] in numbers]
    return truth | {"participants": named}


def participant_table(
    frame: pd.DataFrame, shapes: list[str], speeds: tuple[float, ...] = ()
) -> list[dict[str, Any]]:
    """Per participant: measured trials answered, how many await review, and the correct
    ones overall and per shape (of the coded ones); per speed too when speed is a factor."""
    if not len(frame):
        return []
    rows = []
    for label, mine in frame.groupby("participant", sort=True):
        coded = mine[mine["coded_status"] != "unclear"]
        correct = coded["correct"].astype(int)
        rows.append(
            {
                "participant": str(label),
                "simulated": bool(int(mine["simulated"].iloc[0])),
                "trials": len(mine),
                "unclear": len(mine) - len(coded),
                "correct": int(correct.sum()),
                "coded": len(coded),
                "by_shape": {
                    shape: [
                        int(correct[coded["shape"] == shape].sum()),
                        int((coded["shape"] == shape).sum()),
                    ]
                    for shape in shapes
                },
            }
        )
        if speeds:
            rows[-1]["by_speed"] = {
                f"{speed:g}": [
                    int(correct[coded[SPEED_COLUMN] == speed].sum()),
                    int((coded[SPEED_COLUMN] == speed).sum()),
                ]
                for speed in speeds
            }
    return rows


def threshold_summaries(store: StudyStore) -> list[dict[str, Any]]:
    """Every threshold run (SQ2.2), anonymised, with its result when it has finished, whether
    its interval reaches an end of the tested range (``censored``), and whether it is a dry
    run (``simulated``: the report keeps those apart)."""
    from feelmysign.study.threshold import censored, dimension_settings

    labels = anonymous_labels(store)
    design = store.design.threshold
    return [
        {
            "participant": labels[run["participant"]],
            "simulated": bool(run["simulated"]),
            "dimension": run["dimension"],
            "threshold": run["threshold"],
            "low": run["low"],
            "high": run["high"],
            # Where the interval reaches an end of the tested range: "above" (not measured),
            # "below" (a bound); None: measured, or not finished.
            "censored": None
            if run["threshold"] is None
            else censored(dimension_settings(design, run["dimension"]), run["low"], run["high"]),
            "trials": len(store.threshold_trials(run["id"])),
            "stop_reason": run["stop_reason"],
        }
        for run in store.threshold_runs()
    ]


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _interval_json(prefix: str, interval: Interval) -> dict[str, Any]:
    """An interval's ends within the tested range; ``*_open``: it reaches beyond that end."""
    return {
        f"{prefix}low": interval.low,
        f"{prefix}low_open": interval.low_open,
        f"{prefix}high": interval.high,
        f"{prefix}high_open": interval.high_open,
    }


def _estimate_json(name: str, value: Any, why_not: str | None) -> dict[str, Any]:
    """A number the report gives, or null with the report's reason where it says the data
    cannot estimate it (``NAME_not_estimable``), so no reader of results.json takes it."""
    return {name: None if why_not is not None else value, f"{name}_not_estimable": why_not}


def _needed_json(analysis: Analysis, shape: str, needed: Needed) -> dict[str, Any]:
    threshold = analysis.thresholds[shape]
    participants = analysis.participants
    cluster_why = cluster_not_estimable(needed.cluster, participants)
    cluster = _interval_json("cluster_bootstrap_", needed.cluster)
    if cluster_why is not None:
        cluster = dict.fromkeys(cluster)
    return {
        "kind": needed.kind,
        "strokes": needed.strokes,
        "lowest_tested": needed.lowest_tested,
        "highest_tested": needed.highest_tested,
        "interval": "parametric bootstrap with the participants' spread, "
        "bias-corrected percentiles, truncated to the tested range",
        **_interval_json("", needed.interval),
        **_interval_json("profile_", needed.profile),
        **cluster,
        "cluster_bootstrap_not_estimable": cluster_why,
        **_estimate_json(
            "dispersion",
            _finite(threshold.dispersion),
            dispersion_not_estimable(threshold.dispersion, participants),
        ),
        **_estimate_json(
            "participant_sd_doublings",
            threshold.population.spread,
            spread_not_estimable(threshold.population.spread, participants),
        ),
        "bootstrap_samples": threshold.samples,
        "midpoint_log2": threshold.fit.midpoint,
        **_estimate_json(
            "slope_per_doubling", threshold.fit.slope, slope_not_estimable(threshold.fit.slope)
        ),
    }


def _results_json(path: Path, analysis: Analysis) -> Path:
    data: dict[str, Any] = {
        "participants": analysis.participants,
        "trials": analysis.trials,
        "unclear": analysis.unclear,
        "criterion": analysis.criterion,
        "accuracy": {
            shape: [
                dict(zip(("strokes", "correct", "total", "low", "high"), r, strict=True))
                for r in rows
            ]
            for shape, rows in analysis.accuracy.items()
        },
        "needed_strokes": {
            shape: _needed_json(analysis, shape, needed)
            for shape, needed in analysis.needed.items()
        },
        "shape_model": _model_json(analysis),
        "thresholds": analysis.threshold_runs,
        "per_participant": analysis.per_participant,
        # A dry run with in-range simulated wearers: their curves, to compare with the
        # estimates above ("participants": those who answered by it, as labelled above).
        "simulated_truth": analysis.simulated_truth,
    }
    if analysis.speeds:
        # Speed a factor: accuracy and needed_strokes are per shape and speed, keyed as the
        # report names them ("circle at 3 cm/s"); cells says which shape and speed each is.
        data["speeds_cm_s"] = list(analysis.speeds)
        data["cells"] = {
            key: {"shape": shape, "speed_cm_s": speed}
            for key, (shape, speed) in analysis.cells.items()
        }
        for key, entry in data["needed_strokes"].items():
            entry["shape"], entry["speed_cm_s"] = analysis.cells[key]
    path.write_text(json.dumps(data, indent=2, default=str) + "\n", encoding="utf-8")
    return path


def _model_json(analysis: Analysis) -> dict[str, Any] | None:
    """The shape model; its speed test and effects only when speed is a factor (a design of
    one speed gives what it always gave)."""
    if analysis.model is None:
        return None
    data = asdict(analysis.model)
    data.update(
        _estimate_json(
            "participant_sd",
            data["participant_sd"],
            model_sd_not_estimable(analysis.participants),
        )
    )
    if not analysis.speeds:
        for key in ("speed_test", "speed_effects", "reference_speed_cm_s"):
            del data[key]
    return data
