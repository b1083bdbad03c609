"""The window simplifier: an error-bounded online simplifier (opening window).

The plain opening window of the line-simplification literature, in its
"before opening window" form (Meratnia & de By 2004, "Spatiotemporal
compression techniques for moving point objects", EDBT; the family goes back
to Sklansky & Gonzalez 1980 and Williams 1978, whose cone intersection makes
the same test in O(1) per sample but bounds the distance to an infinite line,
not to the stroke, and ends strokes off the samples). Here:

- A stroke starts at an anchor frame and grows one frame at a time. When a
  frame arrives, the stroke anchor -> frame is tried: every frame since the
  anchor must lie within ``max_error`` (grid units, after mapping) of that
  segment — the distance to the segment, not to its line.
- If one does not, the stroke ends at the previous frame and is emitted now,
  one frame after its end; the previous frame becomes the next anchor, so
  strokes join end to start.
- When a stroke covers ``max_window`` frames after its anchor it is cut at the
  current frame: the work per frame is at most ``max_window`` distance tests.
- On release the rest is one stroke. A path's first and last frames are
  always stroke ends, and every stroke starts and ends on a frame.
- A stroke too short (grid units) or too brief (ms) is dropped with its reason,
  as the angle simplifier does; it still ends where the next one starts.

It takes the same animation frames (``frames_from_samples`` at ``fps``) as
the angle simplifier, so the two are compared on the same input. Pure and
streaming: ``push`` one frame at a time, ``end`` on release.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from feelmysign.simplify.mapping import CanvasMapping
from feelmysign.simplify.params import FRAME_AND_GRID_SPECS, FrameAndGrid, ParamSpec, check_all
from feelmysign.simplify.segment import Sample, Segment, finish_segment
from feelmysign.stroke import Point

WINDOW_PARAMS: dict[str, ParamSpec] = {
    s.name: s
    for s in (
        ParamSpec(
            "max_error",
            float,
            0.001,
            100,
            "farthest a drawn point may lie from its stroke, in grid units",
        ),
        ParamSpec(
            "max_window", int, 1, 1000, "longest stroke in frames after its start (bounds the work)"
        ),
        *FRAME_AND_GRID_SPECS,
    )
}


@dataclass(frozen=True)
class WindowParams(FrameAndGrid):
    """The error bound and window cap, then the same frame, drop and grid settings as angle.

    ``max_error`` 0.1 grid units is 3 mm on the paper's sleeve (3 cm spacing),
    the same as its minimum stroke length; 64 frames is about a second at 60 fps.
    """

    max_error: float = 0.1
    max_window: int = 64
    fps: float = 60.0
    clear_on_press: bool = True
    min_duration_ms: float = 6.1
    min_length: float = 0.1
    rows: int = 3
    columns: int = 4
    canvas_width_px: float = 1920.0
    canvas_height_px: float = 1080.0
    stretch: bool = False

    def __post_init__(self) -> None:
        check_all(self, WINDOW_PARAMS)


@dataclass(frozen=True)
class _Frame:
    sample: Sample
    point: Point  # the frame in grid units


@dataclass
class WindowSimplifier:
    params: WindowParams = field(default_factory=WindowParams)
    # The frames of the stroke being drawn: its anchor first, then every frame since.
    _window: list[_Frame] = field(default_factory=list)
    _pointer: Sample | None = None
    _emitted_in_path: bool = False
    _max_error_sq: float = field(init=False)
    _mapping: CanvasMapping = field(init=False)

    def __post_init__(self) -> None:
        self._max_error_sq = self.params.max_error * self.params.max_error
        self._mapping = self.params.mapping

    @property
    def drawing(self) -> bool:
        """True between the first frame of a path and ``end``."""
        return bool(self._window)

    @property
    def line_start(self) -> Sample | None:
        """Where the stroke being drawn starts (canvas pixels); None between paths."""
        return self._window[0].sample if self._window else None

    def push(self, frame: Sample) -> list[Segment]:
        """One animation frame while the pointer is down; the first frame of a path is the press."""
        self._pointer = frame
        current = _Frame(frame, self._mapping.to_grid(frame.x, frame.y))
        window = self._window
        if not window:
            self._window = [current]
            self._emitted_in_path = False
            return []
        out: list[Segment] = []
        if not self._fits(window, current.point):
            out.append(self._finish(window[0], window[-1]))
            window = self._window = [window[-1]]
        window.append(current)
        if len(window) - 1 >= self.params.max_window:
            out.append(self._finish(window[0], current))
            self._window = [current]
        return out

    def end(self) -> list[Segment]:
        """Release: the rest of the path as one stroke (a tap gives one, dropped, of length 0)."""
        window = self._window
        self._window = []
        if not window:
            return []
        if len(window) == 1 and self._emitted_in_path:
            return []  # the last frame already ends a stroke (a cut at the window cap)
        return [self._finish(window[0], window[-1])]

    def _fits(self, window: list[_Frame], end: Point) -> bool:
        """Whether every frame after the anchor lies within max_error of anchor -> end."""
        ax, ay = window[0].point
        dx, dy = end[0] - ax, end[1] - ay
        length_sq = dx * dx + dy * dy
        for item in window[1:]:
            qx, qy = item.point[0] - ax, item.point[1] - ay
            if length_sq > 0.0:
                # The nearest point of the segment: the projection, clamped onto it.
                t = min(max((qx * dx + qy * dy) / length_sq, 0.0), 1.0)
                qx, qy = qx - t * dx, qy - t * dy
            if qx * qx + qy * qy > self._max_error_sq:
                return False
        return True

    def _finish(self, start: _Frame, end: _Frame) -> Segment:
        self._emitted_in_path = True
        return finish_segment(
            start.point,
            end.point,
            start.sample.t_ms,
            end.sample.t_ms,
            self._pointer.t_ms if self._pointer else end.sample.t_ms,
            min_length=self.params.min_length,
            min_duration_ms=self.params.min_duration_ms,
        )
