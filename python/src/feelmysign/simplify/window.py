"""The window simplifier: an error-bounded online simplifier over every drawn sample.

An opening window (Meratnia & de By 2004, "Spatiotemporal compression
techniques for moving point objects", EDBT; the family goes back to Sklansky
& Gonzalez 1980 and Williams 1978) that cuts where Douglas-Peucker would
(Douglas & Peucker 1973): at the drawn point farthest from the chord, so that
corners land on the drawing's features. Here:

- It takes every pointer sample (in the browser every pointer event, coalesced
  ones included; in a recording every sample), not animation frames: the bound
  holds for everything drawn, and strokes start and end on real samples (or,
  where a line the latency cap cut goes on, next to one, below) at
  their real times.
- A stroke starts at an anchor sample and grows one sample at a time. When a
  sample arrives, the stroke anchor -> sample is tried: every sample since the
  anchor must lie within ``max_error`` (grid units, after mapping) of that
  segment — the distance to the segment, not to its line.
- If one does not, the stroke is cut at a feature: of the samples since the
  anchor, the one farthest from the chord anchor -> new sample among those
  whose own stroke (anchor -> it) keeps the bound (the sample before the new
  one always does). That stroke is emitted now; the cut sample anchors the
  next stroke, and the samples after it are taken again, so strokes join end
  to start and every sample keeps the bound.
- Latency cap: a stroke lasts at most ``max_stroke_ms`` of drawing. A sample
  that would make it longer cuts it, so the wearer feels a long line begin
  before it ends (the paper's "frame max", in ms): at a feature (as above,
  against the chord to the sample before) among the samples of the stroke's
  second half (``CAP_FEATURE_SHARE``), so the stroke it ends is not too brief
  to be felt in its drawn time; a straight stroke at the sample before. A
  stroke still too short to send (``min_length``) is not cut: a slow pen's
  line would otherwise be cut into pieces too short to feel, all dropped.
- A line the cap cut goes on straight: after a stroke the cap ended whose
  samples all lie within ``LINE_SHARE`` x max_error of it, the next stroke, if
  the cap or the release ends it too, ends on that stroke's line (its end
  sample projected onto it) when that moves the end at most ``LINE_SHARE`` x
  max_error, every sample since its start keeps the bound to that end and it
  is still long enough to send; else at the sample. The cap cuts a line, not
  a corner, and the $1 recogniser scales a thin line to a square, so one
  sample's sideways noise would show as a bend. Such an end lies within
  ``LINE_SHARE`` x max_error of its drawn sample, not on it.
- Work cap: when a stroke holds ``max_window`` samples after its anchor it is
  cut at the current sample (each sample costs at most that many tests).
- On release the rest is one stroke. A path's first sample always starts a
  stroke and its last sample's time always ends one (at the sample, or on the
  line it goes on along).
- A stroke too short (grid units) or too brief (ms) is dropped with its reason,
  as the angle simplifier does; it still ends where the next one starts.

Pure and streaming: ``push`` one sample at a time, ``end`` on release. A
sample earlier than the one before it (clocks of two event sources) is taken
at the earlier one's time, so times never run backwards.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from feelmysign.simplify.mapping import CanvasMapping
from feelmysign.simplify.params import DROP_AND_GRID_SPECS, FrameAndGrid, ParamSpec, check_all
from feelmysign.simplify.segment import Sample, Segment, finish_segment
from feelmysign.stroke import Point

# The latency cap cuts at a feature drawn at least this share of max_stroke_ms after the
# stroke's start, so that the stroke it ends is not too brief to be felt in its drawn time.
CAP_FEATURE_SHARE = 0.5
# A stroke whose samples all lie within this share of max_error of its chord is straight
# (rounding, not a feature): the cap cuts it at its last sample, as late as it can.
STRAIGHT = 1e-6
# A stroke the latency cap ends is a line when all its samples lie within this share of
# max_error of it; the stroke after it then goes on along that line where the bound allows, by
# moving its end at most this share of max_error off its drawn sample (no drift along a bend).
LINE_SHARE = 0.25

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
            "max_window",
            int,
            1,
            10_000,
            "longest stroke in samples after its start (bounds the work per sample)",
        ),
        ParamSpec(
            "max_stroke_ms",
            float,
            0,
            60_000,
            "longest stroke in ms of drawing, so a long line is felt before it ends; 0 = no limit",
        ),
        *DROP_AND_GRID_SPECS,
    )
}


@dataclass(frozen=True)
class WindowParams(FrameAndGrid):
    """The error bound, the caps, then the same drop and grid settings as angle.

    The defaults are the project's (docs/research.md, "Default settings"):
    ``max_error`` 0.25 grid units is 7.5 mm on the paper's sleeve (3 cm
    spacing), well below the forearm's two-point threshold (about 35 mm);
    strokes of at most 300 ms keep the felt drawing within about a third of a
    second of the pen.
    """

    max_error: float = 0.25
    max_window: int = 256
    max_stroke_ms: float = 300.0
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
class _Point:
    sample: Sample
    point: Point  # the sample in grid units


@dataclass
class WindowSimplifier:
    params: WindowParams = field(default_factory=WindowParams)
    # The samples of the stroke being drawn: its anchor first, then every sample since.
    _window: list[_Point] = field(default_factory=list)
    _pointer: Sample | None = None
    _emitted_in_path: bool = False
    # The direction of the stroke the latency cap ended last, while the next one may go on along
    # it (None at a path's start and after any other cut).
    _line: tuple[float, float] | None = None
    _max_error_sq: float = field(init=False)
    _mapping: CanvasMapping = field(init=False)

    def __post_init__(self) -> None:
        self._max_error_sq = self.params.max_error * self.params.max_error
        self._mapping = self.params.mapping

    @property
    def drawing(self) -> bool:
        """True between the first sample of a path and ``end``."""
        return bool(self._window)

    @property
    def line_start(self) -> Sample | None:
        """Where the stroke being drawn starts (canvas pixels); None between paths."""
        return self._window[0].sample if self._window else None

    def push(self, sample: Sample) -> list[Segment]:
        """One pointer sample while the pointer is down; the first of a path is the press."""
        if self._window and sample.t_ms < self._window[-1].sample.t_ms:
            sample = Sample(self._window[-1].sample.t_ms, sample.x, sample.y, sample.pressure)
        self._pointer = sample
        current = _Point(sample, self._mapping.to_grid(sample.x, sample.y))
        if not self._window:
            self._window = [current]
            self._emitted_in_path = False
            self._line = None
            return []
        out: list[Segment] = []
        self._add(current, out)
        return out

    def end(self) -> list[Segment]:
        """Release: the rest of the path as one stroke (a tap gives one, dropped, of length 0)."""
        window = self._window
        self._window = []
        if not window:
            return []
        if len(window) == 1 and self._emitted_in_path:
            return []  # the last sample already ends a stroke (a cut at the work cap)
        return [self._finish(window[0], self._continued(window, len(window) - 1))]

    def _add(self, current: _Point, out: list[Segment]) -> None:
        """``current`` joins the stroke being drawn, cutting it first where it must.

        A cut at a feature gives back the samples after it: they are taken
        again, in order, into the stroke that now starts at the cut.
        """
        pending = [current]  # a stack: the next sample to take is last
        while pending:
            item = pending.pop()
            window = self._window
            anchor = window[0]
            cap_ms = self.params.max_stroke_ms
            if (
                cap_ms > 0
                and len(window) > 1
                and item.sample.t_ms - anchor.sample.t_ms > cap_ms
                and self._sendable(anchor, window[-1])
            ):
                cut = self._cap_cut(window)
                vertex = self._continued(window, cut)
                out.append(self._finish(anchor, vertex))
                self._line = self._line_of(window, cut, vertex)
                if cut < len(window) - 1:
                    pending.append(item)
                    pending.extend(reversed(window[cut + 1 :]))
                    self._window = [vertex]
                    continue
                window = self._window = [vertex]
            if not self._fits(window, 1, len(window), item.point):
                cut = self._feature(window, item.point)
                out.append(self._finish(window[0], window[cut]))
                self._line = None
                pending.append(item)
                pending.extend(reversed(window[cut + 1 :]))
                self._window = [window[cut]]
                continue
            window.append(item)
            if len(window) - 1 >= self.params.max_window:
                out.append(self._finish(window[0], item))
                self._line = None
                self._window = [item]

    def _cap_cut(self, window: list[_Point]) -> int:
        """Where the latency cap cuts: at a feature in the stroke's later part, else at its end.

        The feature is the sample farthest from the chord anchor -> last sample
        among those drawn at least ``CAP_FEATURE_SHARE`` x max_stroke_ms after the
        anchor whose own stroke keeps the bound and is long enough to send; if it
        lies on the chord (a straight stroke, to ``STRAIGHT``), at the last sample.
        """
        anchor = window[0]
        earliest = anchor.sample.t_ms + CAP_FEATURE_SHARE * self.params.max_stroke_ms
        first = next(
            (i for i in range(1, len(window)) if window[i].sample.t_ms >= earliest),
            len(window) - 1,
        )
        cut = self._feature(window, window[-1].point, first)
        straight = STRAIGHT * self.params.max_error
        far_sq = _distance_sq(window[cut].point, anchor.point, window[-1].point)
        bends = far_sq > straight * straight
        return cut if bends and self._sendable(anchor, window[cut]) else len(window) - 1

    def _continued(self, window: list[_Point], cut: int) -> _Point:
        """Where a stroke that the latency cap or the release ends, ending at window[cut], ends.

        After a stroke the latency cap ended that is a line (``_line_of``), the
        stroke that follows it goes on along that line when it can: its end is
        window[cut] projected onto it, if that moves it at most ``LINE_SHARE`` x
        max_error, every sample up to window[cut] keeps the bound to the
        projected end and the stroke is still long enough to send; else
        window[cut] itself. The cap cuts a drawn line, not a drawn corner, so a
        straight line cut into strokes stays one straight line (a sample's
        sideways noise would otherwise bend it).
        """
        at = window[cut]
        if self._line is None:
            return at
        ux, uy = self._line
        ax, ay = window[0].point
        along = (at.point[0] - ax) * ux + (at.point[1] - ay) * uy
        if along <= 0:
            return at
        end = _Point(at.sample, (ax + along * ux, ay + along * uy))
        limit = LINE_SHARE * self.params.max_error
        if _distance_sq(at.point, end.point, end.point) > limit * limit:  # a bend, not noise
            return at
        if not self._sendable(window[0], end) or not self._fits(window, 1, cut + 1, end.point):
            return at
        return end

    def _line_of(self, window: list[_Point], cut: int, end: _Point) -> tuple[float, float] | None:
        """The direction of the stroke window[0] -> end if it is a line, else None.

        A line: every sample up to window[cut] lies within ``LINE_SHARE`` x max_error of it.
        """
        limit = LINE_SHARE * self.params.max_error
        anchor = window[0].point
        for index in range(1, cut + 1):
            if _distance_sq(window[index].point, anchor, end.point) > limit * limit:
                return None
        return _direction(anchor, end.point)

    def _sendable(self, start: _Point, end: _Point) -> bool:
        """Whether start -> end is long enough to send (the cap never cuts off a dropped stroke)."""
        dx, dy = end.point[0] - start.point[0], end.point[1] - start.point[1]
        return dx * dx + dy * dy >= self.params.min_length * self.params.min_length

    def _feature(self, window: list[_Point], end: Point, first: int = 1) -> int:
        """Where to cut: the sample farthest from anchor -> end whose own stroke keeps the bound.

        The last sample always qualifies (the window kept the bound up to it).
        Ties go to the later sample, so the stroke is the longer.
        """
        anchor = window[0].point
        ranked = sorted(
            range(first, len(window)),
            key=lambda i: (_distance_sq(window[i].point, anchor, end), i),
            reverse=True,
        )
        for index in ranked:
            if self._fits(window, 1, index, window[index].point):
                return index
        return len(window) - 1  # unreachable: the last sample fits by construction

    def _fits(self, window: list[_Point], first: int, stop: int, end: Point) -> bool:
        """Whether window[first:stop] all lie within max_error of window[0] -> end."""
        anchor = window[0].point
        for index in range(first, stop):
            if _distance_sq(window[index].point, anchor, end) > self._max_error_sq:
                return False
        return True

    def _finish(self, start: _Point, end: _Point) -> Segment:
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


def _direction(start: Point, end: Point) -> tuple[float, float] | None:
    """The unit vector from ``start`` to ``end`` (None if they coincide)."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    length = math.sqrt(dx * dx + dy * dy)
    return (dx / length, dy / length) if length > 0.0 else None


def _distance_sq(point: Point, start: Point, end: Point) -> float:
    """Squared distance from ``point`` to the segment start -> end (its nearest point)."""
    ax, ay = start
    dx, dy = end[0] - ax, end[1] - ay
    qx, qy = point[0] - ax, point[1] - ay
    length_sq = dx * dx + dy * dy
    if length_sq > 0.0:
        # The nearest point of the segment: the projection, clamped onto it.
        t = min(max((qx * dx + qy * dy) / length_sq, 0.0), 1.0)
        qx, qy = qx - t * dx, qy - t * dy
    return qx * qx + qy * qy
