"""The window simplifier as first written: every sample tested at every new one, no shortcuts.

A reference for the property test that the simplifier in ``feelmysign.simplify.window``, which
keeps its samples in flat lists and skips tests a bound proves needless, gives the same strokes
to the last bit. It is the simplifier as of its straight-line rule (a line's end kept on the
grid), with the canvas-to-grid mapping computed in full for every sample (``_to_grid``). Kept
in the tests, not in the package. Its point-to-segment distance and direction are the
simplifier's own: what the two must agree on is which samples are tested where, and the
simplifier's inlined loops must equal that distance to the last bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from feelmysign.simplify.mapping import CanvasMapping
from feelmysign.simplify.segment import Sample, Segment, finish_segment
from feelmysign.simplify.window import (
    CAP_FEATURE_SHARE,
    LINE_SHARE,
    REST_SHARE,
    REST_SPEED_PX_PER_MS,
    STRAIGHT,
    WindowParams,
    segment_distance_sq,
    unit_direction,
)
from feelmysign.stroke import Point


def _to_grid(mapping: CanvasMapping, x_px: float, y_px: float) -> Point:
    """``CanvasMapping.to_grid`` as first written: every term computed for every sample."""
    x_extent, y_extent = float(mapping.columns - 1), float(mapping.rows - 1)
    if mapping.stretch:
        x = x_px * x_extent / mapping.width_px
        y = y_px * y_extent / mapping.height_px
    else:
        scale = mapping.scale
        x = (x_extent - mapping.width_px * scale) / 2 + x_px * scale
        y = (y_extent - mapping.height_px * scale) / 2 + y_px * scale
    return (min(max(x, 0.0), x_extent), min(max(y, 0.0), y_extent))


@dataclass(frozen=True)
class _Point:
    sample: Sample
    point: Point  # the sample in grid units


def _retimed(drawn: _Point, t_ms: float) -> _Point:
    """``drawn`` at another time (the anchor's, while the pen rests or crawls)."""
    return _Point(replace(drawn.sample, t_ms=t_ms), drawn.point)


def _squared(a: Point, b: Point) -> float:
    dx, dy = a[0] - b[0], a[1] - b[1]
    return dx * dx + dy * dy


@dataclass
class ReferenceWindowSimplifier:
    params: WindowParams = field(default_factory=WindowParams)
    # The samples of the stroke being drawn: its anchor first, then every sample since.
    _window: list[_Point] = field(default_factory=list)
    _pointer: Sample | None = None
    _emitted_in_path: bool = False
    # The direction of the stroke the latency cap ended last, while the next one may go on along
    # it (None at a path's start and after any other cut).
    _line: tuple[float, float] | None = None
    # While the pen rests at the anchor: each sample near it moves the anchor's time.
    _resting: bool = False
    _max_error_sq: float = field(init=False)
    _rest_sq: float = field(init=False)
    _mapping: CanvasMapping = field(init=False)

    def __post_init__(self) -> None:
        self._max_error_sq = self.params.max_error * self.params.max_error
        self._mapping = self.params.mapping
        params = self.params
        # The canvas's tighter scale (grid units per pixel), from the axes that have an extent.
        scales = [
            extent / size
            for extent, size in (
                (params.columns - 1, params.canvas_width_px),
                (params.rows - 1, params.canvas_height_px),
            )
            if extent > 0
        ]
        px = REST_SPEED_PX_PER_MS * params.rest_ms
        rest = min(
            REST_SHARE * params.min_length, 0.5 * params.max_error, px * min(scales, default=0.0)
        )
        self._rest_sq = rest * rest

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
        current = _Point(sample, _to_grid(self._mapping, sample.x, sample.y))
        if not self._window:
            self._window = [current]
            self._emitted_in_path = False
            self._line = None
            self._resting = False
            return []
        out: list[Segment] = []
        self._add(current, out)
        return out

    def end(self) -> list[Segment]:
        """Release: the rest of the path as one stroke (a tap gives one, dropped, of length 0)."""
        window = self._window
        self._window = []
        self._resting = False
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
            if self._resting:
                if len(window) == 1 and _squared(item.point, anchor.point) <= self._rest_sq:
                    self._window = [_retimed(anchor, item.sample.t_ms)]
                    continue
                self._resting = False
            if (
                cap_ms > 0
                and len(window) > 1
                and item.sample.t_ms - anchor.sample.t_ms > cap_ms
                and not self._sendable(anchor, window[-1])
            ):
                anchor = window[0] = _retimed(anchor, item.sample.t_ms - cap_ms)
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
            bound_sq = self._bend_sq(window, item.point)
            if not self._fits(window, 1, len(window), item.point, bound_sq):
                cut = self._feature(window, item.point)
                # A piece briefer than the floor, where the window holds a longer one: the
                # feature among the samples drawn at least the floor after the anchor.
                floor_ms = max(self.params.floor_ms, self.params.min_duration_ms)
                floor_end_ms = window[0].sample.t_ms + floor_ms
                if window[cut].sample.t_ms < floor_end_ms <= window[-1].sample.t_ms:
                    later = next(
                        i for i in range(1, len(window)) if window[i].sample.t_ms >= floor_end_ms
                    )
                    cut = self._feature(window, item.point, later)
                out.append(self._finish(window[0], window[cut]))
                self._line = None
                pending.append(item)
                pending.extend(reversed(window[cut + 1 :]))
                self._window = [window[cut]]
                continue
            window.append(item)
            if self._rests(window, out):
                continue
            if len(window) - 1 >= self.params.max_window:
                out.append(self._finish(window[0], item))
                self._line = None
                self._window = [item]

    def _rests(self, window: list[_Point], out: list[Segment]) -> bool:
        """Whether the pen has rested rest_ms at the last sample (then as the package's)."""
        rest_ms = self.params.rest_ms
        last = window[-1]
        t_ms = last.sample.t_ms
        if rest_ms <= 0 or t_ms - window[0].sample.t_ms < rest_ms:
            return False
        start = len(window) - 1
        while start > 0 and _squared(window[start - 1].point, last.point) <= self._rest_sq:
            start -= 1
        if t_ms - window[start].sample.t_ms < rest_ms:
            return False
        if start == 0:
            self._window = [_retimed(window[0], t_ms)]
        else:
            out.append(self._finish(window[0], _Point(window[start].sample, last.point)))
            self._window = [last]
        self._line = None
        self._resting = True
        return True

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
        far_sq = segment_distance_sq(window[cut].point, anchor.point, window[-1].point)
        bends = far_sq > straight * straight
        return cut if bends and self._sendable(anchor, window[cut]) else len(window) - 1

    def _continued(self, window: list[_Point], cut: int) -> _Point:
        """Where a stroke that the latency cap or the release ends, ending at window[cut], ends.

        After a stroke the latency cap ended that is a line (``_line_of``), the
        stroke that follows it goes on along that line when it can: its end is
        window[cut] projected onto it, if that moves it at most ``LINE_SHARE`` x
        max_error, lies on the grid, every sample up to window[cut] keeps the
        bound to the projected end and the stroke is still long enough to send;
        else window[cut] itself. The cap cuts a drawn line, not a drawn corner, so a
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
        x_extent, y_extent = float(self.params.columns - 1), float(self.params.rows - 1)
        if not (0.0 <= end.point[0] <= x_extent and 0.0 <= end.point[1] <= y_extent):
            return at  # off the grid: the sleeve would refuse it
        limit = LINE_SHARE * self.params.max_error
        if segment_distance_sq(at.point, end.point, end.point) > limit * limit:  # a bend, not noise
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
            if segment_distance_sq(window[index].point, anchor, end.point) > limit * limit:
                return None
        return unit_direction(anchor, end.point)

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
            key=lambda i: (segment_distance_sq(window[i].point, anchor, end), i),
            reverse=True,
        )
        for index in ranked:
            if self._fits(window, 1, index, window[index].point):
                return index
        return len(window) - 1  # unreachable: the last sample fits by construction

    def _bend_sq(self, window: list[_Point], end: Point) -> float:
        """The squared bound a stroke window[0] -> end grows under: max_error's, or the bend
        rule's (max_bend x its length, never under bend_floor) when that is less."""
        bend = self.params.max_bend
        if bend <= 0.0 or len(window) == 1:
            return self._max_error_sq
        anchor = window[0].point
        cx, cy = end[0] - anchor[0], end[1] - anchor[1]
        limit = max(bend * math.sqrt(cx * cx + cy * cy), self.params.bend_floor)
        return limit * limit if limit < self.params.max_error else self._max_error_sq

    def _fits(
        self, window: list[_Point], first: int, stop: int, end: Point, limit_sq: float | None = None
    ) -> bool:
        """Whether window[first:stop] all lie within max_error (or sqrt(limit_sq)) of
        window[0] -> end."""
        anchor = window[0].point
        bound_sq = self._max_error_sq if limit_sq is None else limit_sq
        for index in range(first, stop):
            if segment_distance_sq(window[index].point, anchor, end) > bound_sq:
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
