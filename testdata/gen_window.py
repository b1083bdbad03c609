"""Window-simplifier vectors: the angle vectors' paths and the segments the reference emits.

The shapes are gen_angle's (imported, not copied), so both simplifiers are
pinned on the same input. Each case: the full parameter set, the canvas, the
pointer samples of each path (``[t_ms, x_px, y_px, pressure]``) and the
expected segments. An implementation pushes every sample of a path (the window
simplifier takes samples, not frames), calls ``end``, and must reproduce
``expected.segments`` (path index, start, end, times, dropped reason) and
``expected.inputs`` (samples per path) within ``tolerance``. ``params.json`` is the
parameter table (defaults and allowed ranges).
"""

from __future__ import annotations

from typing import Any

from feelmysign.simplify import WindowParams
from feelmysign.simplify.window import WINDOW_PARAMS
from gen_angle import simplifier_cases

VARIATIONS: dict[str, dict[str, Any]] = {
    "defaults": {},
    "max-error-0.02": {"max_error": 0.02},
    "max-error-0.05": {"max_error": 0.05},
    "max-error-0.2": {"max_error": 0.2},
    "max-window-1": {"max_window": 1},
    "max-window-8": {"max_window": 8},
    "max-window-1000": {"max_window": 1000},
    "max-stroke-ms-100": {"max_stroke_ms": 100.0},
    "max-stroke-ms-300": {"max_stroke_ms": 300.0},
    "min-duration-200": {"min_duration_ms": 200.0},
    "min-length-0.5": {"min_length": 0.5},
    "stretch": {"stretch": True, "canvas_width_px": 1600.0},
    "sleeve-4x6": {"rows": 4, "columns": 6},
}


def cases() -> dict[str, dict[str, Any]]:
    return simplifier_cases(
        WindowParams,
        WINDOW_PARAMS,
        VARIATIONS,
        "the window simplifier's parameters: defaults and allowed ranges",
    )
