"""Simulated gesture recordings: the 16 $1 gestures drawn by 10 simulated people at 3 speeds.

A set to test the simplifiers on something other than LASA, in the layout and
format of Wobbrock, Wilson & Li's $1 gesture logs (UIST 2007):
``sNN/{slow,medium,fast}/NAME01.xml``, integer pixels and epoch milliseconds,
one drawing per person, gesture and speed (16 x 10 x 3 = 480 files). The shapes
are this module's own outlines of the 16 gestures of the $1 paper, named as in
its gesture logs (``left_sq_bracket``, ``question_mark``, ...).

The hand model, per drawing:

1. The gesture's outline (corners, or control points of a smooth curve) is
   moved by the person: a size (70 to 160 px), an aspect (0.85 to 1.15), a
   slant (+-8 degrees), and every point jittered by a share of the size that
   grows with speed (a fast drawing is sloppier).
2. Corners are rounded (Chaikin corner cutting, more passes when faster: a fast
   pen does not stop at a corner) and curves are smoothed (Catmull-Rom), then
   the path is resampled to 1 px steps.
3. Speed along the path follows the two-thirds power law (Lacquaniti, Terzuolo
   & Viviani 1983): tangential speed ``v = K (kappa + kappa_0)^(-1/3)``, so the
   pen slows in tight turns; it starts and ends at rest (a ramp over the first
   and last 8 % of the path). ``K`` is set so that the drawing lasts the
   person's time for the speed (about 1.8 s, 1.15 s and 0.67 s for a gesture of
   average length, as the $1 study's participants took; +-25 % per person,
   longer gestures longer).
4. The pen is sampled every 8 to 16 ms (per person: a device's rate) with
   +-1 ms jitter and 0.4 px of tremor, and rounded to whole pixels and ms.

Deterministic (a seeded generator):
``python -m feelmysign.research.synthetic research/gestures`` writes the
committed set; a test checks that it is unchanged.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

SEED = 20070807  # UIST 2007
PEOPLE = 10
# The $1 study's speeds and about how long its participants took for each (ms).
SPEEDS_MS: dict[str, float] = {"slow": 1800.0, "medium": 1150.0, "fast": 670.0}
EPOCH_MS = 1_156_372_000_000
RAMP = 0.08  # the share of the path over which the pen starts and stops
CURVATURE_FLOOR = 0.02  # kappa_0, 1/px: a straight line is not infinitely fast
TREMOR_PX = 0.4

# Outlines in a unit box, y down: ("poly", corners) or ("curve", control points).
SHAPES: dict[str, tuple[str, list[tuple[float, float]]]] = {
    "triangle": ("poly", [(0.1, 1.0), (0.5, 0.0), (0.9, 1.0), (0.1, 1.0)]),
    "x": ("poly", [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]),
    "rectangle": ("poly", [(0.0, 0.15), (0.0, 0.85), (1.0, 0.85), (1.0, 0.15), (0.0, 0.15)]),
    "circle": (
        "curve",
        [
            (0.5 + 0.5 * math.sin(a), 0.5 - 0.5 * math.cos(a))
            for a in np.linspace(0.0, -2.1 * math.pi, 15)
        ],
    ),
    "check": ("poly", [(0.0, 0.55), (0.3, 1.0), (1.0, 0.0)]),
    "caret": ("poly", [(0.0, 1.0), (0.5, 0.0), (1.0, 1.0)]),
    "question_mark": (
        "curve",
        [
            (0.15, 0.3),
            (0.25, 0.08),
            (0.5, 0.0),
            (0.75, 0.08),
            (0.8, 0.28),
            (0.65, 0.45),
            (0.5, 0.58),
            (0.5, 0.8),
            (0.5, 1.0),
        ],
    ),
    "arrow": ("poly", [(0.0, 1.0), (1.0, 0.0), (0.5, 0.08), (1.0, 0.0), (0.92, 0.5)]),
    "left_sq_bracket": ("poly", [(0.7, 0.0), (0.2, 0.0), (0.2, 1.0), (0.7, 1.0)]),
    "right_sq_bracket": ("poly", [(0.3, 0.0), (0.8, 0.0), (0.8, 1.0), (0.3, 1.0)]),
    "v": ("poly", [(0.0, 0.0), (0.5, 1.0), (1.0, 0.0)]),
    "delete_mark": ("poly", [(0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0)]),
    "left_curly_brace": (
        "curve",
        [
            (0.7, 0.0),
            (0.4, 0.05),
            (0.35, 0.3),
            (0.3, 0.45),
            (0.1, 0.5),
            (0.3, 0.55),
            (0.35, 0.7),
            (0.4, 0.95),
            (0.7, 1.0),
        ],
    ),
    "right_curly_brace": (
        "curve",
        [
            (0.3, 0.0),
            (0.6, 0.05),
            (0.65, 0.3),
            (0.7, 0.45),
            (0.9, 0.5),
            (0.7, 0.55),
            (0.65, 0.7),
            (0.6, 0.95),
            (0.3, 1.0),
        ],
    ),
    "star": (
        "poly",
        [(0.2, 1.0), (0.5, 0.0), (0.8, 1.0), (0.0, 0.38), (1.0, 0.38), (0.2, 1.0)],
    ),
    "pigtail": (
        "curve",
        [
            (0.0, 1.0),
            (0.35, 0.75),
            (0.7, 0.35),
            (0.75, 0.1),
            (0.6, 0.0),
            (0.45, 0.15),
            (0.55, 0.45),
            (0.8, 0.75),
            (1.0, 1.0),
        ],
    ),
}


def _chaikin(points: Array, passes: int, closed: bool = False) -> Array:
    """Corners cut ``passes`` times (Chaikin 1974); the ends stay where they are."""
    for _ in range(passes):
        a, b = points[:-1], points[1:]
        q, r = 0.75 * a + 0.25 * b, 0.25 * a + 0.75 * b
        middle = np.stack([q, r], axis=1).reshape(-1, 2)
        points = np.vstack([points[:1], middle[1:-1], points[-1:]])
    return points


def _catmull_rom(points: Array, per_span: int = 24) -> Array:
    """A smooth curve through the control points (uniform Catmull-Rom)."""
    padded = np.vstack([2 * points[0] - points[1], points, 2 * points[-1] - points[-2]])
    out = []
    t = np.linspace(0.0, 1.0, per_span, endpoint=False)[:, None]
    for i in range(1, len(padded) - 2):
        p0, p1, p2, p3 = padded[i - 1], padded[i], padded[i + 1], padded[i + 2]
        out.append(
            0.5
            * (
                2 * p1
                + (-p0 + p2) * t
                + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t**2
                + (-p0 + 3 * p1 - 3 * p2 + p3) * t**3
            )
        )
    out.append(points[-1:])
    return np.vstack(out)


def _by_length(path: Array, step: float) -> Array:
    """The path resampled at ``step`` px along it."""
    steps = np.hypot(*np.diff(path, axis=0).T)
    along = np.concatenate([[0.0], np.cumsum(steps)])
    wanted = np.append(np.arange(0.0, along[-1], step), along[-1])
    return np.stack([np.interp(wanted, along, path[:, 0]), np.interp(wanted, along, path[:, 1])], 1)


def _curvature(path: Array) -> Array:
    """Unsigned curvature (1/px) at each point of a path of about equal steps."""
    d1 = np.gradient(path, axis=0)
    d2 = np.gradient(d1, axis=0)
    speed = np.maximum(np.hypot(d1[:, 0], d1[:, 1]), 1e-9)
    result: Array = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3
    return result


def drawn_path(
    name: str, person: np.random.Generator, speed: str, traits: dict[str, float]
) -> Array:
    """The pen's path (px, 1 px steps) for one person's drawing of a gesture."""
    kind, outline = SHAPES[name]
    sloppiness = {"slow": 0.6, "medium": 1.0, "fast": 1.6}[speed]
    points = np.array(outline, dtype=np.float64)
    points += person.normal(0.0, 0.025 * sloppiness * traits["jitter"], points.shape)
    points[:, 0] *= traits["aspect"]
    slant = traits["slant"]
    rotation = np.array([[math.cos(slant), -math.sin(slant)], [math.sin(slant), math.cos(slant)]])
    points = points @ rotation.T * traits["size"]
    if kind == "curve":
        path = _catmull_rom(points)
    else:
        passes = round(traits["rounding"] + {"slow": 1, "medium": 2, "fast": 3}[speed])
        path = _chaikin(_by_length(points, traits["size"] / 12.0), passes)
    return _by_length(path, 1.0)


def timed(path: Array, duration_ms: float) -> Array:
    """The time (ms) at each point of a 1 px-step path under the two-thirds power law."""
    speed = (_curvature(path) + CURVATURE_FLOOR) ** (-1.0 / 3.0)
    share = np.linspace(0.0, 1.0, len(path))
    ramp = np.clip(np.minimum(share, 1.0 - share) / RAMP, 0.0, 1.0)
    speed = speed * (0.15 + 0.85 * np.sin(0.5 * math.pi * ramp) ** 2)
    steps = np.hypot(*np.diff(path, axis=0).T)
    dt = steps / (0.5 * (speed[:-1] + speed[1:]))
    times = np.concatenate([[0.0], np.cumsum(dt)])
    result: Array = times * (duration_ms / times[-1])
    return result


def sampled(path: Array, times: Array, period_ms: float, rng: np.random.Generator) -> Array:
    """(x, y, t) rows as a pointer reports them: whole pixels and ms, with jitter and tremor."""
    wanted = [0.0]
    while wanted[-1] + period_ms < times[-1]:
        wanted.append(wanted[-1] + period_ms + rng.uniform(-1.0, 1.0))
    wanted.append(float(times[-1]))
    at = np.array(wanted)
    xs = np.interp(at, times, path[:, 0]) + rng.normal(0.0, TREMOR_PX, len(at))
    ys = np.interp(at, times, path[:, 1]) + rng.normal(0.0, TREMOR_PX, len(at))
    return np.stack([np.round(xs), np.round(ys), np.round(at)], axis=1)


def _traits(rng: np.random.Generator) -> dict[str, float]:
    return {
        "size": rng.uniform(70.0, 160.0),
        "aspect": rng.uniform(0.85, 1.15),
        "slant": math.radians(rng.uniform(-8.0, 8.0)),
        "jitter": rng.uniform(0.5, 1.5),
        "rounding": rng.uniform(0.0, 1.0),
        "pace": rng.uniform(0.75, 1.25),
        "period_ms": rng.uniform(8.0, 16.0),
    }


def gesture_xml(name: str, subject: int, speed: str, rows: Array, start_ms: int) -> str:
    """One drawing as a $1 gesture log."""
    times = rows[:, 2] + start_ms
    points = "\n".join(
        f'  <Point X="{int(x)}" Y="{int(y)}" T="{int(t)}" />'
        for (x, y, _), t in zip(rows, times, strict=True)
    )
    label = f"{name}01"
    return (
        '<?xml version="1.0" encoding="utf-8" standalone="yes"?>\n'
        f'<Gesture Name="{label}" Subject="{subject}" Speed="{speed}" Number="1" '
        f'NumPts="{len(rows)}" Milliseconds="{int(rows[-1, 2])}" '
        f'AppName="feelmysign synthetic" AppVer="1" Date="" TimeOfDay="">\n{points}\n</Gesture>\n'
    )


def generate(folder: Path) -> list[Path]:
    """Every drawing of the set, written under ``folder``; the files written."""
    rng = np.random.default_rng(SEED)
    lengths = {
        name: float(np.hypot(*np.diff(np.array(outline), axis=0).T).sum())
        for name, (_, outline) in SHAPES.items()
    }
    mean_length = float(np.mean(list(lengths.values())))
    written = []
    clock = EPOCH_MS
    for subject in range(1, PEOPLE + 1):
        traits = _traits(rng)
        for speed, base_ms in SPEEDS_MS.items():
            for name in SHAPES:
                path = drawn_path(name, rng, speed, traits)
                duration = (
                    base_ms
                    * traits["pace"]
                    * (lengths[name] / mean_length) ** 0.5
                    * rng.uniform(0.9, 1.1)
                )
                rows = sampled(path, timed(path, duration), traits["period_ms"], rng)
                rows[:, :2] -= rows[:, :2].min(axis=0) - 20.0
                target = folder / f"s{subject:02d}" / speed / f"{name}01.xml"
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_text(gesture_xml(name, subject, speed, rows, clock), encoding="utf-8")
                written.append(target)
                clock += int(rows[-1, 2]) + 1000
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="where to write sNN/SPEED/NAME01.xml")
    args = parser.parse_args(argv)
    written = generate(Path(args.folder))
    print(f"wrote {len(written)} gesture logs under {args.folder}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
