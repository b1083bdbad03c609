"""Window-simplifier vectors: the angle vectors' paths and the segments the reference emits.

The shapes are gen_angle's (imported, not copied), so both simplifiers are
pinned on the same input. Each case: the full parameter set, the canvas, the
pointer samples of each path (``[t_ms, x_px, y_px, pressure]``) and the
expected segments. An implementation resamples each path into frames with
``frames_from_samples(samples, fps)``, pushes every frame, calls ``end``, and
must reproduce ``expected.segments`` (path index, start, end, times, dropped
reason) and ``expected.frames`` within ``tolerance``. ``params.json`` is the
parameter table (defaults and allowed ranges).
"""

from __future__ import annotations

from dataclasses import asdict, fields
from typing import Any

from feelmysign.simplify import WindowParams, frames_from_samples, simplify_paths
from feelmysign.simplify.window import WINDOW_PARAMS
from gen_angle import SHAPES, H, W
from gen_angle import Path as SamplePath

VARIATIONS: dict[str, dict[str, Any]] = {
    "defaults": {},
    "max-error-0.02": {"max_error": 0.02},
    "max-error-0.05": {"max_error": 0.05},
    "max-error-0.2": {"max_error": 0.2},
    "max-window-1": {"max_window": 1},
    "max-window-8": {"max_window": 8},
    "max-window-1000": {"max_window": 1000},
    "fps-30": {"fps": 30.0},
    "min-duration-200": {"min_duration_ms": 200.0},
    "min-length-0.5": {"min_length": 0.5},
    "stretch": {"stretch": True, "canvas_width_px": 1600.0},
    "sleeve-4x6": {"rows": 4, "columns": 6},
}

# Every shape with the defaults; the richer shapes with every variation.
VARIED_SHAPES = ("circle", "zigzag", "right-angle", "pause")


def _segments(params: WindowParams, paths: list[SamplePath]) -> dict[str, Any]:
    segments = [
        {
            "path": p.path,
            "start": list(s.start),
            "end": list(s.end),
            "start_ms": s.start_ms,
            "end_ms": s.end_ms,
            "emitted_at_ms": s.emitted_at_ms,
            "dropped": s.dropped,
        }
        for p in simplify_paths(params, paths)
        for s in [p.segment]
    ]
    return {
        "frames": [len(frames_from_samples(path, params.fps)) for path in paths],
        "segments": segments,
    }


def _case(shape: str, variation: str) -> dict[str, Any]:
    overrides = {"canvas_width_px": W, "canvas_height_px": H, **VARIATIONS[variation]}
    params = WindowParams(**overrides)
    paths = SHAPES[shape]()
    return {
        "description": f"{shape} path, {variation}",
        "tolerance": 1e-9,
        "params": asdict(params),
        "paths": [[[s.t_ms, s.x, s.y, s.pressure] for s in path] for path in paths],
        "expected": _segments(params, paths),
    }


def cases() -> dict[str, dict[str, Any]]:
    result: dict[str, dict[str, Any]] = {}
    for shape in SHAPES:
        result[f"{shape}/defaults.json"] = _case(shape, "defaults")
    for shape in VARIED_SHAPES:
        for variation in VARIATIONS:
            result[f"{shape}/{variation}.json"] = _case(shape, variation)
    defaults = WindowParams()
    result["params.json"] = {
        "description": "the window simplifier's parameters: defaults and allowed ranges",
        "parameters": [
            WINDOW_PARAMS[f.name].to_json(getattr(defaults, f.name)) for f in fields(defaults)
        ],
    }
    return result
