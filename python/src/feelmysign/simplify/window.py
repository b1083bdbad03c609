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
  to start and every sample keeps the bound. A cut that would end a piece
  briefer than the sleeve's floor (``floor_ms``, or ``min_duration_ms`` if
  longer) is made, where the window holds a sample drawn at least that long
  after the anchor, at the feature among those samples: the sleeve need not
  slow the piece, and the merger need not hold it (a corner it passes lies
  within max_error of the piece, as every sample does).
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
  max_error, the end stays on the grid (the sleeve refuses a stroke off it),
  every sample since its start keeps the bound to that end and it is still
  long enough to send; else at the sample. The cap cuts a line, not
  a corner, and the $1 recogniser scales a thin line to a square, so one
  sample's sideways noise would show as a bend. Such an end lies within
  ``LINE_SHARE`` x max_error of its drawn sample, not on it.
- Work cap: when a stroke holds ``max_window`` samples after its anchor it is
  cut at the current sample (each sample costs at most that many tests).
- On release the rest is one stroke. A path's first sample always starts a
  stroke and its last sample's time ends one (at the sample, or on the line it
  goes on along), unless that last piece merges back (below).
- Bend rule: while ``max_bend`` > 0 a stroke grows only while every sample
  since its anchor lies within ``max_bend`` x its chord's length (never under
  ``bend_floor``, never over ``max_error``), so a round shape is cut into more
  strokes; a cut still keeps ``max_error``.
- A piece too short (``min_length``) or briefer than the sleeve's floor
  (``floor_ms``, or ``min_duration_ms`` if longer) is not dropped: ``Merger``
  merges it into the next piece where every drawn sample of both keeps
  ``max_error``, else sends it as it is. Only a path that is one such piece in
  all (a tap) is dropped, with its reason, as the angle simplifier drops.
- No stroke the sleeve must slow: a stroke drawn briefer than the floor
  (one that could not merge, where the bound must win: a circle drawn in a
  third of a second needs more strokes than the floor leaves time for) is sent
  to last the floor (``Segment.play_ms``), as the sleeve would have slowed it;
  its times stay the drawn ones. The strokes after it catch up on the sleeve,
  as before.
- Merged back at release: the piece left when the pen lifts, if briefer than
  the floor (the pen lifted within the floor after the last cut, mostly one of
  the latency cap), merges into the stroke already sent before it when every
  drawn sample that stroke has not covered lies within ``max_error`` of it:
  nothing more is sent, the sent stroke is not held back or changed, and the
  path's felt end is earlier (the sleeve would play the piece at the floor,
  after the stroke before). ``merged_back`` counts such pieces (a held piece
  that had merged others counts them too). With strict minimums a last piece
  below ``min_length`` merges back the same way instead of being dropped.

- A resting pen (``rest_ms``): when the samples of the last ``rest_ms`` all
  lie within the rest radius (``REST_SHARE`` x min_length, at most max_error
  / 2, and at most what a pen at ``REST_SPEED_PX_PER_MS`` covers in
  ``rest_ms``, so a slow steady pen is never taken for a resting one) of the
  newest, the stroke so far ends there, at the time the rest
  began, and is sent now; while the pen stays, the next stroke's start moves
  on with it, so the rest is not played. A held short piece is sent at the
  rest (briefer than the floor, it takes the time it needs from the rest);
  nothing is merged across a rest.
- A crawling pen: a stroke still too short to send after ``max_stroke_ms``
  starts later rather than lasting longer, so the latency cap holds for it.
- Strict minimums (``strict_minimums``, a wearer's limits): a piece below
  ``min_length`` or ``min_duration_ms`` merges into the next even where
  ``max_error`` must yield, but never across a rest: a path's last such piece,
  and one still below them at a rest (after taking time from it), merges back
  into the stroke sent before it where the bound allows, else is dropped with
  its reason.

Pure and streaming: ``push`` one sample at a time, ``end`` on release. A
sample earlier than the one before it (clocks of two event sources) is taken
at the earlier one's time, so times never run backwards.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field, replace

from feelmysign.simplify.distance import ROUNDING_SLACK
from feelmysign.simplify.fit import FitCore
from feelmysign.simplify.mapping import CanvasMapping
from feelmysign.simplify.params import ParamSpec, SharedParams, param, specs_of
from feelmysign.simplify.segment import (
    NOT_ENOUGH_DISTANCE,
    NOT_ENOUGH_DURATION,
    Sample,
    Segment,
    finish_segment,
)
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
# A pen rests while its samples stay within this share of min_length of one point (never
# farther than half of max_error, so the point that ends or starts a stroke covers the rest):
# well below a stroke the sleeve renders, well above a still hand's jitter.
REST_SHARE = 0.25
# ... and never farther than a pen this slow (canvas pixels per ms) covers in rest_ms: a quarter
# of a pixel a frame at 60 fps. A pen that stays near one point for all of rest_ms rests; a slow,
# steady pen does not, as the distance it covers over the whole window tells: at twice this speed
# (half a pixel a frame) or more, in any direction, it leaves the radius well within rest_ms, even
# with its samples rounded to whole pixels. In pixels, not grid units: a hand's speed on the
# screen does not depend on how the canvas maps onto the sleeve (at the default canvas a quarter
# of min_length is 16 pixels, which a pen at 2 pixels a frame took 100 ms to leave).
REST_SPEED_PX_PER_MS = 0.015


@dataclass(frozen=True)
class _WindowOwn:
    """The error bound and the caps.

    The defaults are the project's (docs/research.md, "Default settings"):
    ``max_error`` 0.25 grid units is 7.5 mm on the paper's sleeve (3 cm
    spacing), well below the forearm's two-point threshold (about 35 mm);
    strokes of at most 200 ms, with the sleeve catching up queued strokes, end
    the felt drawing about a quarter second after the pen on people's fast and
    medium gestures. The bend rule is off (``max_bend`` 0): on people's gestures
    it gained at most a gesture or two a speed, within the noise, and with its
    absolute floor it overrides a coarse ``max_error`` (the study's resolution
    levels and the page's detail control). ``floor_ms`` is the sleeve's own
    (73.701 ms on ERM motors, as its status reports it: two 20 ms end bursts,
    ``apparent_motion.shortest_planned_ms``, rounded up to the microsecond; a
    piece of 73.7 ms would be slowed by a microsecond).
    """

    max_error: float = param(
        0.25,
        0.001,
        100,
        help="farthest a drawn point may lie from its stroke, in grid units",
        label="Max error",
        unit="grid units",
        detail_levels=(0.4, 0.25, 0.15, 0.1, 0.05),
        short="err",
    )
    max_window: int = param(
        256,
        1,
        10_000,
        help="longest stroke in samples after its start (bounds the work per sample)",
        label="Window cap",
        unit="samples",
    )
    max_stroke_ms: float = param(
        200.0,
        0,
        60_000,
        help="longest stroke in ms of drawing, so a long line is felt before it ends; 0 = no limit",
        label="Longest stroke",
        unit="ms",
    )
    max_bend: float = param(
        0.0,
        0,
        1,
        help="farthest a drawn point may lie from its stroke as a share of the stroke's length "
        "(never under bend_floor), so round shapes stay round; 0 = no limit",
        label="Max bend",
        unit="of the stroke's length",
        only_when=("least_squares", False),
    )
    bend_floor: float = param(
        0.1,
        0,
        100,
        help="least bound the bend rule sets, in grid units, so noise does not cut a short stroke",
        label="Bend floor",
        unit="grid units",
        only_when=("least_squares", False),
    )
    rest_ms: float = param(
        100.0,
        0,
        10_000,
        help="a pen resting this long ends the stroke so far, in ms (the rest is not played); "
        "0 = never",
        label="Rest",
        unit="ms",
    )
    strict_minimums: bool = param(
        False,
        help="never send a stroke below min_length or min_duration_ms, even where max_error must "
        "yield (a wearer's measured limits: senders set it from the sleeve's status)",
        label="Strict minimums",
    )
    floor_ms: float = param(
        73.701,
        0,
        10_000,
        help="shortest stroke the sleeve plays without slowing it, in ms (its status says); "
        "a piece drawn briefer merges into a neighbour where the error bound allows, else is "
        "sent to last it",
        label="Sleeve floor",
        unit="ms",
    )
    least_squares: bool = param(
        True,
        help="place strokes where the drawn samples lie nearest them (least squares over "
        "several strokes, each lasting the sleeve's floor) instead of at the sample farthest "
        "from the chord where the bound breaks",
        label="Least squares",
    )
    lookahead_ms: float = param(
        30.0,
        0,
        1000,
        help="how long the pen draws past a stroke's end before the stroke is sent, in ms",
        label="Lookahead",
        unit="ms",
        only_when=("least_squares", True),
    )


@dataclass(frozen=True)
class WindowParams(SharedParams, _WindowOwn):
    """The error bound, the caps, then the same drop and grid settings as angle."""


WINDOW_PARAMS: dict[str, ParamSpec] = specs_of(WindowParams)

# The grid ``feelmysign evaluate`` sweeps without --sweep: around 0.1 grid units, small enough
# for all 210 LASA demonstrations in a minute or two.
SWEEPS = ("max_error=0.05:0.3:0.05",)


def describe(params: WindowParams) -> str:
    """The settings that shape the strokes, in a few words."""
    # The latency cap cuts a stroke after so much drawing; a stroke merged with a brief
    # neighbour, or drawn between two samples further apart, can still last longer.
    cap = (
        f"cut after {params.max_stroke_ms:g} ms of drawing"
        if params.max_stroke_ms
        else "not cut by time"
    )
    if params.least_squares:
        floor_ms = max(params.floor_ms, params.min_duration_ms)
        return (
            f"window, least squares: max error {params.max_error:g} grid units, strokes of "
            f"{floor_ms:g} ms or more (the sleeve's floor), sent {params.lookahead_ms:g} ms "
            f"after their end is drawn, {cap}"
        )
    return f"window, chord: max error {params.max_error:g} grid units, every sample, {cap}"


@dataclass
class WindowCore:
    """The window itself: strokes cut by the error bound, the bend rule and the caps, before
    too-short pieces are merged (``WindowSimplifier`` merges them)."""

    params: WindowParams = field(default_factory=WindowParams)
    # The stroke being drawn, its anchor first, then every sample since, as three parallel lists:
    # the points in grid units, their times and their samples. Plain lists of floats and tuples,
    # not an object per sample: every sample is tested against the chord at every new one.
    _points: list[Point] = field(default_factory=list)
    _times: list[float] = field(default_factory=list)
    _samples: list[Sample] = field(default_factory=list)
    _pointer: Sample | None = None
    _emitted_in_path: bool = False
    # The direction of the stroke the latency cap ended last, while the next one may go on along
    # it (None at a path's start and after any other cut).
    _line: tuple[float, float] | None = None
    # The reach of the stroke being drawn: no sample since its anchor lies farther than this from
    # the segment anchor -> last sample (grid units; true distances, rounding allowed for). A
    # sample that moves the end by a step moves every point of that segment by at most the step,
    # so while reach + step stays under max_error (by ROUNDING_SLACK) every sample keeps the bound
    # to the new segment without testing each one, as testing each one would find; else they are
    # tested, and their farthest distance is the new reach. The same strokes, fewer tests.
    _reach: float = 0.0
    # The reach each sample of the stroke had when it was the last: a bound on the distances of
    # the samples before it to anchor -> it, which stay as they are while the stroke goes on. So
    # a test of points[1:i] against anchor -> points[i] or a point near it (a cut's feature, a
    # line's end) needs no sample tested when that bound says so. Index 0 is never read.
    _reaches: list[float] = field(default_factory=lambda: [0.0])
    # While the pen rests at the anchor (``rest_ms``): each sample near it moves the anchor's time.
    _resting: bool = False
    # Whether the last push found the pen resting (the stroke before the rest is final).
    rested: bool = False
    # The last sample pushed, as taken: its time (never before the one before) and grid point.
    _taken: tuple[float, Point] = (0.0, (0.0, 0.0))
    _max_error_sq: float = field(init=False)
    _rest_sq: float = field(init=False)
    _min_length_sq: float = field(init=False)
    # The shortest piece the merger need not hold: the larger of floor_ms and min_duration_ms.
    _floor_ms: float = field(init=False)
    _reach_limit: float = field(
        init=False
    )  # reach + step at most this: every sample keeps the bound
    _mapping: CanvasMapping = field(init=False)
    # The grid's extents (grid units): every stroke's start and end lies in [0, x] x [0, y].
    _x_extent: float = field(init=False)
    _y_extent: float = field(init=False)

    def __post_init__(self) -> None:
        self._max_error_sq = self.params.max_error * self.params.max_error
        self._min_length_sq = self.params.min_length * self.params.min_length
        self._floor_ms = max(self.params.floor_ms, self.params.min_duration_ms)
        self._reach_limit = self.params.max_error - ROUNDING_SLACK
        rest = rest_radius(self.params)
        self._rest_sq = rest * rest
        self._mapping = self.params.mapping
        self._x_extent = float(self.params.columns - 1)
        self._y_extent = float(self.params.rows - 1)

    @property
    def drawing(self) -> bool:
        """True between the first sample of a path and ``end``."""
        return bool(self._points)

    @property
    def line_start(self) -> Sample | None:
        """Where the stroke being drawn starts (canvas pixels); None between paths."""
        return self._samples[0] if self._samples else None

    def last_sample(self) -> tuple[float, Point]:
        """The last sample taken, as taken: its time (never before the one before) and point."""
        return self._taken

    def pointer_ms(self) -> float:
        """The time of the last sample pushed, as taken (0 before any)."""
        return self._pointer.t_ms if self._pointer else 0.0

    def push(self, sample: Sample) -> list[Segment]:
        """One pointer sample while the pointer is down; the first of a path is the press."""
        times = self._times
        if times and sample.t_ms < times[-1]:
            sample = Sample(times[-1], sample.x, sample.y, sample.pressure)
        self._pointer = sample
        point = self._mapping.to_grid(sample.x, sample.y)
        self._taken = (sample.t_ms, point)
        self.rested = False
        if not times:
            self._points, self._times, self._samples = [point], [sample.t_ms], [sample]
            self._emitted_in_path = False
            self._line = None
            self._reach = 0.0
            self._resting = False
            return []
        out: list[Segment] = []
        self._add(point, sample, out)
        return out

    def end(self) -> list[Segment]:
        """Release: the rest of the path as one stroke (a tap gives one, dropped, of length 0)."""
        points, times = self._points, self._times
        self._points, self._times, self._samples = [], [], []
        self._resting = False
        if not points:
            return []
        if len(points) == 1 and self._emitted_in_path:
            return []  # the last sample already ends a stroke (a cut at the work cap)
        end = self._continued(points, len(points) - 1)
        return [self._finish(points[0], times[0], end, times[-1])]

    def _add(self, point: Point, sample: Sample, out: list[Segment]) -> None:
        """``point`` (of ``sample``) joins the stroke being drawn, cutting it first where it must.

        A cut at a feature gives back the samples after it: they are taken
        again, in order, into the stroke that now starts at the cut.
        """
        cap_ms = self.params.max_stroke_ms
        max_window = self.params.max_window
        rest_ms = self.params.rest_ms
        max_error_sq = self._max_error_sq
        rest_sq = self._rest_sq
        # _keeps_bound's first test, inlined for the common case (no bend rule): most samples
        # pass it, and a call per sample costs more than the test.
        reach_limit = self._reach_limit if self.params.max_bend <= 0.0 else -math.inf
        pending: list[tuple[Point, Sample]] = []  # a stack: the next sample to take is last
        while True:
            points, times, samples = self._points, self._times, self._samples
            t_ms = sample.t_ms
            if self._resting:
                if len(points) == 1 and _distance_sq(point, points[0]) <= self._rest_sq:
                    # The pen still rests: the next stroke starts when it moves on, not before.
                    self._retime(t_ms)
                    if not pending:
                        return
                    point, sample = pending.pop()
                    continue
                self._resting = False
            if cap_ms > 0 and len(points) > 1 and t_ms - times[0] > cap_ms:
                if not self._sendable(points[0], points[-1]):
                    # The pen crawls: too little drawn in max_stroke_ms to send. The stroke
                    # starts later rather than lasting longer, so the cap holds for it too.
                    self._retime(t_ms - cap_ms)
                    cut = -1
                else:
                    cut = self._cap_cut(points, times)
            else:
                cut = -1
            if cut >= 0:
                vertex = self._continued(points, cut)
                out.append(self._finish(points[0], times[0], vertex, times[cut]))
                self._line = self._line_of(points, cut, vertex)
                if cut < len(points) - 1:
                    pending.append((point, sample))
                    pending.extend(zip(points[:cut:-1], samples[:cut:-1], strict=True))
                    self._points, self._times, self._samples = (
                        [vertex],
                        [times[cut]],
                        [samples[cut]],
                    )
                    self._reach = 0.0
                    point, sample = pending.pop()
                    continue
                self._reach = 0.0
                self._points = points = [vertex]
                self._times = times = [times[cut]]
                self._samples = samples = [samples[cut]]
            if len(points) > 1:
                last = points[-1]
                dx, dy = point[0] - last[0], point[1] - last[1]
                reach = self._reach + math.sqrt(dx * dx + dy * dy) + ROUNDING_SLACK
                if reach <= reach_limit:
                    self._reach = reach
                    keeps = True
                else:
                    keeps = self._keeps_bound(points, point, max_error_sq)
            else:
                self._reach = 0.0
                keeps = True
            if not keeps:
                cut = self._feature(points, point)
                floor_end_ms = times[0] + self._floor_ms
                if times[cut] < floor_end_ms <= times[-1]:
                    # The piece would be briefer than the sleeve's floor, and the window holds
                    # a longer one: cut at the feature among the samples drawn at least the
                    # floor after the anchor (the last one always keeps the bound), so the
                    # sleeve need not slow the piece and the merger need not hold it.
                    cut = self._feature(
                        points, point, bisect.bisect_left(times, floor_end_ms, cut + 1)
                    )
                out.append(self._finish(points[0], times[0], points[cut], times[cut]))
                self._line = None
                pending.append((point, sample))
                pending.extend(zip(points[:cut:-1], samples[:cut:-1], strict=True))
                self._points, self._times, self._samples = (
                    [points[cut]],
                    [times[cut]],
                    [samples[cut]],
                )
                self._reach = 0.0
                point, sample = pending.pop()
                continue
            points.append(point)
            times.append(t_ms)
            samples.append(sample)
            reaches = self._reaches
            if len(reaches) < len(points):
                reaches.append(self._reach)
            else:
                reaches[len(points) - 1] = self._reach
            # A stroke younger than rest_ms cannot hold a rest, nor a pen that left the rest
            # radius since the sample before: most samples stop at these two tests.
            if (
                rest_ms > 0.0
                and t_ms - times[0] >= rest_ms
                and _distance_sq(points[-2], point) <= rest_sq
                and self._rests(points, times, point, sample, out)
            ):
                pass
            elif len(points) - 1 >= max_window:
                out.append(self._finish(points[0], times[0], point, t_ms))
                self._line = None
                self._points, self._times, self._samples = [point], [t_ms], [sample]
                self._reach = 0.0
            if not pending:
                return
            point, sample = pending.pop()

    def _retime(self, t_ms: float) -> None:
        """The anchor at another time (while the pen rests or crawls), its sample too."""
        self._times[0] = t_ms
        anchor = self._samples[0]
        # Built directly, not by dataclasses.replace: a crawling pen retimes at every sample.
        self._samples[0] = Sample(t_ms, anchor.x, anchor.y, anchor.pressure)

    def _rests(
        self,
        points: list[Point],
        times: list[float],
        point: Point,
        sample: Sample,
        out: list[Segment],
    ) -> bool:
        """Whether the pen has rested ``rest_ms`` at ``point``, the stroke's newest sample.

        It rests when its samples of the last ``rest_ms`` or more all lie within
        the rest radius of ``point``. The stroke drawn up to the rest then ends
        at ``point`` at the time the rest began, and is sent now; the rest is
        not played (the next stroke starts where and when the pen moves on).
        If the stroke is all rest, its anchor waits instead. Every sample of
        the rest lies within the rest radius (at most max_error / 2) of
        ``point``, and ``point`` within it of the anchor when all is rest.
        """
        rest_ms = self.params.rest_ms
        t_ms = times[-1]
        if rest_ms <= 0.0 or t_ms - times[0] < rest_ms:
            return False
        start = len(points) - 1
        rest_sq = self._rest_sq
        x, y = point
        while start > 0:  # _distance_sq(points[start - 1], point) <= rest_sq, inlined
            px, py = points[start - 1]
            dx, dy = px - x, py - y
            if not dx * dx + dy * dy <= rest_sq:  # (not ">": a NaN ends the rest too)
                break
            start -= 1
        if t_ms - times[start] < rest_ms:
            return False
        if start == 0:
            self._points, self._times, self._samples = [points[0]], [t_ms], [self._samples[0]]
            self._retime(t_ms)
        else:
            out.append(self._finish(points[0], times[0], point, times[start]))
            self._points, self._times, self._samples = [point], [t_ms], [sample]
        self._line = None
        self._reach = 0.0
        self._resting = True
        self.rested = True
        return True

    def _keeps_bound(self, points: list[Point], point: Point, max_error_sq: float) -> bool:
        """Whether every sample since the anchor lies within max_error of anchor -> ``point``.

        As ``_within`` finds; sets the reach for ``point`` as the stroke's new last sample. A
        NaN drawn is never farther than max_error (no comparison with NaN is true), in
        ``_within`` as here: a NaN step tests every sample, a NaN sample counts in no reach.
        """
        if len(points) == 1:
            self._reach = 0.0
            return True
        reach_limit = self._reach_limit
        bend = self.params.max_bend
        if bend > 0.0:
            # The bend rule: a round shape is cut before its chord strays farther than a share of
            # the chord's length, never under the floor, never over max_error.
            ax, ay = points[0]
            cx, cy = point[0] - ax, point[1] - ay
            limit = max(bend * math.sqrt(cx * cx + cy * cy), self.params.bend_floor)
            if limit < self.params.max_error:
                reach_limit = limit - ROUNDING_SLACK
                max_error_sq = limit * limit
        last = points[-1]
        dx, dy = point[0] - last[0], point[1] - last[1]
        reach = self._reach + math.sqrt(dx * dx + dy * dy) + ROUNDING_SLACK
        if reach <= reach_limit:
            self._reach = reach
            return True
        farthest_sq = _farthest_sq(points, len(points), point, max_error_sq)
        if farthest_sq < 0.0:
            return False
        self._reach = math.sqrt(farthest_sq) + ROUNDING_SLACK
        return True

    def _reaches_near(self, points: list[Point], index: int, end: Point, limit: float) -> bool:
        """Whether points[1:index + 1] surely lie within ``limit`` + slack of points[0] -> ``end``.

        ``end`` is a point near points[index]: moving the end moves the segment at most as far,
        so index's reach plus that step bounds them all; then a test of each finds them all
        within. False when unsure (a NaN too): test each.
        """
        if index == 0:
            return False
        dx, dy = end[0] - points[index][0], end[1] - points[index][1]
        return self._reaches[index] + math.sqrt(dx * dx + dy * dy) + ROUNDING_SLACK <= limit

    def _cap_cut(self, points: list[Point], times: list[float]) -> int:
        """Where the latency cap cuts: at a feature in the stroke's later part, else at its end.

        The feature is the sample farthest from the chord anchor -> last sample
        among those drawn at least ``CAP_FEATURE_SHARE`` x max_stroke_ms after the
        anchor whose own stroke keeps the bound and is long enough to send; if it
        lies on the chord (a straight stroke, to ``STRAIGHT``), at the last sample.
        """
        anchor = points[0]
        last = len(points) - 1
        earliest = times[0] + CAP_FEATURE_SHARE * self.params.max_stroke_ms
        first = next((i for i in range(1, last + 1) if times[i] >= earliest), last)
        cut = self._feature(points, points[last], first)
        straight = STRAIGHT * self.params.max_error
        far_sq = segment_distance_sq(points[cut], anchor, points[last])
        bends = far_sq > straight * straight
        return cut if bends and self._sendable(anchor, points[cut]) else last

    def _continued(self, points: list[Point], cut: int) -> Point:
        """Where a stroke that the latency cap or the release ends, ending at points[cut], ends.

        After a stroke the latency cap ended that is a line (``_line_of``), the
        stroke that follows it goes on along that line when it can: its end is
        points[cut] projected onto it, if that moves it at most ``LINE_SHARE`` x
        max_error, lies on the grid, every sample up to points[cut] keeps the
        bound to the projected end and the stroke is still long enough to send;
        else points[cut] itself (the end keeps the time of the sample at the cut).
        The cap cuts a drawn line, not a drawn corner, so a straight line cut
        into strokes stays one straight line (a sample's sideways noise would
        otherwise bend it).
        """
        at = points[cut]
        if self._line is None:
            return at
        ux, uy = self._line
        ax, ay = points[0]
        along = (at[0] - ax) * ux + (at[1] - ay) * uy
        if along <= 0:
            return at
        end = (ax + along * ux, ay + along * uy)
        # On the line but off the grid (a line drawn along an edge, its noise clamped onto the
        # edge): the sleeve refuses a stroke that ends off the grid, so keep the drawn sample,
        # which the mapping put on it. Not the projection clamped: that would bend the line.
        if not (0.0 <= end[0] <= self._x_extent and 0.0 <= end[1] <= self._y_extent):
            return at
        limit = LINE_SHARE * self.params.max_error
        if segment_distance_sq(at, end, end) > limit * limit:  # a bend, not noise
            return at
        if not self._sendable(points[0], end):
            return at
        if not self._reaches_near(points, cut, end, self._reach_limit) and not _within(
            points, cut + 1, end, self._max_error_sq
        ):
            return at
        return end

    def _line_of(self, points: list[Point], cut: int, end: Point) -> tuple[float, float] | None:
        """The direction of the stroke points[0] -> end if it is a line, else None.

        A line: every sample up to points[cut] lies within ``LINE_SHARE`` x max_error of it.
        """
        limit = LINE_SHARE * self.params.max_error
        certain = self._reaches_near(points, cut, end, limit - ROUNDING_SLACK)
        if not certain and not _within(points, cut + 1, end, limit * limit):
            return None
        return unit_direction(points[0], end)

    def _sendable(self, start: Point, end: Point) -> bool:
        """Whether start -> end is long enough to send (the cap never cuts off a dropped stroke)."""
        dx, dy = end[0] - start[0], end[1] - start[1]
        return dx * dx + dy * dy >= self._min_length_sq

    def _feature(self, points: list[Point], end: Point, first: int = 1) -> int:
        """Where to cut: the sample farthest from anchor -> end whose own stroke keeps the bound.

        The last sample always qualifies (the window kept the bound up to it).
        Ties go to the later sample, so the stroke is the longer.
        """
        anchor = points[0]
        stop = len(points)
        # (distance, index), farthest first and, at equal distance, the later sample first.
        ranked = sorted(
            zip(_distances_sq(points, first, stop, anchor, end), range(first, stop), strict=True),
            reverse=True,
        )
        max_error_sq, reaches, reach_limit = self._max_error_sq, self._reaches, self._reach_limit
        for _, index in ranked:
            if reaches[index] <= reach_limit or _within(points, index, points[index], max_error_sq):
                return index
        return stop - 1  # unreachable: the last sample fits by construction

    def _finish(self, start: Point, start_ms: float, end: Point, end_ms: float) -> Segment:
        self._emitted_in_path = True
        return finish_segment(
            start,
            end,
            start_ms,
            end_ms,
            self._pointer.t_ms if self._pointer else end_ms,
            min_length=self.params.min_length,
            min_duration_ms=self.params.min_duration_ms,
        )


@dataclass
class Merger:
    """Merges the pieces the window cuts too short to send into a neighbour, never dropping one.

    A piece is too short when it is shorter than ``min_length`` or briefer than the larger of
    ``min_duration_ms`` and ``floor_ms`` (the sleeve would slow it). A short piece is held back
    until the next piece arrives; the two become one stroke, from the first's start to the
    second's end, when every drawn sample of both lies within ``max_error`` of it (and that
    stroke, if still short, waits for the next in turn); else the short piece is sent as it is
    (the window keeps the bound for each piece). A piece long enough is sent at once: holding
    every stroke back until the next is known would delay the whole drawing (on people's
    gestures, about 40 ms more from release to felt end at p95; docs/research.md), so a short
    piece merges forward, not back, and the path's last piece, if short, is sent short, except
    that at release (``end``), when nothing comes after it, a last piece briefer than the floor
    merges into the stroke already sent before it where every drawn sample it has not covered
    lies within ``max_error`` of that stroke (nothing more is sent; ``merged_back`` counts
    them). Only a path's one and only piece, too short, is dropped with its reason (a tap:
    nothing to merge with). Every other drawn sample lies within ``max_error`` of a sent stroke.
    With ``strict`` (a wearer's minimums), a piece below them merges into the next whatever the
    bound, but never across a rest (``rest``), and one left at release or at a rest merges back
    where the bound allows, else is dropped with its reason.
    """

    max_error: float
    min_length: float
    min_duration_ms: float
    floor_ms: float
    strict: bool = False
    # Whether a piece too short or too brief waits to merge (the window's pieces). The least
    # squares' pieces do not once the path has sent one (a path's first piece still waits, so
    # that a tap is dropped), unless strict: they are briefer than the floor only where no piece
    # lasting it keeps the bound, and one that lasts the floor yet is shorter than min_length was
    # drawn by a nearly still pen; each is sent as it is, a brief one to last the floor (holding
    # them made the felt end later and lost shapes drawn fast: docs/research.md).
    hold_short: bool = True
    # With hold_short off (the least squares' pieces): no merge makes a stroke outlast this (the
    # latency cap, ms; 0: no limit). The window's own merges keep it by their pieces.
    cap_ms: float = 0.0
    # The drawn samples not yet covered by a sent stroke (grid units, ms), oldest first.
    _points: list[Point] = field(default_factory=list)
    _times: list[float] = field(default_factory=list)
    _held: Segment | None = None
    _sent_in_path: bool = False
    # The path's last sent stroke, its start and end (None before its first): a piece briefer
    # than the sleeve's floor left at release merges into it when every drawn sample it has not
    # covered lies within max_error of it (``end``).
    _last_start: Point | None = None
    _last_end: Point = (0.0, 0.0)
    # Pieces merged at release (or, strict, at a rest) into a stroke already sent (nothing more
    # is sent for them), in all.
    merged_back: int = 0

    def sample(self, t_ms: float, point: Point) -> None:
        """A drawn sample, in order (its time as the window took it)."""
        self._points.append(point)
        self._times.append(t_ms)

    def _short(self, segment: Segment) -> bool:
        return (self.hold_short or not self._sent_in_path) and (
            segment.length < self.min_length
            or segment.drawn_ms < max(self.min_duration_ms, self.floor_ms)
        )

    def _below_minimums(self, segment: Segment) -> bool:
        return segment.length < self.min_length or segment.drawn_ms < self.min_duration_ms

    def _fits(self, start: Point, end: Point, end_ms: float) -> bool:
        """Whether every sample not yet covered, drawn up to end_ms, lies within max_error of it.

        All of them, not only those after the held piece's start: a stroke whose pen crawled or
        rested starts after samples it covers."""
        limit_sq = self.max_error * self.max_error
        for point, t_ms in zip(self._points, self._times, strict=True):
            if t_ms > end_ms:
                break
            if segment_distance_sq(point, start, end) > limit_sq:
                return False
        return True

    def _paced(self, segment: Segment) -> float | None:
        """How long the sleeve is to play ``segment``: None (as drawn), or the floor for a piece
        briefer than it that could not merge. The sleeve would slow such a piece to its floor;
        sent lasting the floor, it is played the same, and the sleeve has nothing to adjust
        (the strokes after it catch up with their drawing as before: docs/protocol.md)."""
        floor_ms = max(self.min_duration_ms, self.floor_ms)
        return floor_ms if segment.end_ms - segment.start_ms < floor_ms else None

    def _send(self, segment: Segment, now_ms: float, out: list[Segment]) -> None:
        self._sent_in_path = True
        self._last_start, self._last_end = segment.start, segment.end
        # Built directly, not by dataclasses.replace (several times slower): one per stroke.
        out.append(
            Segment(
                segment.start,
                segment.end,
                segment.start_ms,
                segment.end_ms,
                now_ms,
                None,
                segment.merged,
                self._paced(segment),
            )
        )
        # The samples before its end are covered now (those at its end may start the next).
        keep = bisect.bisect_left(self._times, segment.end_ms)
        del self._points[:keep]
        del self._times[:keep]

    def take(self, piece: Segment, now_ms: float) -> list[Segment]:
        """A piece the window cut: the strokes sent now (none while a short one waits)."""
        out: list[Segment] = []
        held = self._held
        if held is not None:
            self._held = None
            within_cap = (
                self.hold_short or self.cap_ms <= 0.0 or piece.end_ms - held.start_ms <= self.cap_ms
            )
            if (within_cap and self._fits(held.start, piece.end, piece.end_ms)) or (
                self.strict and self._below_minimums(held)
            ):
                piece = Segment(
                    held.start,
                    piece.end,
                    held.start_ms,
                    piece.end_ms,
                    now_ms,
                    merged=held.merged + piece.merged + 1,
                )
            else:
                self._send(held, now_ms, out)
        if self._short(piece):
            self._held = piece
        else:
            self._send(piece, now_ms, out)
        return out

    def rest(self, now_ms: float) -> list[Segment]:
        """The pen rests (since the held piece's end, until ``now_ms``): the held piece is let go
        now rather than merged with what comes after the rest, which would play the rest.

        If it is briefer than the sleeve's floor, it takes the time it needs from the rest: the
        pen was at its end then (``floor_end_ms``), and it is sent. With strict minimums, a
        piece still below them is not sent: as at release, it merges into the path's last sent
        stroke where that keeps the bound (``_merges_back``), else it is dropped with its
        reason."""
        held = self._held
        if held is None:
            return []
        short_ms = max(self.min_duration_ms, self.floor_ms)
        if held.drawn_ms < short_ms and now_ms > held.end_ms:
            held = replace(held, end_ms=min(floor_end_ms(held.start_ms, short_ms), now_ms))
        self._held = None
        out: list[Segment] = []
        if self.strict and self._below_minimums(held):
            if self._merges_back(held):
                self.merged_back += held.merged + 1
            else:
                out.append(replace(held, emitted_at_ms=now_ms, dropped=self._reason(held)))
            # Its samples are let go with it (those at its end may start the next).
            keep = bisect.bisect_left(self._times, held.end_ms)
            del self._points[:keep]
            del self._times[:keep]
            return out
        self._send(held, now_ms, out)
        return out

    def _reason(self, segment: Segment) -> str | None:
        """Why ``segment`` is too short to send (None if it is not)."""
        if segment.length < self.min_length:
            return NOT_ENOUGH_DISTANCE
        if segment.drawn_ms < self.min_duration_ms:
            return NOT_ENOUGH_DURATION
        return None

    def _merges_back(self, held: Segment) -> bool:
        """Whether the piece held at release merges into the path's last sent stroke.

        It does when it is briefer than the sleeve's floor (the sleeve would slow it; or, with
        strict minimums, shorter than min_length: it would be dropped) and every drawn sample
        not yet covered, its own and any after it, lies within max_error of that stroke. The
        stroke was sent and is not held back: nothing more is sent, the bound holds for every
        sample and the path's felt end is earlier.
        """
        if self._last_start is None:
            return False
        brief = held.drawn_ms < max(self.min_duration_ms, self.floor_ms)
        if not brief and not (self.strict and held.length < self.min_length):
            return False
        return self._fits(self._last_start, self._last_end, math.inf)

    def end(self, now_ms: float) -> list[Segment]:
        """Release, after the window's last piece: the held piece merges into the path's last
        sent stroke where that keeps the bound (``_merges_back``: nothing more is sent), else it
        is sent (or, if it is the path's only piece and too short to send, dropped with its
        reason)."""
        out: list[Segment] = []
        held = self._held
        if held is not None and self._merges_back(held):
            self.merged_back += held.merged + 1
            held = None
        if held is not None:
            reason = self._reason(held) if not self._sent_in_path or self.strict else None
            if reason is not None:
                out.append(replace(held, emitted_at_ms=now_ms, dropped=reason))
            else:
                self._send(held, now_ms, out)
        self._held = None
        self._sent_in_path = False
        self._last_start = None
        self._points, self._times = [], []
        return out


@dataclass
class WindowSimplifier:
    """The window simplifier: the window's pieces, the too-short ones merged (``Merger``)."""

    params: WindowParams = field(default_factory=WindowParams)
    _core: WindowCore | FitCore = field(init=False)
    _merger: Merger = field(init=False)
    # The last sample pushed in the path being drawn (None between paths).
    _last: Sample | None = field(init=False, default=None)
    _rest_ms: float = field(init=False)

    def __post_init__(self) -> None:
        params = self.params
        self._rest_ms = params.rest_ms
        self._core = FitCore(params) if params.least_squares else WindowCore(params)
        self._merger = Merger(
            params.max_error,
            params.min_length,
            params.min_duration_ms,
            params.floor_ms,
            params.strict_minimums,
            hold_short=not params.least_squares or params.strict_minimums,
            cap_ms=params.max_stroke_ms,
        )

    @property
    def drawing(self) -> bool:
        """True between the first sample of a path and ``end``."""
        return self._core.drawing

    @property
    def line_start(self) -> Sample | None:
        """Where the stroke being drawn starts (canvas pixels); None between paths."""
        return self._core.line_start

    def push(self, sample: Sample) -> list[Segment]:
        """One pointer sample while the pointer is down; the first of a path is the press.

        A sample ``rest_ms`` or more after the one before (with the rest rule on) comes after a
        stop: a pointer held still sends no event, and a source that does not sample it where
        it is (the page does, every 32 ms) leaves a gap. The pen is taken to have stood at the
        sample before until this one, as if sampled there at this one's time: the rest rule
        sees the rest, and the stop is not played as a stroke as long as the stop."""
        core = self._core
        last = self._last
        self._last = sample
        # ``after_stop`` written out (it runs at every sample), from the last time taken
        # (``core.pointer_ms()``: times never run backwards).
        if last is not None and 0.0 < self._rest_ms <= sample.t_ms - core._taken[0]:
            self._last = None
            return self.push(still_before(last, sample)) + self.push(sample)
        pieces = core.push(sample)
        merger = self._merger
        taken, point = core._taken  # core.last_sample() and merger.sample, inlined: per sample
        merger._points.append(point)
        merger._times.append(taken)
        if not pieces and not core.rested:
            return []
        out: list[Segment] = []
        for piece in pieces:
            out.extend(merger.take(piece, taken))
        if core.rested:
            out.extend(merger.rest(taken))
        return out

    @property
    def merged_back(self) -> int:
        """Pieces merged at release (or, strict, at a rest) into a stroke already sent
        (``Merger.end``, ``Merger.rest``: nothing more was sent for them), over every path so
        far."""
        return self._merger.merged_back

    def end(self) -> list[Segment]:
        """Release: the rest of the path, the held piece first (a tap gives one, dropped)."""
        core = self._core
        self._last = None
        now_ms = core.pointer_ms()
        out: list[Segment] = []
        for piece in core.end():
            out.extend(self._merger.take(piece, now_ms))
        out.extend(self._merger.end(now_ms))
        return out


def after_stop(gap_ms: float, rest_ms: float) -> bool:
    """Whether a sample ``gap_ms`` after the last time taken comes after a stop: ``rest_ms``
    or more, with the rest rule on (``WindowSimplifier.push``, which writes this test out)."""
    return 0.0 < rest_ms <= gap_ms


def still_before(last: Sample, sample: Sample) -> Sample:
    """The pen standing at ``last`` at ``sample``'s time: what a stop before ``sample`` gives
    (``after_stop``)."""
    return Sample(sample.t_ms, last.x, last.y, last.pressure)


def taken_samples(samples: list[Sample], rest_ms: float) -> list[Sample]:
    """The samples ``WindowSimplifier`` takes for one path's ``samples``: each, after the pen
    standing at the one before where a stop left a gap (``after_stop``). What its strokes
    cover, for tests and tools that check them against the samples."""
    taken: list[Sample] = []
    taken_ms = -math.inf
    for sample in samples:
        if taken and after_stop(sample.t_ms - taken_ms, rest_ms):
            taken.append(still_before(taken[-1], sample))
        taken.append(sample)
        taken_ms = max(taken_ms, sample.t_ms)
    return taken


def floor_end_ms(start_ms: float, floor_ms: float) -> float:
    """The earliest end a piece starting at ``start_ms`` lasts ``floor_ms`` to: ``start_ms +
    floor_ms``, or the double above it where that sum rounds down (15000.1 + 73.701 - 15000.1 is
    73.70099999999911, which the sleeve would slow to 73.701 and report ``adjusted``)."""
    end_ms = start_ms + floor_ms
    while end_ms - start_ms < floor_ms:
        end_ms = math.nextafter(end_ms, math.inf)
    return end_ms


def rest_radius(params: WindowParams) -> float:
    """How near one point a resting pen stays, in grid units: the least of ``REST_SHARE`` x
    min_length, half of max_error and the distance a pen at ``REST_SPEED_PX_PER_MS`` covers in
    rest_ms, mapped at the canvas's tighter scale (so no more pixels on either axis)."""
    px = REST_SPEED_PX_PER_MS * params.rest_ms
    return min(REST_SHARE * params.min_length, 0.5 * params.max_error, px * params.mapping.scale)


def _distance_sq(a: Point, b: Point) -> float:
    dx, dy = a[0] - b[0], a[1] - b[1]
    return dx * dx + dy * dy


def unit_direction(start: Point, end: Point) -> tuple[float, float] | None:
    """The unit vector from ``start`` to ``end`` (None if they coincide)."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    length = math.sqrt(dx * dx + dy * dy)
    return (dx / length, dy / length) if length > 0.0 else None


# The squared distance from a point to a segment start -> end (its nearest point), as
# ``segment_distance_sq`` computes it, is the inner loop of the simplifier: ``_farthest_sq`` and
# ``_distances_sq`` inline it over a stroke's samples, with the chord's terms computed once. The
# float operations are ``segment_distance_sq``'s, in its order, so every result is the same to
# the last bit: max(t, 0.0) and min(t, 1.0) are written as the comparisons Python's max and min
# make (a NaN stays NaN), t <= 0 leaves q as it is (q - 0 * d is q; a zero's sign is squared
# away) and t == 1 subtracts d itself (1.0 * d is d).


def _within(points: list[Point], stop: int, end: Point, limit_sq: float) -> bool:
    """Whether points[1:stop] all lie within sqrt(limit_sq) of the segment points[0] -> end."""
    return _farthest_sq(points, stop, end, limit_sq) >= 0.0


def _farthest_sq(points: list[Point], stop: int, end: Point, limit_sq: float) -> float:
    """The greatest squared distance of points[1:stop] to points[0] -> end, or -1 past limit_sq.

    0.0 when there are none; a NaN distance counts as none. Stops at the first past the limit.
    """
    ax, ay = points[0]
    dx, dy = end[0] - ax, end[1] - ay
    length_sq = dx * dx + dy * dy
    farthest = 0.0
    if length_sq > 0.0:
        for px, py in points[1:stop]:
            qx, qy = px - ax, py - ay
            t = (qx * dx + qy * dy) / length_sq
            if t <= 0.0:
                distance_sq = qx * qx + qy * qy
            elif t >= 1.0:
                qx, qy = qx - dx, qy - dy
                distance_sq = qx * qx + qy * qy
            else:
                qx, qy = qx - t * dx, qy - t * dy
                distance_sq = qx * qx + qy * qy
            if distance_sq > limit_sq:
                return -1.0
            if distance_sq > farthest:
                farthest = distance_sq
    else:
        for px, py in points[1:stop]:
            qx, qy = px - ax, py - ay
            distance_sq = qx * qx + qy * qy
            if distance_sq > limit_sq:
                return -1.0
            if distance_sq > farthest:
                farthest = distance_sq
    return farthest


def _distances_sq(
    points: list[Point], first: int, stop: int, start: Point, end: Point
) -> list[float]:
    """``segment_distance_sq`` of points[first:stop] to the segment start -> end."""
    ax, ay = start
    dx, dy = end[0] - ax, end[1] - ay
    length_sq = dx * dx + dy * dy
    out = []
    if length_sq > 0.0:
        for px, py in points[first:stop]:
            qx, qy = px - ax, py - ay
            t = (qx * dx + qy * dy) / length_sq
            if t <= 0.0:
                pass
            elif t >= 1.0:
                qx, qy = qx - dx, qy - dy
            else:
                qx, qy = qx - t * dx, qy - t * dy
            out.append(qx * qx + qy * qy)
    else:
        for px, py in points[first:stop]:
            qx, qy = px - ax, py - ay
            out.append(qx * qx + qy * qy)
    return out


def segment_distance_sq(point: Point, start: Point, end: Point) -> float:
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
