"""The evaluation's figures, as PNG files (matplotlib, Agg: no display needed).

- ``error_vs_strokes.png``: each algorithm's parameter sets as points (mean
  strokes per recording, mean maximum deviation), Douglas-Peucker's frontier
  as a line: below and left of it is out of reach even offline.
- ``lag.png``: the emission lag of every stroke, one box per parameter set.
- ``per_group.png``: strokes and maximum deviation per shape (per recording
  group), each algorithm at its reference parameter set.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # before pyplot: files only, never a window

import matplotlib.pyplot as plt
import matplotlib.ticker as ticker
import numpy as np

from feelmysign.research.evaluate import Row
from feelmysign.research.sweep import SHORT_NAMES

DPI = 120
COLOURS = {"angle": "tab:blue", "window": "tab:orange"}
FRONTIER_COLOUR = "black"


def _colour(algorithm: str) -> str:
    return COLOURS.get(algorithm, "tab:green")


def error_vs_strokes(
    summary: Sequence[dict[str, Any]], frontier: Sequence[dict[str, float]], path: Path
) -> None:
    figure, axes = plt.subplots(figsize=(8, 5.5))
    axes.plot(
        [p["strokes_mean"] for p in frontier],
        [p["max_deviation_mean"] for p in frontier],
        "-",
        color=FRONTIER_COLOUR,
        marker=".",
        label="Douglas-Peucker (offline frontier)",
    )
    for algorithm in dict.fromkeys(s["algorithm"] for s in summary):
        own = [s for s in summary if s["algorithm"] == algorithm]
        xs = [s["strokes_mean"] for s in own]
        ys = [s["max_deviation_mean"] for s in own]
        axes.scatter(xs, ys, color=_colour(algorithm), label=algorithm, zorder=3)
        for s, x, y in zip(own, xs, ys, strict=True):
            axes.annotate(
                _short(s["setting"]), (x, y), fontsize=7, xytext=(4, 3), textcoords="offset points"
            )
    axes.set_xscale("log")
    # Plain stroke counts (2, 5, 10), not powers of ten.
    axes.xaxis.set_major_formatter(ticker.FormatStrFormatter("%g"))
    axes.xaxis.set_minor_formatter(ticker.FormatStrFormatter("%g"))
    axes.tick_params(axis="x", which="minor", labelsize=7)
    axes.set_xlabel("strokes per recording (mean, log scale)")
    axes.set_ylabel("maximum deviation per recording (mean, grid units)")
    axes.set_title("Error against stroke count")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend()
    _save(figure, path)


def lag_distribution(rows: Sequence[Row], path: Path) -> None:
    groups: dict[tuple[str, str], list[float]] = {}
    for row in rows:
        groups.setdefault((row.algorithm, row.setting), []).extend(row.lags_ms)
    keys = list(groups)
    figure, axes = plt.subplots(figsize=(9.5, 1.5 + 0.35 * len(keys)))
    boxes = axes.boxplot(
        [groups[k] or [np.nan] for k in keys],
        orientation="horizontal",
        patch_artist=True,
        showfliers=False,
        showmeans=True,
        whis=(5, 95),
        medianprops={"color": "black", "linewidth": 2},
        meanprops={"marker": "D", "markerfacecolor": "white", "markeredgecolor": "black"},
    )
    # The angle rule's lags are whole check periods, so boxes often collapse: say the figures.
    for position, key in enumerate(keys, start=1):
        lags = groups[key]
        if lags:
            text = f"mean {np.mean(lags):.0f}, p95 {np.percentile(lags, 95):.0f} ms"
            axes.annotate(
                text, (1.01, position), xycoords=("axes fraction", "data"), va="center", fontsize=7
            )
    for patch, (algorithm, _) in zip(boxes["boxes"], keys, strict=True):
        patch.set_facecolor(_colour(algorithm))
        patch.set_alpha(0.6)
    axes.set_yticks(range(1, len(keys) + 1), [f"{a}: {_short(s)}" for a, s in keys], fontsize=8)
    axes.invert_yaxis()
    axes.set_xlabel(
        "emission lag, ms (pointer at a stroke's end -> stroke sent); "
        "box: quartiles, bar: median, diamond: mean, whiskers: 5-95 %"
    )
    axes.set_title("Emission lag per parameter set")
    axes.grid(True, axis="x", alpha=0.3)
    _save(figure, path)


def per_group(rows: Sequence[Row], references: dict[str, str], path: Path) -> None:
    """Mean strokes and maximum deviation per group, for each algorithm's reference set."""
    chosen = [r for r in rows if references.get(r.algorithm) == r.setting]
    groups = list(dict.fromkeys(r.group for r in chosen))
    algorithms = list(references)
    figure, (top, bottom) = plt.subplots(
        2, 1, figsize=(max(8, 0.35 * len(groups) + 2), 7), sharex=True
    )
    width = 0.8 / max(len(algorithms), 1)
    x = np.arange(len(groups))
    for k, algorithm in enumerate(algorithms):
        own = [r for r in chosen if r.algorithm == algorithm]
        strokes = [_mean([r.strokes for r in own if r.group == g]) for g in groups]
        error = [_mean([r.max_deviation for r in own if r.group == g]) for g in groups]
        name = f"{algorithm} ({_short(references[algorithm])})"
        offset = x + (k - (len(algorithms) - 1) / 2) * width
        top.bar(offset, strokes, width, color=_colour(algorithm), label=name)
        bottom.bar(offset, error, width, color=_colour(algorithm), label=name)
    top.set_ylabel("strokes (mean)")
    bottom.set_ylabel("maximum deviation\n(mean, grid units)")
    top.set_title("Per shape, each algorithm at its reference parameters")
    top.legend(fontsize=8)
    bottom.set_xticks(x, groups, rotation=60, ha="right", fontsize=8)
    for axes in (top, bottom):
        axes.grid(True, axis="y", alpha=0.3)
    _save(figure, path)


def _mean(values: Sequence[float]) -> float:
    return float(np.mean(values)) if values else float("nan")


def _short(setting: str) -> str:
    """``check_frames=5 frame_max=60`` -> ``chk 5, fmax 60`` style, to fit a plot."""
    parts = []
    for item in setting.split():
        name, _, value = item.partition("=")
        parts.append(f"{SHORT_NAMES.get(name, name)} {value}" if value else name)
    return ", ".join(parts)


def _save(figure: Any, path: Path) -> None:
    figure.tight_layout()
    figure.savefig(path, dpi=DPI)
    plt.close(figure)
