"""Run simplifiers over recordings and parameter grids, and measure every result.

One ``Row`` per recording x algorithm x parameter set; ``summarize`` folds
them per source set (LASA as drawn, or re-timed slow, normal, fast), algorithm
and parameter set; ``frontier`` runs offline Douglas-Peucker over a range of
errors on the same samples. Every recording is run with its canvas and sleeve
and the algorithm's defaults, overridden only by the parameter set, so that
one set means the same on every recording (the parameters a recording's sender
used are not applied).

Each row measures the shape (deviation of every drawn sample, Fréchet
distance, strokes against Douglas-Peucker at the same error), the timing as
the sleeve would play it (``playback``: time on the skin against drawing time,
release to felt end, pen to skin, and how much the sleeve caught up by playing
strokes faster, how much it skipped as ``late`` and how many strokes it had to slow,
briefer than it can play) and, when the recording is a LASA shape,
whether the $1 recogniser (``dollar``) names the shape from the drawing, from
the polyline of the strokes sent, and from the felt path (``felt``: the
phantom point the planned schedules render over time). A shape can survive
the simplifier and still be lost in the planner; the last two tell where.
"""

from __future__ import annotations

import csv
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from feelmysign.layout import PAPER_SLEEVE, Layout, grid_layout
from feelmysign.research import dollar, metrics
from feelmysign.research.felt import felt_path
from feelmysign.research.playback import simulate
from feelmysign.research.rerun import rerun
from feelmysign.research.sweep import label
from feelmysign.simplify.recording import Recording
from feelmysign.simplify.registry import Algorithm, Params, params_for
from feelmysign.simplify.segment import Sample, Segment

# Errors (grid units) at which the Douglas-Peucker frontier is drawn: from far below
# a millimetre to a whole actuator spacing on the paper's sleeve.
FRONTIER_ERRORS = tuple(float(e) for e in np.geomspace(0.01, 1.0, 13))
LAG_PERCENTILE = 95
# Douglas-Peucker keeps a point lying exactly at its tolerance: run at a hair above a
# row's deviation, so that a tie does not cost it a stroke the online simplifier saved.
DP_TIE_MARGIN = 1e-9


@dataclass(frozen=True)
class Source:
    """A recording to evaluate, its name, its group (a LASA shape) and its set.

    ``template`` is the recording's own index among the recogniser's templates of
    its ``pool`` (left out when it is recognised), or None when it has no shape to
    recognise; with a fixed set of templates (``template_sources``) nothing is left
    out, and any index means "recognise it".
    """

    name: str
    group: str
    recording: Recording
    set: str = "files"
    template: int | None = None
    pool: str = ""


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
    set: str
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
    drawing_ms: float = 0.0
    skin_ms: float = 0.0
    release_ms: tuple[float, ...] = field(default=(), repr=False)
    pen_to_skin_ms: tuple[float, ...] = field(default=(), repr=False)
    recognised_drawn: bool | None = None
    recognised_sent: bool | None = None
    recognised_felt: bool | None = None
    compressed: int = 0  # strokes played faster to catch up with the drawing
    compressed_ms: float = 0.0  # by how much, added up
    skipped: int = 0  # strokes skipped as late
    skipped_ms: float = 0.0  # their planned durations, added up
    slowed: int = 0  # strokes the planner made longer than sent (the sleeve's floor)

    @property
    def skin_ratio(self) -> float:
        return self.skin_ms / self.drawing_ms if self.drawing_ms > 0 else float("nan")

    @property
    def played(self) -> int:
        """Strokes played (one pen-to-skin time each)."""
        return len(self.pen_to_skin_ms)

    def csv_fields(self) -> dict[str, Any]:
        lags = np.array(self.lags_ms)
        return {
            "recording": self.recording,
            "group": self.group,
            "set": self.set,
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
            "drawing_ms": _round(self.drawing_ms),
            "skin_ms": _round(self.skin_ms),
            "skin_ratio": _round(self.skin_ratio),
            "release_to_felt_end_ms": _round(max(self.release_ms)) if self.release_ms else "",
            "pen_to_skin_max_ms": _round(max(self.pen_to_skin_ms)) if self.pen_to_skin_ms else "",
            "compressed": self.compressed,
            "compressed_ms": _round(self.compressed_ms),
            "skipped": self.skipped,
            "skipped_ms": _round(self.skipped_ms),
            "slowed": self.slowed,
            "recognised_drawn": _flag(self.recognised_drawn),
            "recognised_sent": _flag(self.recognised_sent),
            "recognised_felt": _flag(self.recognised_felt),
        }


def _round(value: Any) -> float:
    return round(float(value), 3)


def _flag(value: bool | None) -> int | str:
    return "" if value is None else int(value)


def grid_points(params: Params, frames: Sequence[Sample]) -> metrics.Points:
    mapping = params.mapping
    return metrics.as_points([mapping.to_grid(f.x, f.y) for f in frames])


def layout_for(params: Params) -> Layout:
    """The sleeve the strokes are planned on: the paper's, or a grid of the recording's size."""
    if (params.rows, params.columns) == (PAPER_SLEEVE.rows, PAPER_SLEEVE.columns):
        return PAPER_SLEEVE
    return grid_layout(params.rows, params.columns, PAPER_SLEEVE.spacing_cm)


def sent_polyline(segments: Sequence[Segment]) -> metrics.Points:
    """The strokes sent, chained: the first one's start, then every end."""
    sent = [s for s in segments if s.dropped is None]
    if not sent:
        return metrics.as_points([])
    return metrics.as_points([sent[0].start, *(s.end for s in sent)])


class Recogniser:
    """The $1 recogniser, with drawings as templates (one left out per candidate) or with a
    fixed set of templates (``leave_one_out=False``: nothing is left out).

    ``templates`` may be one pool (every source's ``pool`` is ``""``: LASA, or a
    templates file) or one per pool (the recordings of each set, recognised among
    themselves). ``expected`` maps a source's group to the template name it should be
    recognised as (default: the group itself).
    """

    def __init__(
        self,
        templates: dollar.Templates | dict[str, dollar.Templates],
        *,
        leave_one_out: bool = True,
        expected: dict[str, str] | None = None,
        against: str = "the other drawings of its set",
    ) -> None:
        self.against = against  # what the drawings are recognised against, for a reader
        self._pools = templates if isinstance(templates, dict) else {"": templates}
        self._leave_one_out = leave_one_out
        self._expected = expected or {}
        self._drawn: dict[str, bool] = {}

    def names(self, source: Source, candidate: metrics.Points) -> bool | None:
        """Whether ``candidate`` is recognised as the source's shape (None: nothing to test)."""
        if source.template is None:
            return None
        if len(candidate) < 2 or not np.any(candidate != candidate[0]):
            return False
        pool = self._pools[source.pool]
        templates = pool.without(source.template) if self._leave_one_out else pool
        name, _ = dollar.recognise(candidate, templates)
        return name == self._expected.get(source.group, source.group)

    def drawn(self, source: Source, points: metrics.Points) -> bool | None:
        if source.name not in self._drawn:
            self._drawn[source.name] = bool(self.names(source, points))
        return self._drawn[source.name] if source.template is not None else None


def file_sources(gestures: Sequence[Any]) -> tuple[list[Source], Recogniser]:
    """Recorded drawings as sources, each recognised among the others of its set.

    ``gestures`` are ``research.gestures.Gesture``s. A drawing is recognised
    (``template`` set) when its set holds another drawing of the same gesture;
    its templates are the other drawings of its set whose gesture is drawn at
    least twice there (its own left out).
    """
    counts: dict[tuple[str, str], int] = {}
    for g in gestures:
        counts[(g.set, g.gesture)] = counts.get((g.set, g.gesture), 0) + 1
    pools: dict[str, list[tuple[str, metrics.Points]]] = {}
    sources = []
    for g in gestures:
        index = None
        if counts[(g.set, g.gesture)] >= 2:
            pool = pools.setdefault(g.set, [])
            index = len(pool)
            points = [(s.x, s.y) for path in g.recording.paths for s in path]
            pool.append((g.gesture, metrics.as_points(points)))
        sources.append(Source(g.name, g.gesture, g.recording, g.set, index, g.set))
    templates = {name: dollar.Templates.of(named) for name, named in pools.items()}
    return sources, Recogniser(templates)


def template_sources(gestures: Sequence[Any], template_set: Any) -> tuple[list[Source], Recogniser]:
    """Recorded drawings as sources, each recognised against a fixed set of templates.

    ``template_set`` is a ``research.gestures.TemplateSet``. A drawing whose gesture has
    no template there is evaluated but not recognised (``template`` None).
    """
    sources = []
    for g in gestures:
        index = 0 if template_set.expected(g.gesture) is not None else None
        sources.append(Source(g.name, g.gesture, g.recording, g.set, index))
    named = [(name, metrics.as_points(points)) for name, points in template_set.templates]
    expected = {
        g.gesture: name for g in gestures if (name := template_set.expected(g.gesture)) is not None
    }
    return sources, Recogniser(
        dollar.Templates.of(named),
        leave_one_out=False,
        expected=expected,
        against=f"the {len(named)} templates of {template_set.path}",
    )


def evaluate_one(
    source: Source, run: Run, recogniser: Recogniser | None = None, *, shape_metrics: bool = True
) -> Row:
    """Run one recording through one parameter set and measure it, path by path.

    Deviation is measured on every drawn sample (not only on the frames an
    animation loop saw): a sample's distance to the stroke whose time covers it.
    Without ``shape_metrics`` the deviation, Frechet distance and Douglas-Peucker
    count are left out (NaN, NaN, 0): the Frechet distance takes most of the time,
    and the timing figures do not need them.
    """
    params = params_for(run.algorithm, source.recording, run.overrides)
    result = rerun(source.recording, params)
    deviation, frechet, dp_strokes, frames = 0.0, 0.0, 0, 0
    segments = [item.segment for item in result.segments]
    drawn_paths = []
    for index, path in enumerate(source.recording.paths):
        own = [item.segment for item in result.segments if item.path == index]
        points = grid_points(params, path)
        drawn_paths.append(points)
        frames += len(result.frames[index]) if index < len(result.frames) else 0
        if not shape_metrics:
            deviation = frechet = math.nan
            continue
        path_deviation = metrics.max_deviation([s.t_ms for s in path], points, own)
        deviation = max(deviation, path_deviation)
        frechet = max(frechet, metrics.path_frechet(points, own))
        tolerance = path_deviation * (1 + DP_TIE_MARGIN) + DP_TIE_MARGIN
        dp_strokes += metrics.douglas_peucker_strokes(points, tolerance)
    playback = simulate(result.segments, source.recording.paths, layout_for(params))
    drawn = np.concatenate(drawn_paths) if drawn_paths else metrics.as_points([])
    return Row(
        recording=source.name,
        group=source.group,
        set=source.set,
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
        drawing_ms=playback.drawing_ms,
        skin_ms=playback.skin_ms,
        release_ms=playback.release_to_felt_end_ms,
        pen_to_skin_ms=playback.pen_to_skin_ms,
        recognised_drawn=recogniser.drawn(source, drawn) if recogniser else None,
        recognised_sent=recogniser.names(source, sent_polyline(segments)) if recogniser else None,
        recognised_felt=recogniser.names(source, felt_path(playback.schedules))
        if recogniser
        else None,
        compressed=playback.compressed,
        compressed_ms=playback.compressed_ms,
        skipped=playback.skipped,
        skipped_ms=playback.skipped_ms,
        slowed=playback.slowed,
    )


def evaluate(
    sources: Sequence[Source],
    runs: Sequence[Run],
    advance: Callable[[], None] = lambda: None,
    recogniser: Recogniser | None = None,
    *,
    shape_metrics: bool = True,
) -> list[Row]:
    """Every source through every run, in that order; ``advance`` is called after each."""
    rows = []
    for run in runs:
        for source in sources:
            rows.append(evaluate_one(source, run, recogniser, shape_metrics=shape_metrics))
            advance()
    return rows


def summarize(rows: Sequence[Row]) -> list[dict[str, Any]]:
    """Per set, algorithm and parameter set, in first-seen order: the figures of ``--json``."""
    groups: dict[tuple[str, str, str], list[Row]] = {}
    for row in rows:
        groups.setdefault((row.set, row.algorithm, row.setting), []).append(row)
    summary = []
    for (source_set, algorithm, setting), members in groups.items():
        lags = np.array([lag for r in members for lag in r.lags_ms])
        ratios = np.array([r.skin_ratio for r in members if r.drawing_ms > 0])
        release = np.array([v for r in members for v in r.release_ms])
        pen = np.array([v for r in members for v in r.pen_to_skin_ms])
        # The time the strokes would have played without catching up (skipped ones too).
        planned_ms = sum(r.skin_ms + r.compressed_ms + r.skipped_ms for r in members)
        played = sum(r.played for r in members)
        summary.append(
            {
                "set": source_set,
                "algorithm": algorithm,
                "setting": setting,
                "params": members[0].overrides,
                "recordings": len(members),
                "strokes_mean": _mean([r.strokes for r in members]),
                "strokes_total": sum(r.strokes for r in members),
                "max_deviation_max": round(max(r.max_deviation for r in members), 6),
                "max_deviation_mean": _mean([r.max_deviation for r in members]),
                "frechet_mean": _mean([r.frechet for r in members]),
                "lag_p95_ms": _percentile(lags),
                "lag_mean_ms": _round(lags.mean()) if len(lags) else None,
                "dropped_total": sum(r.dropped for r in members),
                "dp_strokes_mean": _mean([r.dp_strokes for r in members]),
                "skin_ratio_mean": _round(ratios.mean()) if len(ratios) else None,
                "skin_ratio_p95": _percentile(ratios),
                "release_to_felt_end_median_ms": _percentile(release, 50),
                "release_to_felt_end_p95_ms": _percentile(release),
                "pen_to_skin_p95_ms": _percentile(pen),
                "compressed_strokes_pct": round(
                    100.0 * sum(r.compressed for r in members) / played, 2
                )
                if played
                else None,
                "compressed_time_pct": round(
                    100.0 * sum(r.compressed_ms for r in members) / planned_ms, 2
                )
                if planned_ms
                else None,
                "skipped_total": sum(r.skipped for r in members),
                "slowed_total": sum(r.slowed for r in members),
                "skipped_time_pct": round(
                    100.0 * sum(r.skipped_ms for r in members) / planned_ms, 2
                )
                if planned_ms
                else None,
                "recognised_drawn_pct": _percent([r.recognised_drawn for r in members]),
                "recognised_sent_pct": _percent([r.recognised_sent for r in members]),
                "recognised_felt_pct": _percent([r.recognised_felt for r in members]),
            }
        )
    return summary


def _percentile(values: NDArray[np.float64], q: float = LAG_PERCENTILE) -> float | None:
    return _round(np.percentile(values, q)) if len(values) else None


def _percent(flags: Sequence[bool | None]) -> float | None:
    known = [f for f in flags if f is not None]
    return round(100.0 * sum(known) / len(known), 2) if known else None


def _mean(values: Sequence[float]) -> float:
    # NaN, without numpy's warning, when nothing was measured (rows without shape metrics).
    if not values or all(math.isnan(v) for v in values):
        return float("nan")
    return round(float(np.nanmean(values)), 6)


def frontier(
    sources: Sequence[Source], algorithm: Algorithm, errors: Sequence[float] = FRONTIER_ERRORS
) -> list[dict[str, float]]:
    """Douglas-Peucker at each error on every source's samples (the algorithm's default grid).

    Each point: the error, the mean strokes per recording, the mean of each
    recording's actual maximum deviation (at most the error).
    """
    prepared = []
    for source in sources:
        params = params_for(algorithm, source.recording, {})
        prepared.append([grid_points(params, path) for path in source.recording.paths])
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
