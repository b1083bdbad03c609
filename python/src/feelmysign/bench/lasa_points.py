"""Simplifier throughput on real pen data: the LASA points, shared with the web bench.

Every one of the 210 LASA demonstrations (``feelmysign.research.lasa``) is
resampled into animation frames at 60 fps (``frames_from_samples``), in canvas
pixels of the demonstration's own canvas: the points every simplifier is timed
on, in Python here and in TypeScript by ``web/bench/lasa.ts`` (which also times
``simplify-js``, Douglas-Peucker, on the same points).

``python -m feelmysign.bench.lasa_points [PATH]`` writes them to a JSON file
(default ``web/bench/.lasa-frames.json``, the file the web bench reads; the
Makefile writes it before ``make web-bench``). ``report`` is the Python group of
``make bench``: angle and window frames per second over all those frames,
beside the one-distance-per-frame baseline of ``bench.algorithms``.

The file: ``fps``, ``pressure`` (the data has none: every frame has it),
``max_error`` (grid units, the window simplifier's default) and ``demos``, each
with ``name``, ``canvas_width_px``, ``canvas_height_px``, ``tolerance_px``
(``max_error`` in that canvas's pixels, for Douglas-Peucker: the mapping keeps
the aspect ratio, one scale for both axes) and ``frames`` as ``[t_ms, x, y]``.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from feelmysign.bench._timing import Rate, best_rate, row
from feelmysign.bench.algorithms import one_distance_per_frame
from feelmysign.research.lasa import PRESSURE, load_lasa
from feelmysign.simplify import ALGORITHMS, AngleParams, Sample, WindowParams, frames_from_samples

FPS = 60.0
MAX_ERROR = WindowParams().max_error  # grid units: 3 mm on the paper's sleeve
# python/src/feelmysign/bench/ -> the repository's root.
DEFAULT_PATH = Path(__file__).resolve().parents[4] / "web" / "bench" / ".lasa-frames.json"


@dataclass(frozen=True)
class LasaFrames:
    """One demonstration's frames and its canvas."""

    name: str
    width_px: float
    height_px: float
    frames: list[Sample]

    @property
    def tolerance_px(self) -> float:
        """``MAX_ERROR`` in this canvas's pixels (the aspect-keeping mapping's one scale)."""
        mapping = WindowParams(canvas_width_px=self.width_px, canvas_height_px=self.height_px)
        return MAX_ERROR / mapping.mapping.scale


def lasa_frames() -> list[LasaFrames]:
    """All 210 demonstrations as 60 fps frames, by shape then number."""
    out = []
    for demo in load_lasa():
        recording = demo.recording
        (path,) = recording.paths
        out.append(
            LasaFrames(
                demo.name,
                recording.width_px,
                recording.height_px,
                frames_from_samples(path, FPS),
            )
        )
    return out


def to_json(demos: Sequence[LasaFrames]) -> dict[str, Any]:
    return {
        "source": "feelmysign.bench.lasa_points: LASA handwriting data set, frames at 60 fps",
        "fps": FPS,
        "pressure": PRESSURE,
        "max_error": MAX_ERROR,
        "demos": [
            {
                "name": d.name,
                "canvas_width_px": d.width_px,
                "canvas_height_px": d.height_px,
                "tolerance_px": d.tolerance_px,
                "frames": [[f.t_ms, f.x, f.y] for f in d.frames],
            }
            for d in demos
        ],
    }


def write(path: Path = DEFAULT_PATH) -> int:
    """Write the frames file; returns the number of frames."""
    demos = lasa_frames()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(to_json(demos), separators=(",", ":")) + "\n")
    return sum(len(d.frames) for d in demos)


def simplifier_rates(demos: Sequence[LasaFrames]) -> list[Rate]:
    """The baseline, then angle and window (defaults, each demo's canvas; the window also with
    its chord core, ``least_squares`` off) per frame."""
    params: dict[str, list[AngleParams | WindowParams]] = {
        "angle": [
            AngleParams(canvas_width_px=d.width_px, canvas_height_px=d.height_px) for d in demos
        ],
        "window": [
            WindowParams(canvas_width_px=d.width_px, canvas_height_px=d.height_px) for d in demos
        ],
        "chord": [
            WindowParams(
                canvas_width_px=d.width_px, canvas_height_px=d.height_px, least_squares=False
            )
            for d in demos
        ],
    }

    def baseline() -> int:
        return sum(one_distance_per_frame(d.frames) for d in demos)

    def run(name: str) -> int:
        make = ALGORITHMS["window" if name == "chord" else name].make
        count = 0
        for demo, demo_params in zip(demos, params[name], strict=True):
            simplifier = make(demo_params)
            for frame in demo.frames:
                simplifier.push(frame)
            simplifier.end()
            count += len(demo.frames)
        return count

    return [
        best_rate("baseline: one distance per frame", baseline),
        best_rate("angle simplifier (paper's defaults)", lambda: run("angle")),
        best_rate(
            f"window simplifier (max_error {MAX_ERROR}, least squares: the defaults)",
            lambda: run("window"),
        ),
        best_rate(f"window simplifier (max_error {MAX_ERROR}, chord)", lambda: run("chord")),
    ]


def report() -> list[str]:
    demos = lasa_frames()
    frames = sum(len(d.frames) for d in demos)
    lines = [
        f"Simplifiers on LASA (Python): {len(demos)} demonstrations, {frames:,} frames at"
        f" {FPS:g} fps (simplify-js on the same points: the web bench)"
    ]
    base, *rates = simplifier_rates(demos)
    lines += [row(base, base)] + [row(rate, base) for rate in rates]
    return lines


def main(argv: Sequence[str] | None = None) -> None:
    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) > 1 or any(a.startswith("-") for a in args):
        sys.exit("usage: python -m feelmysign.bench.lasa_points [PATH]")
    path = Path(args[0]) if args else DEFAULT_PATH
    count = write(path)
    print(f"wrote {count:,} LASA frames to {path}")


if __name__ == "__main__":
    main()
