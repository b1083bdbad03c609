"""From canvas pixels to the sleeve's grid units.

By default the mapping keeps the aspect ratio (a circle drawn stays a circle on
the skin): one scale for both axes, the canvas centred on the grid. The paper
stretched each axis to fill the grid; ``stretch=True`` does the same.
"""

from __future__ import annotations

from dataclasses import dataclass

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
        x_extent, y_extent = float(self.columns - 1), float(self.rows - 1)
        if self.stretch:
            x = x_px * x_extent / self.width_px
            y = y_px * y_extent / self.height_px
        else:
            scale = self.scale
            x = (x_extent - self.width_px * scale) / 2 + x_px * scale
            y = (y_extent - self.height_px * scale) / 2 + y_px * scale
        return (min(max(x, 0.0), x_extent), min(max(y, 0.0), y_extent))

    @property
    def scale(self) -> float:
        """Grid units per pixel when the aspect ratio is kept (the tighter axis decides)."""
        scales = [
            extent / size
            for extent, size in ((self.columns - 1, self.width_px), (self.rows - 1, self.height_px))
            if extent > 0
        ]
        return min(scales) if scales else 0.0
