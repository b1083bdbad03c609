"""Parameters of the simplifiers: defaults, allowed ranges, units, help — one table.

The same table is written to ``testdata/angle/params.json`` so that the
browser's settings panel validates with exactly these ranges.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

from feelmysign.errors import ParameterError
from feelmysign.simplify.mapping import CanvasMapping


@dataclass(frozen=True)
class ParamSpec:
    name: str
    kind: type
    minimum: float | None
    maximum: float | None
    help: str

    def check(self, value: Any) -> None:
        if self.kind is bool:
            if not isinstance(value, bool):
                raise ParameterError(self.name, value, "true or false")
            return
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(self.name, value, f"a number in {self.range_text()}")
        if self.kind is int and not float(value).is_integer():
            raise ParameterError(self.name, value, f"a whole number in {self.range_text()}")
        if not math.isfinite(value) or not self._in_range(float(value)):
            raise ParameterError(self.name, value, f"in {self.range_text()}")

    def _in_range(self, value: float) -> bool:
        low_ok = self.minimum is None or value >= self.minimum
        high_ok = self.maximum is None or value <= self.maximum
        return low_ok and high_ok

    def range_text(self) -> str:
        return f"[{_fmt(self.minimum)}, {_fmt(self.maximum)}]"

    def to_json(self, default: Any) -> dict[str, Any]:
        return {
            "name": self.name,
            "type": {bool: "boolean", int: "integer", float: "number"}[self.kind],
            "default": default,
            "minimum": self.minimum,
            "maximum": self.maximum,
            "help": self.help,
        }


def _fmt(bound: float | None) -> str:
    return "unbounded" if bound is None else f"{bound:g}"


def check_all(params: object, specs: dict[str, ParamSpec]) -> None:
    """Raise ParameterError for the first field of a params dataclass outside its range."""
    for field in fields(params):  # type: ignore[arg-type]
        specs[field.name].check(getattr(params, field.name))


# The drop and grid settings every simplifier has (beside its own).
DROP_AND_GRID_SPECS = (
    ParamSpec("clear_on_press", bool, None, None, "a new press clears the drawing"),
    ParamSpec("min_duration_ms", float, 0, 10_000, "shortest stroke to send, in ms"),
    ParamSpec("min_length", float, 0, 100, "shortest stroke to send, in grid units"),
    ParamSpec("rows", int, 1, 64, "actuator rows of the sleeve"),
    ParamSpec("columns", int, 1, 64, "actuator columns of the sleeve"),
    ParamSpec("canvas_width_px", float, 1, 100_000, "drawing area width in pixels"),
    ParamSpec("canvas_height_px", float, 1, 100_000, "drawing area height in pixels"),
    ParamSpec("stretch", bool, None, None, "stretch the canvas onto the grid (the paper's)"),
)
# A simplifier that sees animation frames has their rate too.
FRAME_AND_GRID_SPECS = (
    ParamSpec("fps", float, 1, 1000, "frames per second of the drawing loop"),
    *DROP_AND_GRID_SPECS,
)


class FrameAndGrid:
    """The canvas-to-grid mapping of a simplifier's parameters (their grid and canvas fields)."""

    rows: int
    columns: int
    canvas_width_px: float
    canvas_height_px: float
    stretch: bool

    @property
    def mapping(self) -> CanvasMapping:
        return CanvasMapping(
            self.canvas_width_px, self.canvas_height_px, self.columns, self.rows, self.stretch
        )
