"""From canvas pixels to the sleeve's grid units.

By default the mapping keeps the aspect ratio (a circle drawn stays a circle on
the skin): one scale for both axes, the canvas centred on the grid. The paper
stretched each axis to fill the grid; ``stretch=True`` does the same.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

from feelmysign.stroke import Point


@dataclass(frozen=True)
class CanvasMapping:
    width_px: float
    height_px: float
    columns: int
    rows: int
    stretch: bool = False

    def to_grid(self, x_px: float, y_px: float) -> Point:
        """Grid point (x = column, y = row) of a canvas pixel, clamped onto the grid."""
        x_extent, y_extent, x_offset, y_offset, scale = self._terms
        if self.stretch:
            x = x_px * x_extent / self.width_px
            y = y_px * y_extent / self.height_px
        else:
            x = x_offset + x_px * scale
            y = y_offset + y_px * scale
        # min(max(v, 0.0), extent), as the comparisons Python's max and min make: a mapping
        # per drawn sample, where the two builtin calls per axis cost more than the rest.
        if x < 0.0:
            x = 0.0
        if x_extent < x:
            x = x_extent
        if y < 0.0:
            y = 0.0
        if y_extent < y:
            y = y_extent
        return (x, y)

    @cached_property
    def _terms(self) -> tuple[float, float, float, float, float]:
        """The grid's extents, the offsets of the centred canvas and the scale, computed once.

        The offsets are the first terms of ``to_grid``'s sums, (extent - size x scale) / 2,
        so every grid point is the same to the last bit as computed in full each time.
        """
        x_extent, y_extent = float(self.columns - 1), float(self.rows - 1)
        scale = self.scale
        x_offset = (x_extent - self.width_px * scale) / 2
        y_offset = (y_extent - self.height_px * scale) / 2
        return x_extent, y_extent, x_offset, y_offset, scale

    @property
    def scale(self) -> float:
        """Grid units per pixel when the aspect ratio is kept (the tighter axis decides)."""
        scales = [
            extent / size
            for extent, size in ((self.columns - 1, self.width_px), (self.rows - 1, self.height_px))
            if extent > 0
        ]
        return min(scales) if scales else 0.0
