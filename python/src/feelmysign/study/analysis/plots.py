"""The study's figures (PNG, small enough for a paper column): accuracy by resolution with
Wilson intervals and the fitted curves, and the needed resolution per shape."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # files only: no display on a lab machine or CI
import matplotlib.pyplot as plt
import numpy as np

from feelmysign.study.analysis.psychometric import AT_OR_BELOW, ESTIMATE, Needed, Threshold

DPI = 110
FIGURE_IN = (6.4, 4.0)


def accuracy_plot(
    path: Path,
    accuracy: dict[str, list[tuple[int, int, int, float, float]]],
    thresholds: dict[str, Threshold],
    criterion: float,
    panels: dict[str, list[str]] | None = None,
) -> Path:
    """Per shape: points (strokes, share correct) with Wilson bars, and the fitted curve.
    ``panels`` (speed a factor): one panel per title ("3 cm/s") holding those keys of
    ``accuracy`` ("circle at 3 cm/s"), side by side on the same axes."""
    groups = panels or {"": list(accuracy)}
    width = FIGURE_IN[0] if len(groups) == 1 else 3.6 * len(groups)
    figure, all_axes = plt.subplots(
        1, len(groups), figsize=(width, FIGURE_IN[1]), dpi=DPI, sharey=True, squeeze=False
    )
    # The tested range sets the axis, so that a study with no answer yet still has a plot.
    every = [float(r[0]) for rows in accuracy.values() for r in rows] or [1.0, 2.0]
    for axes, (title, keys) in zip(all_axes[0], groups.items(), strict=True):
        _accuracy_panel(axes, {key: accuracy[key] for key in keys}, thresholds, criterion, title)
        axes.set_xlim(min(every) / 1.2, max(every) * 1.2)
    all_axes[0][0].set_ylabel("share named correctly")
    if panels:
        figure.suptitle("Recognition by resolution and speed (95% Wilson intervals, fitted curves)")
    else:
        all_axes[0][0].set_title("Recognition by resolution (95% Wilson intervals, fitted curves)")
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)
    return path


def _accuracy_panel(
    axes: Any,
    accuracy: dict[str, list[tuple[int, int, int, float, float]]],
    thresholds: dict[str, Threshold],
    criterion: float,
    title: str,
) -> None:
    colours = plt.get_cmap("tab10")
    for index, (key, rows) in enumerate(accuracy.items()):
        colour = colours(index % 10)
        strokes = np.array([r[0] for r in rows], dtype=float)
        share = np.array([r[1] / r[2] if r[2] else math.nan for r in rows])
        low = np.array([r[3] for r in rows])
        high = np.array([r[4] for r in rows])
        axes.errorbar(
            strokes * (1 + 0.015 * (index - len(accuracy) / 2)),
            share,
            yerr=[np.clip(share - low, 0, None), np.clip(high - share, 0, None)],
            fmt="o",
            color=colour,
            capsize=2,
            markersize=4,
            label=key.removesuffix(f" at {title}") if title else key,
        )
        if key in thresholds and len(strokes) > 1:
            grid = np.geomspace(strokes.min(), strokes.max(), 100)  # the tested range only
            axes.plot(grid, thresholds[key].fit.accuracy(grid), color=colour, linewidth=1)
    axes.axhline(criterion, color="grey", linestyle=":", linewidth=1)
    axes.set_xscale("log", base=2)
    axes.set_xlabel("strokes per shape (log scale)")
    axes.set_ylim(-0.02, 1.02)
    if title:
        axes.set_title(title, fontsize="medium")
    axes.legend(fontsize="small", ncol=2, loc="lower right")


def threshold_plot(path: Path, needed: dict[str, Needed], criterion: float) -> Path:
    """The strokes each shape needs for the criterion accuracy, with 95% intervals, drawn
    only within each shape's tested range (grey); a bound or an interval that goes on
    beyond the range ends in an arrow at its edge (the data cannot say how far)."""
    lowest = min(n.lowest_tested for n in needed.values())
    highest = max(n.highest_tested for n in needed.values())
    figure, axes = plt.subplots(figsize=(FIGURE_IN[0], 0.45 * len(needed) + 1.2), dpi=DPI)
    names = list(needed)
    for row, name in enumerate(names):
        result = needed[name]
        axes.plot(
            [result.lowest_tested, result.highest_tested],
            [row, row],
            color="#dddddd",
            linewidth=8,
            solid_capstyle="butt",
            zorder=0,
        )
        interval = result.interval
        axes.plot([interval.low, interval.high], [row, row], color="black", linewidth=1.5)
        if interval.high_open:
            axes.plot(interval.high, row, ">", color="black")
        if interval.low_open:
            axes.plot(interval.low, row, "<", color="black")
        if result.kind == ESTIMATE and result.strokes is not None:
            axes.plot(result.strokes, row, "o", color="black")
        elif result.kind == AT_OR_BELOW:
            axes.plot(result.lowest_tested, row, "<", color="tab:blue", markersize=9)
        else:
            axes.plot(result.highest_tested, row, ">", color="tab:red", markersize=9)
    axes.set_xlim(lowest / 1.2, highest * 1.2)
    axes.set_yticks(range(len(names)), names)
    axes.set_xscale("log", base=2)
    axes.set_xlabel(
        # Two lines: on one, the label is wider than the figure and is cut at both ends.
        f"strokes needed for {criterion:.0%} correct (95% bootstrap interval; grey: tested;\n"
        "blue <: at or below the lowest tested; red >: above the highest)",
        fontsize="small",
    )
    axes.invert_yaxis()
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)
    return path
