"""The study's figures (PNG, small enough for a paper column): accuracy by resolution with
Wilson intervals and the fitted curves, and the needed resolution per shape."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display on a lab machine or CI
import matplotlib.pyplot as plt
import numpy as np

from feelmysign.study.analysis.psychometric import Threshold

DPI = 110
FIGURE_IN = (6.4, 4.0)


def accuracy_plot(
    path: Path,
    accuracy: dict[str, list[tuple[int, int, int, float, float]]],
    thresholds: dict[str, Threshold],
    criterion: float,
) -> Path:
    """Per shape: points (strokes, share correct) with Wilson bars, and the fitted curve."""
    figure, axes = plt.subplots(figsize=FIGURE_IN, dpi=DPI)
    colours = plt.get_cmap("tab10")
    for index, (shape, rows) in enumerate(accuracy.items()):
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
            label=shape,
        )
        if shape in thresholds and len(strokes) > 1:
            grid = np.geomspace(strokes.min() * 0.8, strokes.max() * 1.25, 100)
            axes.plot(grid, thresholds[shape].fit.accuracy(grid), color=colour, linewidth=1)
    axes.axhline(criterion, color="grey", linestyle=":", linewidth=1)
    axes.set_xscale("log", base=2)
    axes.set_xlabel("strokes per shape (log scale)")
    axes.set_ylabel("share named correctly")
    axes.set_ylim(-0.02, 1.02)
    axes.set_title("Recognition by resolution (95% Wilson intervals, fitted curves)")
    axes.legend(fontsize="small", ncol=2, loc="lower right")
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)
    return path


def threshold_plot(
    path: Path, thresholds: dict[str, Threshold], tested: tuple[float, float], criterion: float
) -> Path:
    """The strokes each shape needs for the criterion accuracy, with 95% intervals, drawn
    within half the tested range's lowest and twice its highest resolution; what lies
    beyond is an arrow (the data cannot say how far)."""
    low_edge, high_edge = tested[0] / 2, tested[1] * 2
    figure, axes = plt.subplots(figsize=(FIGURE_IN[0], 0.45 * len(thresholds) + 1.2), dpi=DPI)
    names = list(thresholds)
    axes.axvspan(tested[0], tested[1], color="#eeeeee", zorder=0)
    for row, name in enumerate(names):
        result = thresholds[name]
        # The reported interval: the parametric bootstrap with the participants' spread.
        first, last = result.boot_low, result.boot_high
        low = min(max(first, low_edge), high_edge)
        high = min(max(last, low_edge), high_edge) if math.isfinite(last) else high_edge
        axes.plot([low, high], [row, row], color="black", linewidth=1.5)
        if last > high_edge or not math.isfinite(last):
            axes.plot(high_edge, row, ">", color="black")
        if first < low_edge:
            axes.plot(low_edge, row, "<", color="black")
        if math.isfinite(result.strokes) and low_edge <= result.strokes <= high_edge:
            axes.plot(result.strokes, row, "o", color="black")
    axes.set_xlim(low_edge * 0.9, high_edge * 1.1)
    axes.set_yticks(range(len(names)), names)
    axes.set_xscale("log", base=2)
    axes.set_xlabel(
        f"strokes needed for {criterion:.0%} correct (95% bootstrap interval; grey: tested)"
    )
    axes.invert_yaxis()
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)
    return path
