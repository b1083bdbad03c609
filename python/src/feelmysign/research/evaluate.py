"""Run simplifiers over recordings and parameter grids, and measure every result.

One ``Row`` per recording x algorithm x parameter set; ``summarize`` folds
them per algorithm and parameter set; ``frontier`` runs offline
Douglas-Peucker over a range of errors on the same frames. Every recording is
run with its canvas and sleeve and the algorithm's defaults, overridden only
by the parameter set, so that one set means the same on every recording (the
parameters a recording's sender used are not applied).
"""

from __future__ import annotations

import csv
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from feelmysign.research import metrics
from feelmysign.research.rerun import rerun
from feelmysign.research.sweep import label
from feelmysign.simplify.recording import Recording
from feelmysign.simplify.registry import Algorithm, Params
from feelmysign.simplify.segment import Sample

# Errors (grid units) at which the Douglas-Peucker frontier is drawn: from far below
# a millimetre to a whole actuator spacing on the paper's sleeve.
FRONTIER_ERRORS = tuple(float(e) for e in np.geomspace(0.01, 1.0, 13))
LAG_PERCENTILE = 95


@dataclass(frozen=True)
class Source:
    """A recording to evaluate, its name and the group it belongs to (a LASA shape)."""

    name: str
    group: str
    recording: Recording


@dataclass(frozen=True)
class Run:
    """An algorithm with one parameter set (the overrides of its defaults)."""

    algorithm: Algorithm
    overrides: dict[str, Any]

    @property
    def label(self) -> str:
        return label(self.overrides)


@dataclass(frozen=True)
class Row:
    recording: str
    group: str
    algorithm: str
    setting: str
    overrides: dict[str, Any]
    frames: int
    strokes: int
    dropped: int
    max_deviation: float
    frechet: float
    dp_strokes: int  # Douglas-Peucker's strokes at this row's max deviation
    lags_ms: tuple[float, ...] = field(repr=False)

    def csv_fields(self) -> dict[str, Any]:
        lags = np.array(self.lags_ms)
        return {
            "recording": self.recording,
            "group": self.group,
            "algorithm": self.algorithm,
            "setting": self.setting,
            **self.overrides,
            "frames": self.frames,
            "strokes": self.strokes,
            "dropped": self.dropped,
            "max_deviation": round(self.max_deviation, 6),
            "frechet": round(self.frechet, 6),
            "dp_strokes": self.dp_strokes,
            "lag_mean_ms": _round(lags.mean()) if len(lags) else "",
            "lag_p95_ms": _round(np.percentile(lags, LAG_PERCENTILE)) if len(lags) else "",
            "lag_max_ms": _round(lags.max()) if len(lags) else "",
        }


def _round(value: Any) -> float:
    return round(float(value), 3)


def params_for(algorithm: Algorithm, recording: Recording, overrides: dict[str, Any]) -> Params:
    """The algorithm's defaults on the recording's canvas and sleeve, then ``overrides``."""
    base = algorithm.params()
    names = {f.name for f in fields(base)}
    canvas = {
        "canvas_width_px": recording.width_px,
        "canvas_height_px": recording.height_px,
        "rows": recording.rows or base.rows,
        "columns": recording.columns or base.columns,
    }
    params: Params = replace(base, **{k: v for k, v in canvas.items() if k in names}, **overrides)
    return params


def grid_points(params: Params, frames: Sequence[Sample]) -> metrics.Points:
    mapping = params.mapping
    return metrics.as_points([mapping.to_grid(f.x, f.y) for f in frames])


def evaluate_one(source: Source, run: Run) -> Row:
    """Run one recording through one parameter set and measure it, path by path."""
    params = params_for(run.algorithm, source.recording, run.overrides)
    result = rerun(source.recording, params)
    deviation, frechet, dp_strokes, frames = 0.0, 0.0, 0, 0
    segments = [item.segment for item in result.segments]
    for index, path in enumerate(result.frames):
        own = [item.segment for item in result.segments if item.path == index]
        points = grid_points(params, path)
        path_deviation = metrics.max_deviation([f.t_ms for f in path], points, own)
        deviation = max(deviation, path_deviation)
        frechet = max(frechet, metrics.path_frechet(points, own))
        dp_strokes += metrics.douglas_peucker_strokes(points, path_deviation)
        frames += len(path)
    return Row(
        recording=source.name,
        group=source.group,
        algorithm=run.algorithm.name,
        setting=run.label,
        overrides=run.overrides,
        frames=frames,
        strokes=metrics.stroke_count(segments),
        dropped=metrics.dropped_count(segments),
        max_deviation=deviation,
        frechet=frechet,
        dp_strokes=dp_strokes,
        lags_ms=tuple(float(v) for v in metrics.emission_lags_ms(segments)),
    )


def evaluate(
    sources: Sequence[Source], runs: Sequence[Run], advance: Callable[[], None] = lambda: None
) -> list[Row]:
    """Every source through every run, in that order; ``advance`` is called after each."""
    rows = []
    for run in runs:
        for source in sources:
            rows.append(evaluate_one(source, run))
            advance()
    return rows


def summarize(rows: Sequence[Row]) -> list[dict[str, Any]]:
    """Per algorithm and parameter set, in first-seen order: the figures of ``--json``."""
    groups: dict[tuple[str, str], list[Row]] = {}
    for row in rows:
        groups.setdefault((row.algorithm, row.setting), []).append(row)
    summary = []
    for (algorithm, setting), members in groups.items():
        lags = np.array([lag for r in members for lag in r.lags_ms])
        summary.append(
            {
                "algorithm": algorithm,
                "setting": setting,
                "params": members[0].overrides,
                "recordings": len(members),
                "strokes_mean": _mean([r.strokes for r in members]),
                "strokes_total": sum(r.strokes for r in members),
                "max_deviation_max": round(max(r.max_deviation for r in members), 6),
                "max_deviation_mean": _mean([r.max_deviation for r in members]),
                "frechet_mean": _mean([r.frechet for r in members]),
                "lag_p95_ms": _round(np.percentile(lags, LAG_PERCENTILE)) if len(lags) else None,
                "lag_mean_ms": _round(lags.mean()) if len(lags) else None,
                "dropped_total": sum(r.dropped for r in members),
                "dp_strokes_mean": _mean([r.dp_strokes for r in members]),
            }
        )
    return summary


def _mean(values: Sequence[float]) -> float:
    return round(float(np.nanmean(values)), 6) if values else float("nan")


def frontier(
    sources: Sequence[Source], algorithm: Algorithm, errors: Sequence[float] = FRONTIER_ERRORS
) -> list[dict[str, float]]:
    """Douglas-Peucker at each error on every source's frames (the algorithm's default grid).

    Each point: the error, the mean strokes per recording, the mean of each
    recording's actual maximum deviation (at most the error).
    """
    prepared = []
    for source in sources:
        params = params_for(algorithm, source.recording, {})
        frames = rerun(source.recording, params).frames
        prepared.append([grid_points(params, path) for path in frames])
    points = []
    for error in errors:
        strokes, deviations = [], []
        for paths in prepared:
            count, worst = 0, 0.0
            for path in paths:
                kept = metrics.douglas_peucker(path, error)
                count += max(len(kept) - 1, 1)
                worst = max(worst, _dp_deviation(path, kept))
            strokes.append(count)
            deviations.append(worst)
        points.append(
            {
                "max_error": round(error, 6),
                "strokes_mean": _mean(strokes),
                "max_deviation_mean": _mean(deviations),
            }
        )
    return points


def _dp_deviation(path: metrics.Points, kept: NDArray[np.int64]) -> float:
    worst = 0.0
    for a, b in itertools.pairwise(kept):
        worst = max(
            worst, float(metrics.segment_distances(path[a : b + 1], path[a], path[b]).max())
        )
    return worst


def write_csv(rows: Sequence[Row], path: Path) -> None:
    """One line per row; a swept parameter gets its own column (empty where not swept)."""
    table = [row.csv_fields() for row in rows]
    columns: list[str] = []
    for entry in table:
        columns += [key for key in entry if key not in columns]
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns, restval="")
        writer.writeheader()
        writer.writerows(table)


def write_frontier_csv(points: Sequence[dict[str, float]], path: Path) -> None:
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(
            handle, fieldnames=["max_error", "strokes_mean", "max_deviation_mean"]
        )
        writer.writeheader()
        writer.writerows(points)
