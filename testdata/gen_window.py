"""Window-simplifier vectors: the angle vectors' paths and the segments the reference emits.

The shapes are gen_angle's (imported, not copied), so both simplifiers are
pinned on the same input. Each case: the full parameter set, the canvas, the
pointer samples of each path (``[t_ms, x_px, y_px, pressure]``) and the
expected segments. An implementation pushes every sample of a path (the window
simplifier takes samples, not frames), calls ``end``, and must reproduce
``expected.segments`` (path index, start, end, times, dropped reason) and
``expected.inputs`` (samples per path) within ``tolerance``, and ``expected.merged_back``:
per path, the pieces merged at release into the stroke already sent before them (nothing is
sent for them; ``WindowSimplifier.merged_back``). ``params.json`` is the
parameter table (defaults and allowed ranges). Besides gen_angle's shapes, a window-only
ones (``EDGE_SHAPES``): a drawing along the canvas edges, whose strokes must stay on the grid,
a crawl, lines released just after a cut of the latency cap (a last piece merged at release,
and one sent), and "L"s with a stop half-way down the stem (``stop``), one without samples
during the stop (``gap``).
"""

from __future__ import annotations

import random
from typing import Any

from feelmysign.simplify import Sample, WindowParams
from feelmysign.simplify.window import WINDOW_PARAMS, WindowSimplifier
from gen_angle import SHAPES, H, Path, W, _line, simplifier_case, simplifier_cases

VARIATIONS: dict[str, dict[str, Any]] = {
    "defaults": {},
    "chord": {"least_squares": False},
    "max-error-0.02": {"least_squares": False, "max_error": 0.02},
    "max-error-0.05": {"least_squares": False, "max_error": 0.05},
    "max-error-0.2": {"least_squares": False, "max_error": 0.2},
    "max-window-1": {"least_squares": False, "max_window": 1},
    "max-window-8": {"least_squares": False, "max_window": 8},
    "max-window-1000": {"least_squares": False, "max_window": 1000},
    "max-stroke-ms-100": {"least_squares": False, "max_stroke_ms": 100.0},
    "max-stroke-ms-300": {"least_squares": False, "max_stroke_ms": 300.0},
    "min-duration-200": {"least_squares": False, "min_duration_ms": 200.0},
    "min-length-0.5": {"least_squares": False, "min_length": 0.5},
    "stretch": {"least_squares": False, "stretch": True, "canvas_width_px": 1600.0},
    "sleeve-4x6": {"least_squares": False, "rows": 4, "columns": 6},
    "rest-off": {"least_squares": False, "rest_ms": 0.0},
    "rest-300": {"least_squares": False, "rest_ms": 300.0},
    "strict-minimums": {
        "least_squares": False,
        "strict_minimums": True,
        "min_length": 0.5,
        "min_duration_ms": 120.0,
    },
    # A wearer's limits as a sender takes them from the sleeve's floor (a wearer file's
    # min_length 0.5 and min_duration_ms 150): strict minimums above the floor.
    "wearer": {
        "least_squares": False,
        "strict_minimums": True,
        "min_length": 0.5,
        "min_duration_ms": 150.0,
    },
}
# The least-squares core (``least_squares``; ``simplify/fit.py``) over the same shapes.
FIT = {"least_squares": True}
FIT_VARIATIONS: dict[str, dict[str, Any]] = {
    "least-squares": FIT,
    "least-squares-max-error-0.05": {**FIT, "max_error": 0.05},
    "least-squares-max-error-0.15": {**FIT, "max_error": 0.15},
    "least-squares-lookahead-0": {**FIT, "lookahead_ms": 0.0},
    "least-squares-lookahead-100": {**FIT, "lookahead_ms": 100.0},
    "least-squares-max-stroke-ms-100": {**FIT, "max_stroke_ms": 100.0},
    "least-squares-no-cap": {**FIT, "max_stroke_ms": 0.0},
    "least-squares-max-window-8": {**FIT, "max_window": 8},
    "least-squares-floor-40": {**FIT, "floor_ms": 40.0},
    "least-squares-min-duration-200": {**FIT, "min_duration_ms": 200.0},
    "least-squares-rest-off": {**FIT, "rest_ms": 0.0},
    "least-squares-rest-300": {**FIT, "rest_ms": 300.0},
    "least-squares-strict-minimums": {
        **FIT,
        "strict_minimums": True,
        "min_length": 0.5,
        "min_duration_ms": 120.0,
    },
    "least-squares-stretch": {**FIT, "stretch": True, "canvas_width_px": 1600.0},
    "least-squares-wearer": {
        **FIT,
        "strict_minimums": True,
        "min_length": 0.5,
        "min_duration_ms": 150.0,
    },
}
VARIATIONS.update(FIT_VARIATIONS)


def _edge_u(seed: int = 3) -> Path:
    """A "U" drawn along the canvas's left, bottom and right edges, as a hand draws it.

    Each sample lies up to 3 px inside its edge or up to 6 px beyond it (the mapping puts it on
    the edge), so the strokes the latency cap ends point a little across the edge, and a line
    going on along one would leave the grid.
    """
    rng = random.Random(seed)
    samples = []
    for s in _line([(0, 150), (0, H), (W, H), (W, 150)], 0.4):
        x, y = s.x, s.y
        if x == 0:
            x = -rng.uniform(-3.0, 6.0)
        elif x == W:
            x = W + rng.uniform(-3.0, 6.0)
        if y == H:
            y = H + rng.uniform(-3.0, 6.0)
        samples.append(Sample(s.t_ms, x, y))
    return samples


def _crawl(seed: int = 5) -> Path:
    """A line, a crawl (the pen creeping on, too little in 200 ms to send), a rest with a still
    hand's jitter, a short hook, a rest, a line, and a crawl before the release."""
    rng = random.Random(seed)
    samples = list(_line([(100, 400), (500, 400)], 0.5))

    def go_on(dx: float, dy: float, count: int, step_ms: float = 8.0) -> None:
        last = samples[-1]
        for k in range(1, count + 1):
            jitter_x, jitter_y = rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6)
            samples.append(
                Sample(
                    round(last.t_ms + step_ms * k, 3),
                    last.x + dx * k / count + jitter_x,
                    last.y + dy * k / count + jitter_y,
                )
            )

    go_on(30, 10, 60)  # 480 ms creeping 32 px (0.1 grid units)
    go_on(0, 0, 40)  # 320 ms at rest
    go_on(-20, 30, 5)  # a brief hook
    go_on(0, 0, 30)  # 240 ms at rest
    go_on(0, -300, 40)  # a line
    go_on(12, 0, 50)  # a crawl, then the release
    return samples


def _tail() -> list[Path]:
    """Two lines released about 30 ms after the latency cap's last cut: the first goes on
    straight to the release (its last piece lies within max_error of the stroke before, and
    merges into it at release: nothing more is sent), the second ends in a quick hook 0.36 grid
    units across (too far from the stroke before: the piece is sent, briefer than the floor)."""
    line = _line([(100, 400), (540, 400)], 1.0, seed=7)
    hooked = _line([(100, 400), (540, 400)], 1.0, seed=7)
    last = hooked[-1]
    hooked += [Sample(round(last.t_ms + 8.0 * k, 3), last.x, last.y + 48.0 * k) for k in (1, 2, 3)]
    return [line, hooked]


def _stop_l(stop_y: float, still_samples: bool = True) -> Path:
    """An "L" drawn as a mouse draws it (a sample a frame at 60 Hz, 800 px/s: 2 grid units a
    second), down from (200, 80) to (200, ``stop_y``), held still there for a second with the
    button down (a sample every 32 ms, as the page and the Processing library sample a still
    pen; with ``still_samples`` off, none, as a source of pointer events alone gives it), on
    down to (200, 720) and across to (1000, 720)."""
    frame_ms = 1000.0 / 60.0
    samples = [Sample(0.0, 200.0, 80.0)]

    def to(x: float, y: float) -> None:
        last = samples[-1]
        steps = max(1, round(max(abs(x - last.x), abs(y - last.y)) / (0.8 * frame_ms)))
        for k in range(1, steps + 1):
            samples.append(
                Sample(
                    round(last.t_ms + frame_ms * k, 3),
                    last.x + (x - last.x) * k / steps,
                    last.y + (y - last.y) * k / steps,
                )
            )

    to(200.0, stop_y)
    last = samples[-1]
    samples += [Sample(round(last.t_ms + 32.0 * k, 3), last.x, last.y) for k in range(1, 32)]
    if not still_samples:
        # Nothing during the stop; the first move after it, 3 px on, when the stop ends.
        samples = [*samples[:-31], Sample(samples[-1].t_ms, last.x, last.y + 3.0)]
    to(200.0, 720.0)
    to(1000.0, 720.0)
    return samples


def _stops() -> list[Path]:
    """Two "L"s with a stop half-way down the stem, where the piece drawn since the last stroke
    is shorter than a wearer's min_length: at grid y 1.0 (a new user's trial: within max_error
    of the stroke before, with the least squares) and 1.1 (too far from it: dropped at the
    rest). With strict minimums the piece is never merged across the stop (the stop would be
    played)."""
    return [_stop_l(400.0), _stop_l(440.0)]


def _gap() -> list[Path]:
    """The first "L" of ``_stops`` from a source of pointer events alone: no sample during the
    stop, and the first after it 3 px on (a pen moves off a little as it sets off again). The
    simplifier takes the pen to have stood still through the gap: the stop is a rest."""
    return [_stop_l(400.0, still_samples=False)]


# Window-only shapes, each with the defaults and the latency cap's variations (W x H fills the
# default 3 x 4 grid, so the canvas edges are the grid's).
EDGE_SHAPES = {
    "edge-u": lambda: [_edge_u()],
    "crawl": lambda: [_crawl()],
    "tail": _tail,
    "stop": _stops,
    "gap": _gap,
}
EDGE_VARIATIONS = (
    "defaults",
    "chord",
    "least-squares",
    "least-squares-max-stroke-ms-100",
    "least-squares-rest-300",
    "least-squares-strict-minimums",
    "max-stroke-ms-100",
    "max-error-0.05",
    "rest-off",
    "rest-300",
    "strict-minimums",
    "least-squares-wearer",
    "wearer",
)


def _edge_case(shape: str, variation: str) -> dict[str, Any]:
    return simplifier_case(
        WindowParams, VARIATIONS[variation], f"{shape} path, {variation}", EDGE_SHAPES[shape]()
    )


def _merged_back(case: dict[str, Any]) -> list[int]:
    """Per path of ``case``, the pieces the reference merges at release into a sent stroke."""
    simplifier = WindowSimplifier(WindowParams(**case["params"]))
    counts = []
    for path in case["paths"]:
        before = simplifier.merged_back
        for t_ms, x, y, pressure in path:
            simplifier.push(Sample(t_ms, x, y, pressure))
        simplifier.end()
        counts.append(simplifier.merged_back - before)
    return counts


def cases() -> dict[str, dict[str, Any]]:
    result = simplifier_cases(
        WindowParams,
        WINDOW_PARAMS,
        VARIATIONS,
        "the window simplifier's parameters: defaults and allowed ranges",
    )
    for shape in SHAPES:
        for name in ("chord", "least-squares"):
            result[f"{shape}/{name}.json"] = simplifier_case(
                WindowParams, VARIATIONS[name], f"{shape} path, {name}", SHAPES[shape]()
            )
    for shape in EDGE_SHAPES:
        for variation in EDGE_VARIATIONS:
            result[f"{shape}/{variation}.json"] = _edge_case(shape, variation)
    for name, case in result.items():
        if name != "params.json":
            case["expected"]["merged_back"] = _merged_back(case)
    return result
