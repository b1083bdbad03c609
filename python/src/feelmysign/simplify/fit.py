"""Least-squares placement at the sleeve's floor: the window simplifier's core with
``least_squares`` on.

The window (``window.WindowCore``) grows a stroke until a sample breaks the error bound, then
cuts at the sample farthest from the chord. This core places the strokes' ends where the drawn
samples lie nearest them instead: at each sample it keeps, over the samples since the last
stroke it let go (the anchor), the polyline through drawn samples with the least integral square
error (the sum of each sample's squared distance to the line of its stroke) among those whose
strokes all keep every sample within ``max_error`` (distance to the segment) and last at least
the sleeve's floor (``floor_ms``, or ``min_duration_ms`` if longer); where no stroke lasting the
floor keeps the bound, the fewest briefer ones (each sent to last the floor). It is the dynamic
program of Perez and Vidal ("Optimum polygonal approximation of digitized curves", Pattern
Recognition Letters 15, 1994) with the floor and the bound as constraints on each piece instead
of a count of pieces, solved one sample at a time: each sample's best polyline from the anchor
is found once, from those of the samples before it, and each piece's error comes from running
sums in O(1). The last stroke of the polyline to the newest sample may be briefer than the floor
(the path goes on). No stroke lasts longer than the latency cap (``max_stroke_ms``), but one
between two samples drawn further apart than it.

A stroke is let go, its first vertex after the anchor final, once the pen has drawn
``lookahead_ms`` past that vertex, or once that stroke lasts more than ``max_stroke_ms`` (the
latency cap). With no vertex yet and the stroke from the anchor longer than the cap, the stroke
to the sample before is let go as one (a line the cap cuts). At release the polyline to the last
sample is let go whole, every stroke at the floor. The samples after a stroke let go are taken
again from its end. So each stroke but the last waits ``lookahead_ms`` for what is drawn after
it, and no stroke lasts the floor only because the bound broke.

Measured on people's gestures and LASA (docs/research.md, "What the floor leaves of
recognition"), this keeps the drawings' shape better than the chord's farthest sample at the
same error bound: its vertices sit where the drawing turns, found over several strokes at once.

Kept from the window: the mapping, times that never run backwards, the rest rule (a pen resting
``rest_ms`` lets the polyline to the rest's start go; the rest is not played) and the work cap
(no piece holds more than ``max_window`` samples after its start). Not taken: the chord's reach,
the bend rule, the crawling pen's later start and the line a cap cut goes on along (the least
squares place a line's vertices on it). The float operations are written out, in this order, in
the TypeScript and Java ports, which reproduce the shared vectors exactly.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from feelmysign.simplify.distance import ROUNDING_SLACK, segment_distance_sq
from feelmysign.simplify.segment import Sample, Segment, finish_segment
from feelmysign.stroke import Point

if TYPE_CHECKING:
    from feelmysign.simplify.window import WindowParams

# The running sums at a sample: of x, y, x^2, y^2 and xy over the samples before it, each
# relative to the anchor.
Sums = tuple[float, float, float, float, float]


@dataclass
class FitCore:
    """The least-squares core: the pieces to merge (``WindowSimplifier`` merges them), as
    ``WindowCore`` gives its own."""

    params: WindowParams
    # The samples since the anchor, the anchor first: grid points, times, samples.
    _xs: list[float] = field(default_factory=list)
    _ys: list[float] = field(default_factory=list)
    _ts: list[float] = field(default_factory=list)
    _samples: list[Sample] = field(default_factory=list)
    # Running sums of x, y, x^2, y^2 and xy over the samples, relative to the anchor's point.
    _sums: list[Sums] = field(default_factory=lambda: [(0.0, 0.0, 0.0, 0.0, 0.0)])
    # Each sample's best polyline from the anchor (every piece at the floor, where the bound lets
    # it be): its squared error, its count of pieces briefer than the floor and its last vertex.
    _best: list[float] = field(default_factory=list)
    _brief: list[int] = field(default_factory=list)
    _before: list[int] = field(default_factory=list)
    # A piece's error per start, for the sample being placed (reused; -1: left out by ``_scan``).
    _errors: list[float] = field(default_factory=list)
    _errors_end: int = -1
    # For that sample: its first start (``_errors[0]`` is the piece from it) and the best start
    # of an open last piece before its bound is tested (``_choose``'s first choice).
    _errors_low: int = 0
    _open_first: int = -1
    # Per sample, the end of the last piece from it found to keep the bound (-1: none) and that
    # piece's reach: no sample between lies farther from it, rounding allowed for (``_keeps``).
    _reach_end: list[int] = field(default_factory=list)
    _reach_of: list[float] = field(default_factory=list)
    # Per sample, the sample that last broke the bound of a piece from it (-1: none yet): tested
    # first, as it often breaks the next piece from there too.
    _broke: list[int] = field(default_factory=list)
    # How many sample distances the bound's tests have taken, in all (what a sample costs).
    distance_tests: int = 0
    _pointer: Sample | None = None
    _emitted_in_path: bool = False
    # While the pen rests (``rest_ms``): the point it rests at; each sample near it retimes the
    # anchor, none is taken.
    _resting: bool = False
    _rest_x: float = 0.0
    _rest_y: float = 0.0
    rested: bool = False
    _taken: tuple[float, Point] = (0.0, (0.0, 0.0))

    def __post_init__(self) -> None:
        from feelmysign.simplify.window import rest_radius

        params = self.params
        self._max_error_sq = params.max_error * params.max_error
        self._reach_limit = params.max_error - ROUNDING_SLACK
        self._floor_ms = max(params.floor_ms, params.min_duration_ms)
        self._max_window = params.max_window
        self._cap_ms = params.max_stroke_ms
        rest = rest_radius(params)
        self._rest_sq = rest * rest
        self._mapping = params.mapping

    @property
    def drawing(self) -> bool:
        return bool(self._xs)

    @property
    def line_start(self) -> Sample | None:
        return self._samples[0] if self._samples else None

    def last_sample(self) -> tuple[float, Point]:
        return self._taken

    def pointer_ms(self) -> float:
        return self._pointer.t_ms if self._pointer else 0.0

    def push(self, sample: Sample) -> list[Segment]:
        """One pointer sample while the pointer is down; the first of a path is the press."""
        ts = self._ts
        if ts and sample.t_ms < ts[-1]:
            sample = Sample(ts[-1], sample.x, sample.y, sample.pressure)
        self._pointer = sample
        x, y = point = self._mapping.to_grid(sample.x, sample.y)
        self._taken = (sample.t_ms, point)
        self.rested = False
        t = sample.t_ms
        if not ts:
            self._emitted_in_path = False
            self._resting = False
            self._restart_at([x], [y], [t], [sample])
            return []
        if self._resting:
            dx = x - self._rest_x
            dy = y - self._rest_y
            if len(ts) == 1 and dx * dx + dy * dy <= self._rest_sq:
                self._retime(t)
                return []
            self._resting = False
        out: list[Segment] = []
        self._append(x, y, t, sample)
        if self._rests(out):
            return out
        self._let_go(out)
        return out

    def end(self) -> list[Segment]:
        """Release: the best polyline to the last sample, every stroke at the floor (a tap gives
        one stroke, dropped, of length 0)."""
        out: list[Segment] = []
        count = len(self._xs)
        self._resting = False
        if count == 0:
            return out
        if count == 1:
            if not self._emitted_in_path:
                out.append(self._piece(0, 0))
        else:
            self._polyline(count - 1, out)
        self._xs, self._ys, self._ts, self._samples = [], [], [], []
        return out

    # --- the polyline -------------------------------------------------------------------------

    def _restart_at(
        self,
        xs: list[float],
        ys: list[float],
        ts: list[float],
        samples: list[Sample],
        held: tuple[list[int], list[int], list[float]] | None = None,
    ) -> None:
        """The samples since a new anchor (xs[0]): running sums and best polylines again.
        ``held``: what ``_keeps`` found of the pieces between them (``_broke``, ``_reach_end``,
        ``_reach_of``), as indices from the anchor."""
        self._xs, self._ys, self._ts, self._samples = xs, ys, ts, samples
        if held is None:
            held = ([-1] * len(xs), [-1] * len(xs), [0.0] * len(xs))
        self._broke, self._reach_end, self._reach_of = held
        self._sums = [(0.0, 0.0, 0.0, 0.0, 0.0)]
        self._best, self._brief, self._before = [0.0], [0], [-1]
        self._errors_end = -1
        ax, ay = xs[0], ys[0]
        self._add_sums(0.0, 0.0)
        for k in range(1, len(xs)):
            self._add_sums(xs[k] - ax, ys[k] - ay)
            self._place(k)

    def _add_sums(self, rx: float, ry: float) -> None:
        sums = self._sums
        sx, sy, sxx, syy, sxy = sums[-1]
        sums.append((sx + rx, sy + ry, sxx + rx * rx, syy + ry * ry, sxy + rx * ry))

    def _append(self, x: float, y: float, t: float, sample: Sample) -> None:
        self._xs.append(x)
        self._ys.append(y)
        self._ts.append(t)
        self._samples.append(sample)
        self._broke.append(-1)
        self._reach_end.append(-1)
        self._reach_of.append(0.0)
        # ``_add_sums``, written out.
        rx = x - self._xs[0]
        ry = y - self._ys[0]
        sums = self._sums
        sx, sy, sxx, syy, sxy = sums[-1]
        sums.append((sx + rx, sy + ry, sxx + rx * rx, syy + ry * ry, sxy + rx * ry))
        self._place(len(self._xs) - 1)

    def _scan(self, k: int) -> tuple[int, int]:
        """Each piece's error to sample k, from every start it may have (into ``_errors``; -1
        for a start that cannot be a first choice), and the first choice of ``_choose`` for
        its last piece closed and open, in one pass (kept for the sample until the next): the
        first start and the closed first choice."""
        low = k - self._max_window
        if low < 0:
            low = 0
        ts = self._ts
        t_k = ts[k]
        # No piece outlasts the latency cap, but one between two samples drawn further apart.
        cap_ms = self._cap_ms
        if cap_ms > 0.0:
            while low < k - 1 and t_k - ts[low] > cap_ms:
                low += 1
        xs, ys = self._xs, self._ys
        ax, ay = xs[0], ys[0]
        errors = self._errors
        errors.clear()
        append = errors.append
        best, brief = self._best, self._brief
        floor_ms = self._floor_ms
        # ``piece_error`` for every start, written out with the end's terms taken once (the
        # same operations in the same order: each start's error to the last bit).
        sums = self._sums
        ex = xs[k] - ax
        ey = ys[k] - ay
        sx_end, sy_end, sxx_end, syy_end, sxy_end = sums[k + 1]
        # The first choices: the fewest pieces briefer than the floor, then the least squared
        # error, then the earliest start (the last piece counted only when closed).
        closed_start = open_start = -1
        closed_count = open_count = 0
        closed_total = open_total = 0.0
        count = float(k + 1 - low)  # the piece's samples, k + 1 - i: whole numbers, exact
        for i in range(low, k):
            pieces = brief[i]
            closed_pieces = pieces + 1 if t_k - ts[i] < floor_ms else pieces
            if open_start >= 0 and pieces > open_count and closed_pieces > closed_count:
                # More pieces briefer than the floor than both first choices so far: this
                # start can be neither, whatever its error, which is left out (-1: no error
                # is below 0) and computed only if a first choice breaks the bound (``_choose``).
                append(-1.0)
                count -= 1.0
                continue
            px = xs[i] - ax
            py = ys[i] - ay
            dx = ex - px
            dy = ey - py
            sx_i, sy_i, sxx_i, syy_i, sxy_i = sums[i]
            sx = sx_end - sx_i
            sy = sy_end - sy_i
            cxx = sxx_end - sxx_i - 2.0 * px * sx + count * px * px
            cyy = syy_end - syy_i - 2.0 * py * sy + count * py * py
            cxy = sxy_end - sxy_i - px * sy - py * sx + count * px * py
            count -= 1.0
            length_sq = dx * dx + dy * dy
            if length_sq > 0.0:
                error = (dx * dx * cyy + dy * dy * cxx - 2.0 * dx * dy * cxy) / length_sq
            else:
                error = cxx + cyy
            if not error > 0.0:
                error = 0.0
            append(error)
            total = best[i] + error
            if (
                open_start < 0
                or pieces < open_count
                or (pieces == open_count and total < open_total)
            ):
                open_start, open_count, open_total = i, pieces, total
            if (
                closed_start < 0
                or closed_pieces < closed_count
                or (closed_pieces == closed_count and total < closed_total)
            ):
                closed_start, closed_count, closed_total = i, closed_pieces, total
        self._errors_end = k
        self._errors_low = low
        self._open_first = open_start
        return low, closed_start

    def _choose(self, k: int, low: int, closed: bool, chosen: int) -> int:
        """The best start of the last piece to sample k: the fewest pieces briefer than the
        floor (the last counted only when ``closed``), then the least squared error, then the
        earliest start; among the pieces that keep the bound (the piece from k - 1 always
        does). ``chosen`` is the first choice (``_scan``'s), whose bound the caller found broken.

        The other starts are tested in the same order, from a heap of
        (count, error, start) built once: the totals are never NaN (``piece_error`` gives none,
        and sums of numbers at or above 0 give none), so that order is the pass's own and each
        sample costs O(max_window log max_window) choices, not a pass per start rejected."""
        best, brief, errors, ts = self._best, self._brief, self._errors, self._ts
        floor_ms = self._floor_ms
        t_k = ts[k]
        xs, ys = self._xs, self._ys
        for i in range(low, k):
            if errors[i - low] < 0.0:  # left out by ``_scan``: its start could not be first
                errors[i - low] = piece_error(xs, ys, xs[0], ys[0], self._sums, i, k)
        heap = [
            (
                brief[i] + (1 if closed and t_k - ts[i] < floor_ms else 0),
                best[i] + errors[i - low],
                i,
            )
            for i in range(low, k)
            if i != chosen
        ]
        heapq.heapify(heap)
        while True:
            chosen = heapq.heappop(heap)[2]
            if chosen == k - 1 or self._keeps(chosen, k):
                return chosen

    def _place(self, k: int) -> None:
        """Sample k's best polyline from the anchor, every piece closed (at the floor)."""
        low, i = self._scan(k)
        if i != k - 1 and not self._keeps(i, k):
            i = self._choose(k, low, True, i)
        ts = self._ts
        self._best.append(self._best[i] + self._errors[i - low])
        self._brief.append(self._brief[i] + (1 if ts[k] - ts[i] < self._floor_ms else 0))
        self._before.append(i)

    def _keeps(self, start: int, end: int) -> bool:
        """Whether every sample between xs[start] and xs[end] lies within max_error of the
        segment between them. The answer is the same in any order of tests, so a rejected
        start is made to cost few: the sample that broke the last piece tested from ``start``
        is tested first, then the samples coarse to fine (the middle, the quarters, the
        eighths, ...: a bulge the piece cuts off is met early).

        Where the piece from ``start`` to the sample before ``end`` kept the bound, its reach
        plus how far the sample before ``end`` lies from the piece to ``end`` bounds every
        distance to it (the distance to a segment is convex along the old piece, 0 at its
        start): under ``max_error`` by ``ROUNDING_SLACK``, the piece keeps the bound, as
        testing each sample would find, without testing each."""
        reach_end = self._reach_end[start]
        if reach_end == end:
            return True  # (found a moment ago: the closed and the open choice share pieces)
        xs, ys = self._xs, self._ys
        ax, ay = xs[start], ys[start]
        limit_sq = self._max_error_sq
        ex, ey = xs[end], ys[end]
        if reach_end == end - 1:
            self.distance_tests += 1
            step_sq = segment_distance_sq(xs[end - 1], ys[end - 1], ax, ay, ex, ey)
            reach = self._reach_of[start] + math.sqrt(step_sq) + ROUNDING_SLACK
            if reach <= self._reach_limit:
                self._reach_of[start] = reach
                self._reach_end[start] = end
                return True
        m = self._broke[start]
        if start < m < end:
            self.distance_tests += 1
            if segment_distance_sq(xs[m], ys[m], ax, ay, ex, ey) > limit_sq:
                return False
        # ``segment_distance_sq`` written out, the segment's terms taken once.
        dx = ex - ax
        dy = ey - ay
        length_sq = dx * dx + dy * dy
        farthest = 0.0  # (a NaN counts as none: it breaks no bound)
        span = end - start
        step = 1
        while step * 2 < span:
            step *= 2
        while step > 0:
            for m in range(start + step, end, 2 * step):
                qx = xs[m] - ax
                qy = ys[m] - ay
                if length_sq > 0.0:
                    t = (qx * dx + qy * dy) / length_sq
                    if t >= 1.0:
                        qx = qx - dx
                        qy = qy - dy
                    elif not t <= 0.0:
                        qx = qx - t * dx
                        qy = qy - t * dy
                distance_sq = qx * qx + qy * qy
                if distance_sq > limit_sq:
                    self._broke[start] = m
                    self.distance_tests += (m - start - step) // (2 * step) + 1
                    return False
                if distance_sq > farthest:
                    farthest = distance_sq
            self.distance_tests += len(range(start + step, end, 2 * step))
            step //= 2
        self._reach_of[start] = math.sqrt(farthest) + ROUNDING_SLACK
        self._reach_end[start] = end
        return True

    def _polyline(self, last: int, out: list[Segment]) -> None:
        """Lets go the best polyline (every piece closed) to sample ``last``."""
        vertices = [last]
        while vertices[-1] != 0:
            vertices.append(self._before[vertices[-1]])
        vertices.reverse()
        for a, b in itertools.pairwise(vertices):
            out.append(self._piece(a, b))

    def _piece(self, a: int, b: int) -> Segment:
        self._emitted_in_path = True
        xs, ys, ts = self._xs, self._ys, self._ts
        return finish_segment(
            (xs[a], ys[a]),
            (xs[b], ys[b]),
            ts[a],
            ts[b],
            self._pointer.t_ms if self._pointer else ts[b],
            min_length=self.params.min_length,
            min_duration_ms=self.params.min_duration_ms,
        )

    def _from(self, k: int) -> None:
        """Sample k anchors the next stroke; the samples after it are taken again."""
        held = (
            [m - k if m > k else -1 for m in self._broke[k:]],
            [end - k if end > k else -1 for end in self._reach_end[k:]],
            self._reach_of[k:],
        )
        self._restart_at(self._xs[k:], self._ys[k:], self._ts[k:], self._samples[k:], held)

    def _let_go(self, out: list[Segment]) -> None:
        """Lets go each stroke that is final: its end drawn ``lookahead_ms`` ago, or the stroke
        longer than the latency cap."""
        cap_ms = self.params.max_stroke_ms
        lookahead_ms = self.params.lookahead_ms
        floor_ms = self._floor_ms
        while True:
            ts = self._ts
            j = len(ts) - 1
            still = self._still_from(j)
            if ts[j] - ts[0] < floor_ms or still == 0:
                return
            if self._errors_end != j:
                self._scan(j)
            last = self._open_first
            if last != j - 1 and not self._keeps(last, j):
                last = self._choose(j, self._errors_low, False, last)
            if last == 0:
                # One stroke from the anchor: cut by the latency cap at the sample before.
                if (
                    cap_ms > 0.0
                    and ts[j] - ts[0] > cap_ms
                    and j >= 2
                    and ts[j - 1] - ts[0] >= floor_ms
                    and j - 1 <= still
                    and self._keeps(0, j - 1)
                ):
                    out.append(self._piece(0, j - 1))
                    self._from(j - 1)
                    continue
                return
            vertex = last
            while self._before[vertex] != 0:
                vertex = self._before[vertex]
            if vertex > still or (
                ts[j] - ts[vertex] < lookahead_ms
                and not (cap_ms > 0.0 and ts[vertex] - ts[0] > cap_ms)
            ):
                return
            out.append(self._piece(0, vertex))
            self._from(vertex)

    # --- rests --------------------------------------------------------------------------------

    def _still_from(self, j: int) -> int:
        """Where the pen may have been resting since: the first of the samples up to j that all
        lie within the rest radius of sample j (with ``rest_ms`` on; j + 1 without).

        No stroke is let go that ends after it: its end would lie inside a stop that may yet
        turn out a rest, and the stroke would play the stop (strokes of length 0, one per
        floor, where the pen rests at the anchor; a stroke through part of the stop where it
        rests after a stroke's vertex). The rest rule ends the stop once it has lasted
        ``rest_ms``, or the pen moves on."""
        if self.params.rest_ms <= 0.0:
            return j + 1
        xs, ys = self._xs, self._ys
        x, y = xs[j], ys[j]
        rest_sq = self._rest_sq
        k = j
        while k > 0:
            dx = xs[k - 1] - x
            dy = ys[k - 1] - y
            if not dx * dx + dy * dy <= rest_sq:  # (not ">": a NaN is a move, and ends a rest)
                break
            k -= 1
        return k

    def _retime(self, t_ms: float) -> None:
        self._ts[0] = t_ms
        anchor = self._samples[0]
        self._samples[0] = Sample(t_ms, anchor.x, anchor.y, anchor.pressure)

    def _rests(self, out: list[Segment]) -> bool:
        """Whether the pen has rested ``rest_ms`` at the newest sample: its samples of the last
        ``rest_ms`` or more all lie within the rest radius of it (as the window finds). The best
        polyline to the rest's first sample is let go; the rest is not played; the anchor waits
        at that sample for the pen to move on."""
        rest_ms = self.params.rest_ms
        xs, ys, ts = self._xs, self._ys, self._ts
        j = len(ts) - 1
        t = ts[j]
        if rest_ms <= 0.0 or t - ts[0] < rest_ms:
            return False
        start = self._still_from(j)
        if start == j or t - ts[start] < rest_ms:
            return False
        if start > 0:
            self._polyline(start, out)
        self._restart_at([xs[start]], [ys[start]], [ts[start]], [self._samples[start]])
        self._retime(t)
        self._rest_x, self._rest_y = xs[j], ys[j]
        self._resting = True
        self.rested = True
        return True


def piece_error(
    xs: list[float],
    ys: list[float],
    ax: float,
    ay: float,
    sums: list[Sums],
    start: int,
    end: int,
) -> float:
    """The integral square error of the piece xs[start] -> xs[end]: the sum of the squared
    distances of samples start..end to the line through its ends (to its start where they
    coincide), from the running sums ``sums`` (n + 1 of them, from 0, of the coordinates
    relative to the anchor (ax, ay)). Never below 0 (rounding); a NaN gives 0."""
    sx_end, sy_end, sxx_end, syy_end, sxy_end = sums[end + 1]
    sx_start, sy_start, sxx_start, syy_start, sxy_start = sums[start]
    count = float(end + 1 - start)
    px = xs[start] - ax
    py = ys[start] - ay
    dx = (xs[end] - ax) - px
    dy = (ys[end] - ay) - py
    sx = sx_end - sx_start
    sy = sy_end - sy_start
    # Sums of (x - px)^2, (y - py)^2 and (x - px)(y - py) over the piece's samples.
    cxx = sxx_end - sxx_start - 2.0 * px * sx + count * px * px
    cyy = syy_end - syy_start - 2.0 * py * sy + count * py * py
    cxy = sxy_end - sxy_start - px * sy - py * sx + count * px * py
    length_sq = dx * dx + dy * dy
    if length_sq > 0.0:
        error = (dx * dx * cyy + dy * dy * cxx - 2.0 * dx * dy * cxy) / length_sq
    else:
        error = cxx + cyy
    return error if error > 0.0 else 0.0
