"""Angle-simplifier vectors: synthetic pointer paths and the segments the reference emits.

Each case: the full parameter set, the canvas, the pointer samples of each path
(``[t_ms, x_px, y_px, pressure]``, at pointer-event times, not frame times),
and the expected segments. An implementation resamples each path into frames
with ``frames_from_samples(samples, fps)``, pushes every frame, calls ``end``,
and must reproduce ``expected.segments`` (path index, start, end, times,
dropped reason) and ``expected.inputs`` (frames per path) within ``tolerance``.
``params.json`` is the parameter table (defaults and allowed ranges).
"""

from __future__ import annotations

import itertools
import math
import random
from collections.abc import Callable
from dataclasses import asdict, fields
from typing import Any

from feelmysign.simplify import AngleParams, Sample, WindowParams, simplify_paths
from feelmysign.simplify.angle import ANGLE_PARAMS
from feelmysign.simplify.params import ParamSpec
from feelmysign.simplify.registry import Params, algorithm_of

W, H = 1200.0, 800.0  # the canvas of every case: the 3 x 2 grid's aspect ratio

Path = list[Sample]


def _line(points: list[tuple[float, float]], speed_px_per_ms: float, seed: int = 1) -> Path:
    """Samples along a polyline at pointer-event times (about 8 ms apart, jittered)."""
    rng = random.Random(seed)
    samples, t_ms = [Sample(0.0, *points[0])], 0.0
    for (x0, y0), (x1, y1) in itertools.pairwise(points):
        length = math.hypot(x1 - x0, y1 - y0)
        steps = max(1, round(length / (speed_px_per_ms * 8.0)))
        for k in range(1, steps + 1):
            t_ms += round(8.0 + rng.uniform(-2.0, 2.0), 3)
            samples.append(Sample(t_ms, x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps))
    return samples


def _circle(speed: float) -> Path:
    points = [
        (600 + 300 * math.cos(a / 48 * 2 * math.pi), 400 + 300 * math.sin(a / 48 * 2 * math.pi))
        for a in range(49)
    ]
    return _line(points, speed)


def _zigzag(speed: float) -> Path:
    return _line([(100 + 100 * k, 200 if k % 2 == 0 else 600) for k in range(11)], speed)


def _pause() -> Path:
    first = _line([(100, 400), (600, 400)], 0.5)
    t_end = first[-1].t_ms
    held = [Sample(t_end + 16 * k, 600, 400) for k in range(1, 63)]  # a second without moving
    second = _line([(600, 400), (600, 100)], 0.5, seed=2)
    return first + held + [Sample(s.t_ms + held[-1].t_ms, s.x, s.y) for s in second[1:]]


def _flick_back() -> Path:
    out = [Sample(k * 8.0, 300.0 + 800.0 * k / 75, 400.0) for k in range(76)]
    return out + [Sample(600.0 + 8.0 * k, 1100.0 - 800.0 * k / 5, 400.0) for k in range(1, 6)]


def _late_release() -> Path:
    samples = [Sample(k * 8.0, 200.0 + 6.0 * k, 300.0 + 2.0 * k) for k in range(63)]
    frame_ms = 1000.0 / 60.0 * 30  # the 30th frame after the press
    return [*samples, Sample(frame_ms + 0.0003, 200.0 + 6.0 * 63, 300.0 + 2.0 * 63)]


def _brace() -> Path:
    rng = random.Random(4)
    samples = []
    for k in range(121):
        u = k / 120  # 0..1 down the brace; the tip halfway
        y = 100.0 + 600.0 * u
        bulge = 120.0 * math.sin(math.pi * 2 * u) ** 2
        tip = 160.0 * max(0.0, 1 - abs(u - 0.5) * 12)
        x = 600.0 - bulge * 0.5 + tip + rng.uniform(-1.5, 1.5)
        samples.append(Sample(k * 8.0, x, y))
    return samples


def _pressure(path: Path) -> Path:
    return [
        Sample(s.t_ms, s.x, s.y, round(0.2 + 0.6 * k / len(path), 4)) for k, s in enumerate(path)
    ]


SHAPES: dict[str, Callable[[], list[Path]]] = {
    "straight": lambda: [_line([(100, 100), (1100, 700)], 0.5)],
    "right-angle": lambda: [_line([(200, 600), (200, 150), (1000, 150)], 0.5)],
    "circle": lambda: [_circle(0.6)],
    "zigzag": lambda: [_zigzag(0.6)],
    "slow": lambda: [_line([(100, 400), (1100, 400), (1100, 700)], 0.05)],
    "fast": lambda: [_zigzag(4.0)],
    "pause": lambda: [_pause()],
    "two-paths": lambda: [
        _line([(100, 100), (500, 500)], 0.5),
        _line([(700, 100), (700, 700), (1000, 700)], 0.5, 3),
    ],
    "tap": lambda: [[Sample(0.0, 300, 300), Sample(40.0, 300.4, 300.2)]],
    "pressure": lambda: [_pressure(_line([(100, 700), (600, 100), (1100, 700)], 0.5))],
    # Out 2 grid units in 600 ms, flicked back onto the start in 40 ms: two strokes.
    "flick-back": lambda: [_flick_back()],
    # A pen at 125 Hz whose release lands a rounding error after a 60 fps frame.
    "late-release": lambda: [_late_release()],
    # A brace: two arcs meeting at a sharp tip, drawn with a little hand tremor.
    "brace": lambda: [_brace()],
}

VARIATIONS: dict[str, dict[str, Any]] = {
    "defaults": {},
    "check-frames-2": {"check_frames": 2},
    "check-frames-15": {"check_frames": 15},
    "max-angle-5": {"max_angle_deg": 5.0},
    "max-angle-45": {"max_angle_deg": 45.0},
    "frame-max-60": {"frame_max": 60},
    "fps-30": {"fps": 30.0},
    "fps-120": {"fps": 120.0},
    "no-recover": {"recover": False},
    "min-duration-200": {"min_duration_ms": 200.0},
    "min-length-0.5": {"min_length": 0.5},
    "stretch": {"stretch": True, "canvas_width_px": 1600.0},
    "sleeve-4x6": {"rows": 4, "columns": 6},
}

# Every shape with the defaults; the richer shapes with every variation.
VARIED_SHAPES = ("circle", "zigzag", "right-angle", "pause", "brace")


def _segments(params: Params, paths: list[Path]) -> dict[str, Any]:
    segments = [
        {
            "path": p.path,
            "start": list(s.start),
            "end": list(s.end),
            "start_ms": s.start_ms,
            "end_ms": s.end_ms,
            "emitted_at_ms": s.emitted_at_ms,
            "dropped": s.dropped,
            # The window simplifier merges pieces too short to send: how many are in this one.
            **({"merged": s.merged} if isinstance(params, WindowParams) else {}),
            # ... and gives a piece briefer than the sleeve's floor the floor's duration: how
            # long the sleeve is to play each stroke (end_ms - start_ms unless so).
            **({"duration_ms": s.duration_ms} if isinstance(params, WindowParams) else {}),
        }
        for p in simplify_paths(params, paths)
        for s in [p.segment]
    ]
    algorithm = algorithm_of(params)
    return {
        "inputs": [len(algorithm.inputs(params, path)) for path in paths],
        "segments": segments,
    }


def simplifier_case(
    make_params: Callable[..., Params],
    variation: dict[str, Any],
    description: str,
    paths: list[Path],
) -> dict[str, Any]:
    """One vector: ``paths`` with the ``variation``'s parameters, on the W x H canvas unless
    the variation names another."""
    params = make_params(**{"canvas_width_px": W, "canvas_height_px": H, **variation})
    return {
        "description": description,
        "tolerance": 1e-9,
        "params": asdict(params),
        "paths": [[[s.t_ms, s.x, s.y, s.pressure] for s in path] for path in paths],
        "expected": _segments(params, paths),
    }


def simplifier_cases(
    make_params: Callable[..., Params],
    specs: dict[str, ParamSpec],
    variations: dict[str, dict[str, Any]],
    params_description: str,
) -> dict[str, dict[str, Any]]:
    """Every shape with the defaults, the richer shapes with every variation, and the table.

    Shared by every simplifier's generator, so all are pinned on the same paths.
    """

    def case(shape: str, variation: str) -> dict[str, Any]:
        return simplifier_case(
            make_params, variations[variation], f"{shape} path, {variation}", SHAPES[shape]()
        )

    result: dict[str, dict[str, Any]] = {}
    for shape in SHAPES:
        result[f"{shape}/defaults.json"] = case(shape, "defaults")
    for shape in VARIED_SHAPES:
        for variation in variations:
            result[f"{shape}/{variation}.json"] = case(shape, variation)
    defaults = make_params()
    result["params.json"] = {
        "description": params_description,
        "parameters": [specs[f.name].to_json() for f in fields(defaults)],
    }
    return result


def cases() -> dict[str, dict[str, Any]]:
    return simplifier_cases(
        AngleParams,
        ANGLE_PARAMS,
        VARIATIONS,
        "the angle simplifier's parameters: defaults (paper, B.1), allowed ranges",
    )
