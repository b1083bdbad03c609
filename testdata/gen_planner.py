"""Planner vectors: Tactile Brush schedules from the Python reference (feelmysign.planner).

Each case gives the grid, the options and one stroke, and either the expected
schedule (virtual actuators as ``bursts`` and merged physical ``commands``) or
the expected error reason. Times in ms, points in grid units.
"""

from __future__ import annotations

from typing import Any

from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.planner import MERGE_DISTANCE, plan
from feelmysign.schedule import schedule_to_json
from feelmysign.stroke import Stroke

PAPER = {"rows": 3, "columns": 4, "spacing_cm": 3.0, "default_intensity": 1.0}
WIDE = {"rows": 4, "columns": 6, "spacing_cm": 2.5, "default_intensity": 0.7}
LRA = {**WIDE, "actuator_type": "LRA"}
# A stroke whose row and column crossings fall 0.05 to 0.15 apart: once slowed
# from 83 ms to 1,865 ms, with a burst running 603 ms past its end.
NEAR_CROSSINGS = (2.0429, 0.1643, 0.9571, 0.8214, 83.3333)

# A case: its description, layout, stroke (x0, y0, x1, y1, T[, intensity]) and planner options.
Case = tuple[str, dict[str, Any], tuple[float, ...], dict[str, Any]]


def case(
    description: str, stroke: tuple[float, ...], *, layout: dict[str, Any] = PAPER, **options: Any
) -> Case:
    """A case on the paper's sleeve (unless ``layout`` says otherwise) with the planner's
    default options, but for those given."""
    return (description, layout, stroke, options)


CASES: dict[str, Case] = {
    "worked/two-actuators": case("tactile-brush.md: two points, T = 1000", (0, 0, 1, 0, 1000)),
    "worked/three-actuators": case("tactile-brush.md: (0,0)->(2,0), T = 1000", (0, 0, 2, 0, 1000)),
    "worked/diagonal": case(
        "tactile-brush.md: (0,0)->(3,2), T = 1500, overlaps merged", (0, 0, 3, 2, 1500)
    ),
    "interior/both-ends": case(
        "both endpoints inside cells: four-actuator rendering", (0.5, 0.5, 2.5, 1.5, 800)
    ),
    "interior/crossing-cells": case(
        "interior endpoints, up and to the right", (0.3, 1.7, 2.2, 0.4, 1200)
    ),
    "interior/point": case("a stroke of zero length: one point held", (1.5, 0.5, 1.5, 0.5, 300)),
    "interior/on-row-line": case(
        "endpoints on a row line between actuators", (0.25, 1, 2.75, 1, 900)
    ),
    "merge/through-actuator": case(
        "crosses a row and a column at the same actuator", (0, 0, 2, 2, 1000)
    ),
    "merge/near-corner": case(
        "a row and a column crossing 0.014 apart become one", (0, 0, 2.02, 2, 1000)
    ),
    "merge/no-merge": case(
        "the same stroke with merging off keeps both crossings",
        (0, 0, 2.02, 2, 4000),
        merge_distance=0.0,
    ),
    "feasible/too-fast": case(
        "9 cm at 50 ms: too fast even for two end phantoms; slowed to 73.701 ms", (0, 0, 3, 0, 50)
    ),
    "feasible/too-fast-diagonal": case("the diagonal at 50 ms: slowed", (0, 0, 3, 2, 50)),
    "feasible/too-fast-point": case(
        "a point at 30 ms: held as long as the shortest stroke", (1.5, 0.5, 1.5, 0.5, 30)
    ),
    "feasible/strict": case(
        "too fast for two end phantoms, with strict: rejected", (0, 0, 3, 2, 50), strict=True
    ),
    "feasible/strict-thinned": case(
        "the diagonal at 100 ms with strict: thinned, not rejected", (0, 0, 3, 2, 100), strict=True
    ),
    "feasible/min-40": case(
        "a longer minimum burst thins a stroke that was fine",
        (0, 0, 3, 0, 300),
        min_command_ms=40.0,
    ),
    "feasible/min-0": case(
        "minimum 0: only negative bursts are infeasible", (0, 0, 3, 0, 100), min_command_ms=0.0
    ),
    "thin/straight": case(
        "9 cm at 100 ms: the two crossings left out, time kept", (0, 0, 3, 0, 100)
    ),
    "thin/diagonal": case(
        "the diagonal at 200 ms: the crossings closest in time left out", (0, 0, 3, 2, 200)
    ),
    "thin/near-crossings": case(
        "crossings 0.05 to 0.15 apart: thinned, played in its 83.3 ms", NEAR_CROSSINGS
    ),
    "thin/near-crossings-moved": case(
        "the same with the start moved by 0.003: the same duration", (2.04, *NEAR_CROSSINGS[1:])
    ),
    "thin/near-crossings-merged": case(
        "the same with merge distance 0.15: the same duration", NEAR_CROSSINGS, merge_distance=0.15
    ),
    "overrun/near-crossings-slow": case(
        "that stroke at 1,865 ms: the burst before the last is cut 186.5 ms after the end",
        (*NEAR_CROSSINGS[:4], 1865.349),
    ),
    "overrun/long": case(
        "9 cm in 10 s: the burst before the last is cut 1 s after the end", (0, 0, 3, 0, 10000)
    ),
    "grid/outside": case("(0,0)->(5,5) on 3 x 4: outside the grid", (0, 0, 5, 5, 1000)),
    "grid/negative": case("a negative coordinate", (-0.5, 0, 1, 0, 1000)),
    "grid/zero-duration": case("duration 0", (0, 0, 1, 0, 0)),
    "grid/wide-sleeve": case(
        "a 4 x 6 sleeve with default intensity 0.7", (0.5, 3, 5, 0.25, 2000), layout=WIDE
    ),
    "grid/intensity": case("an explicit intensity", (0, 2, 3, 0.5, 1500, 0.4)),
    "grid/lra": case(
        "linear resonant actuators: 10 ms bursts, so 61 ms fit two end phantoms",
        (0, 0, 5, 3, 61),
        layout=LRA,
    ),
}

DIRECTIONS = {
    "east": (3, 1),
    "west": (0, 1),
    "north": (1, 0),
    "south": (1, 2),
    "north-east": (2, 0),
    "north-west": (0, 0),
    "south-east": (2, 2),
    "south-west": (0, 2),
}


def _all_cases() -> dict[str, Case]:
    cases = dict(CASES)
    for name, (x, y) in DIRECTIONS.items():
        cases[f"direction/{name}"] = case(
            f"from the actuator (1, 1) to the {name}", (1, 1, x, y, 600)
        )
    return cases


def _run(
    layout_args: dict[str, Any], values: tuple[float, ...], options: dict[str, Any]
) -> dict[str, Any]:
    layout = Layout(**layout_args)
    x0, y0, x1, y1, duration_ms, *rest = values
    stroke = Stroke((x0, y0), (x1, y1), duration_ms, rest[0] if rest else None)
    try:
        return {"expected": schedule_to_json(plan(stroke, layout, **options), bursts=True)}
    except StrokeError as error:
        return {"expected_error": {"reason": error.reason}}


def cases() -> dict[str, dict[str, Any]]:
    result = {}
    for name, (description, layout_args, values, options) in _all_cases().items():
        x0, y0, x1, y1, duration_ms, *rest = values
        full_options = {
            "min_command_ms": Layout(**layout_args).shortest_burst_ms,
            "merge_distance": MERGE_DISTANCE,
            "strict": False,
        }
        full_options.update(options)
        stroke: dict[str, Any] = {"start": [x0, y0], "end": [x1, y1], "duration_ms": duration_ms}
        if rest:
            stroke["intensity"] = rest[0]
        result[f"{name}.json"] = {
            "description": description,
            "tolerance": 1e-6,
            "layout": layout_args,
            "options": full_options,
            "stroke": stroke,
            **_run(layout_args, values, full_options),
        }
    return result
