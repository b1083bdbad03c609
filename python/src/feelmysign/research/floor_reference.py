"""What the sleeve's floor leaves of a drawing's shape: a reference for the simplifiers.

A stroke the sleeve plays in its drawn time lasts at least its floor (73.7 ms on the paper's
ERM sleeve: two 20 ms end bursts). So whatever a simplifier does, online or offline, a path
drawn in D ms gets at most D / floor strokes that nothing slows. This finds, offline and with
the whole path known, the polyline through drawn samples whose every piece lasts at least the
floor and whose samples lie nearest it: the least integral square error (the sum of each
sample's squared distance to the line of its piece), by dynamic programming over the samples
(Perez and Vidal, "Optimum polygonal approximation of digitized curves", Pattern Recognition
Letters 15, 1994, with the floor as the constraint on each piece instead of a count of pieces).
Each piece's error comes from prefix sums in O(1), so a path of n samples takes O(n^2).

It keeps no error bound, no latency cap and no rest rule, and it sees the future: a
reference for the shape alone, not a simplifier. ``feelmysign evaluate --best-at-floor``
recognises it with $1 beside the drawings and the strokes sent (docs/research.md, "What the
floor leaves of recognition").
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from feelmysign.research import metrics
from feelmysign.simplify.registry import PathSegment
from feelmysign.simplify.segment import Segment

if TYPE_CHECKING:
    from feelmysign.research.evaluate import Recogniser, Source


def _prefix(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Sums of values[:k] for k = 0 .. n."""
    return np.concatenate([[0.0], np.cumsum(values)])


def piece_errors(
    points: NDArray[np.float64], starts: NDArray[np.int64], end: int
) -> NDArray[np.float64]:
    """The integral square error of the pieces points[i] -> points[end], one per i in ``starts``.

    Each sample from i to end (both included) counts its squared distance to the line through
    the piece's ends; a piece whose ends coincide (a closed loop) counts the distance to that
    point. Computed from sums over the samples (`_Sums`) rather than sample by sample.
    """
    return _Sums(points).errors(starts, end)


class _Sums:
    """Prefix sums of x, y, x^2, y^2 and xy over a path's samples."""

    def __init__(self, points: NDArray[np.float64]) -> None:
        x, y = points[:, 0], points[:, 1]
        self.x, self.y = x, y
        self.sx, self.sy = _prefix(x), _prefix(y)
        self.sxx, self.syy, self.sxy = _prefix(x * x), _prefix(y * y), _prefix(x * y)

    def errors(self, starts: NDArray[np.int64], end: int) -> NDArray[np.float64]:
        i = starts
        count = (end + 1 - i).astype(np.float64)
        ax, ay = self.x[i], self.y[i]
        dx, dy = self.x[end] - ax, self.y[end] - ay
        sx = self.sx[end + 1] - self.sx[i]
        sy = self.sy[end + 1] - self.sy[i]
        # Sums of (x - ax)^2, (y - ay)^2 and (x - ax)(y - ay) over the piece's samples.
        cxx = self.sxx[end + 1] - self.sxx[i] - 2.0 * ax * sx + count * ax * ax
        cyy = self.syy[end + 1] - self.syy[i] - 2.0 * ay * sy + count * ay * ay
        cxy = self.sxy[end + 1] - self.sxy[i] - ax * sy - ay * sx + count * ax * ay
        length_sq = dx * dx + dy * dy
        cross_sq = dx * dx * cyy + dy * dy * cxx - 2.0 * dx * dy * cxy
        with np.errstate(divide="ignore", invalid="ignore"):
            along_line = cross_sq / length_sq
        result: NDArray[np.float64] = np.maximum(
            np.where(length_sq > 0.0, along_line, cxx + cyy), 0.0
        )
        return result


def best_at_floor(
    points: Sequence[tuple[float, float]] | NDArray[np.float64],
    times_ms: ArrayLike,
    floor_ms: float,
    max_error: float | None = None,
) -> NDArray[np.int64]:
    """The indices of the samples the best polyline at the floor passes through, first and
    last included: every piece lasts at least ``floor_ms`` (a path briefer than that is one
    piece), and the sum of the samples' squared distances to their pieces is the least such
    a polyline can have. Times earlier than the one before count as the one before; ties go
    to the earlier vertex (the longer last piece).

    With ``max_error``, every piece keeps each of its samples within it (grid units), and a
    piece briefer than the floor is taken where no piece lasting it keeps the bound: the
    fewest such pieces first, then the least squares (as the window simplifier sends such a
    piece, to be played at the floor)."""
    path = metrics.as_points(points)
    n = len(path)
    if n < 2:
        return np.arange(n, dtype=np.int64)
    times = np.maximum.accumulate(np.asarray(times_ms, dtype=np.float64))
    bound = None if max_error is None else _Bound(path, max_error)
    return np.array(_best(_Sums(path), times, 0, n - 1, floor_ms, bound=bound), dtype=np.int64)


# Far more than a distance's rounding error on a grid, far less than any bound (as the window
# simplifier's ROUNDING_SLACK): a sample at the bound, to within rounding, keeps it.
ROUNDING_SLACK = 1e-9
# The most samples a piece of the bounded search holds: the window simplifier's default work
# cap (max_window), which keeps the search's cost (samples x this squared) within reach.
MAX_PIECE_SAMPLES = 256


class _Bound:
    """Which pieces keep every sample within ``max_error`` of them (distances to the segment)."""

    def __init__(self, path: NDArray[np.float64], max_error: float) -> None:
        self.path = path
        self.limit_sq = (max_error + ROUNDING_SLACK) ** 2  # a distance at the bound keeps it
        # end -> (the first start asked, its answers): the online search asks the same pieces
        # again at every sample, from the same or a later start.
        self._answers: dict[int, tuple[int, NDArray[np.bool_]]] = {}

    def keeps(self, starts: NDArray[np.int64], end: int) -> NDArray[np.bool_]:
        """For each piece starts[i] -> end (consecutive starts): whether every sample between
        lies within the bound."""
        first = int(starts[0])
        known = self._answers.get(end)
        if known is not None and known[0] <= first:
            return known[1][first - known[0] : first - known[0] + len(starts)]
        answers = self._compute(starts, end)
        self._answers[end] = (first, answers)
        return answers

    def _compute(self, starts: NDArray[np.int64], end: int) -> NDArray[np.bool_]:
        first = int(starts[0])
        a = self.path[starts]  # (m, 2)
        d = self.path[end] - a
        q = self.path[None, first : end + 1, :] - a[:, None, :]  # (m, samples, 2)
        length_sq = np.einsum("ij,ij->i", d, d)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.clip(np.einsum("ikj,ij->ik", q, d) / length_sq[:, None], 0.0, 1.0)
        t = np.where(length_sq[:, None] > 0.0, t, 0.0)
        r = q - t[:, :, None] * d[:, None, :]
        distance_sq = np.einsum("ikj,ikj->ik", r, r)
        # Only the samples of each piece: those after its start (and up to the end).
        inside = np.arange(first, end + 1)[None, :] > starts[:, None]
        farthest = np.max(np.where(inside, distance_sq, 0.0), axis=1)
        result: NDArray[np.bool_] = farthest <= self.limit_sq
        return result


def _best(
    sums: _Sums,
    times: NDArray[np.float64],
    first: int,
    last: int,
    floor_ms: float,
    *,
    open_end: bool = False,
    bound: _Bound | None = None,
) -> list[int]:
    """The least-squares vertices from sample ``first`` to ``last`` whose pieces all last at
    least ``floor_ms`` (one piece if none can); with ``open_end`` the last piece may be
    briefer (the path goes on: that piece is not final). With ``bound``, every piece keeps
    it, and briefer pieces are taken where needed, the fewest first, each piece at most
    ``MAX_PIECE_SAMPLES`` samples long."""
    n = last - first + 1
    best = np.full(n, np.inf)
    best[0] = 0.0
    # With a bound: how many pieces briefer than the floor, compared before the error (a
    # count kept apart: a large cost added to the error would swamp its last digits).
    brief = np.zeros(n, dtype=np.float64)
    before = np.full(n, -1, dtype=np.int64)
    for k in range(1, n):
        j = first + k
        if bound is None:
            # The vertices i a piece i -> j may start at: drawn at least the floor before j.
            stop = (
                k
                if open_end and j == last
                else int(np.searchsorted(times, times[j] - floor_ms, side="right")) - first
            )
            stop = min(stop, k)
            if stop <= 0:
                continue
            starts = np.arange(first, first + stop, dtype=np.int64)
            totals = best[:stop] + sums.errors(starts, j)
            i = int(np.argmin(totals))
            best[k], before[k] = totals[i], i
            continue
        # At most MAX_PIECE_SAMPLES samples a piece, as the window's work cap (max_window).
        low = max(0, k - MAX_PIECE_SAMPLES)
        starts = np.arange(first + low, j, dtype=np.int64)
        totals = best[low:k] + sums.errors(starts, j)
        counts = brief[low:k].copy()
        if not (open_end and j == last):
            counts += times[j] - times[starts] < floor_ms
        counts = np.where(bound.keeps(starts, j), counts, np.inf)
        fewest = counts.min()
        if not np.isfinite(fewest):
            continue
        totals = np.where(counts == fewest, totals, np.inf)
        i = int(np.argmin(totals))
        best[k], brief[k], before[k] = totals[i], fewest, low + i
    if not np.isfinite(best[n - 1]):
        return [first, last]
    chosen = [n - 1]
    while chosen[-1] != 0:
        chosen.append(int(before[chosen[-1]]))
    return [first + k for k in reversed(chosen)]


def _keeps(bound: _Bound | None, start: int, end: int) -> bool:
    return bound is None or bool(bound.keeps(np.array([start], dtype=np.int64), end)[0])


def online_at_floor(
    points: Sequence[tuple[float, float]] | NDArray[np.float64],
    times_ms: ArrayLike,
    floor_ms: float,
    lookahead_ms: float,
    cap_ms: float,
    max_error: float | None = None,
) -> list[tuple[int, int, float]]:
    """The same polyline found online: the pieces (start index, end index, when let go, ms).

    At each sample the least-squares vertices at the floor are found again from the last
    vertex let go to the sample (the last piece open); the first of them is let go once the
    pen has drawn ``lookahead_ms`` past it, or once the piece lasts more than ``cap_ms`` (the
    latency cap). At release the rest is let go at once, every piece then at least the floor.
    So each stroke but the last few waits ``lookahead_ms`` for what comes after it: a
    reference for a simplifier that holds its strokes that long, not one. ``max_error``
    bounds every piece as ``best_at_floor``'s does.
    """
    path = metrics.as_points(points)
    n = len(path)
    if n < 2:
        return []
    times = np.maximum.accumulate(np.asarray(times_ms, dtype=np.float64))
    sums = _Sums(path)
    bound = None if max_error is None else _Bound(path, max_error)
    pieces: list[tuple[int, int, float]] = []
    anchor = 0
    for j in range(1, n):
        while times[j] - times[anchor] >= floor_ms:
            vertices = _best(sums, times, anchor, j, floor_ms, open_end=True, bound=bound)
            if len(vertices) < 3:
                capped = times[j] - times[anchor] > cap_ms
                if (
                    capped
                    and times[j - 1] - times[anchor] >= floor_ms
                    and _keeps(bound, anchor, j - 1)
                ):
                    pieces.append((anchor, j - 1, float(times[j])))  # one long piece: capped
                    anchor = j - 1
                    continue
                break
            vertex = vertices[1]
            if times[j] - times[vertex] < lookahead_ms and times[vertex] - times[anchor] <= cap_ms:
                break
            pieces.append((anchor, vertex, float(times[j])))
            anchor = vertex
    rest = _best(sums, times, anchor, n - 1, floor_ms, bound=bound)
    pieces += [(a, b, float(times[-1])) for a, b in itertools.pairwise(rest)]
    return pieces


@dataclass(frozen=True)
class Reference:
    """A reference polyline of a drawing (its paths one after another), its stroke count, its
    strokes as a simplifier would send them, and each stroke's farthest sample (grid units)."""

    polyline: NDArray[np.float64]
    strokes: int
    segments: tuple[PathSegment, ...]
    deviations: tuple[float, ...]


def reference(
    paths: Sequence[NDArray[np.float64]],
    times_ms: Sequence[ArrayLike],
    floor_ms: float,
    *,
    lookahead_ms: float | None = None,
    cap_ms: float = math.inf,
    max_error: float | None = None,
) -> Reference:
    """The best polyline at the floor of each path (grid points and their times), chained as
    the strokes sent are: offline (``best_at_floor``, each stroke let go as it ends), or with
    ``lookahead_ms`` online (``online_at_floor``, let go as it says)."""
    pieces = []
    segments: list[PathSegment] = []
    deviations: list[float] = []
    for index, (points, times) in enumerate(zip(paths, times_ms, strict=True)):
        if len(points) == 0:
            continue
        path = np.asarray(points, dtype=np.float64)
        at = np.maximum.accumulate(np.asarray(times, dtype=np.float64))
        if lookahead_ms is None:
            kept = best_at_floor(path, at, floor_ms, max_error)
            let_go = [(int(a), int(b), float(at[b])) for a, b in itertools.pairwise(kept)]
        else:
            let_go = online_at_floor(path, at, floor_ms, lookahead_ms, cap_ms, max_error)
        pieces.append(path[[let_go[0][0], *(b for _, b, _ in let_go)]] if let_go else path[:1])
        for a, b, emitted_ms in let_go:
            start = (float(path[a, 0]), float(path[a, 1]))
            end = (float(path[b, 0]), float(path[b, 1]))
            # A piece briefer than the floor is sent to last it, as the window sends one.
            play_ms = floor_ms if at[b] - at[a] < floor_ms else None
            segment = Segment(start, end, float(at[a]), float(at[b]), emitted_ms, play_ms=play_ms)
            segments.append(PathSegment(index, segment))
            distances = metrics.segment_distances(path[a : b + 1], start, end)
            deviations.append(float(np.max(distances)))
    polyline = np.concatenate(pieces) if pieces else metrics.as_points([])
    return Reference(polyline, len(segments), tuple(segments), tuple(deviations))


def summarize_at_floor(
    sources: Sequence[Source],
    recogniser: Recogniser | None,
    floor_ms: float,
    *,
    lookahead_ms: float | None = None,
    cap_ms: float = math.inf,
    max_error: float | None = None,
    drawings: list[dict[str, Any]] | None = None,
) -> list[dict[str, Any]]:
    """Per set, in first-seen order, of the best polyline at the floor of each drawing
    (offline, or online with ``lookahead_ms``): its strokes (mean; and in all, and how many
    of them are briefer than the floor, played at it), how often $1 names the
    drawing, the polyline and its felt path (planned and played as the sleeve would; percent,
    None without a shape to recognise), the felt end (release to the end of the last stroke
    felt, p95) and time on the skin over drawing time (mean, p95), and the farthest drawn
    sample from its stroke (grid units). Drawings are mapped to the grid as the window
    simplifier maps them. ``drawings``, when given, gets each drawing's own figures
    (``DRAWING_COLUMNS``)."""
    from feelmysign.research.evaluate import grid_points, layout_for
    from feelmysign.research.felt import felt_path
    from feelmysign.research.playback import simulate
    from feelmysign.simplify.registry import ALGORITHMS, params_for

    window = ALGORITHMS["window"]
    sets: dict[str, list[dict[str, Any]]] = {}
    for source in sources:
        params = params_for(window, source.recording, {})
        paths = [grid_points(params, path) for path in source.recording.paths]
        times = [[s.t_ms for s in path] for path in source.recording.paths]
        found = reference(
            paths, times, floor_ms, lookahead_ms=lookahead_ms, cap_ms=cap_ms, max_error=max_error
        )
        drawn = np.concatenate(paths) if paths else metrics.as_points([])
        # Felt as the sleeve plans and plays the strokes (research.felt): the phantom's path.
        playback = simulate(found.segments, source.recording.paths, layout_for(params))
        named = felt = drawn_named = None
        if recogniser is not None:
            felt = recogniser.names(source, felt_path(playback.schedules))
            named = recogniser.names(source, found.polyline)
            drawn_named = recogniser.drawn(source, drawn)
        skin = playback.skin_ratio if playback.drawing_ms > 0 else None
        deviation = max(found.deviations, default=0.0)
        brief = sum(
            item.segment.end_ms - item.segment.start_ms < floor_ms for item in found.segments
        )
        figures: dict[str, Any] = {
            "strokes": found.strokes,
            "brief": brief,
            "drawn": drawn_named,
            "named": named,
            "felt": felt,
            "felt_end_ms": playback.release_to_felt_end_ms,
            "skin": skin,
            "deviation": deviation,
        }
        sets.setdefault(source.set, []).append(figures)
        if drawings is not None:
            drawings.append(
                {
                    "recording": source.name,
                    "group": source.group,
                    "set": source.set,
                    "lookahead_ms": lookahead_ms,
                    "max_error": max_error,
                    "strokes": figures["strokes"],
                    "brief_strokes": brief,
                    "recognised_drawn": _flag(drawn_named),
                    "recognised": _flag(named),
                    "recognised_felt": _flag(felt),
                    "release_to_felt_end_ms": round(max(playback.release_to_felt_end_ms), 1)
                    if playback.release_to_felt_end_ms
                    else "",
                    "skin_ratio": "" if skin is None else round(skin, 3),
                    "max_deviation": round(deviation, 6),
                }
            )
    summary = []
    for name, members in sets.items():
        felt_end = [v for m in members for v in m["felt_end_ms"]]
        skins = [m["skin"] for m in members if m["skin"] is not None]
        summary.append(
            {
                "set": name,
                "floor_ms": floor_ms,
                "lookahead_ms": lookahead_ms,
                "max_error": max_error,
                "recordings": len(members),
                "strokes_mean": round(float(np.mean([m["strokes"] for m in members])), 2),
                "brief_strokes_total": sum(m["brief"] for m in members),
                "strokes_total": sum(m["strokes"] for m in members),
                "recognised_drawn_pct": _percent([m["drawn"] for m in members]),
                "recognised_pct": _percent([m["named"] for m in members]),
                "recognised_felt_pct": _percent([m["felt"] for m in members]),
                "release_to_felt_end_p95_ms": _rounded(felt_end, 95),
                "skin_ratio_mean": round(float(np.mean(skins)), 3) if skins else None,
                "skin_ratio_p95": _rounded(skins, 95, 3),
                "max_deviation_max": round(max(m["deviation"] for m in members), 6),
            }
        )
    return summary


# The columns of best_at_floor.csv, one row per drawing and reference (``drawings``).
DRAWING_COLUMNS = (
    "recording",
    "group",
    "set",
    "lookahead_ms",
    "max_error",
    "strokes",
    "brief_strokes",
    "recognised_drawn",
    "recognised",
    "recognised_felt",
    "release_to_felt_end_ms",
    "skin_ratio",
    "max_deviation",
)


def _flag(value: bool | None) -> int | str:
    return "" if value is None else int(value)


def _rounded(values: Sequence[float], q: float, digits: int = 1) -> float | None:
    return round(float(np.percentile(values, q)), digits) if len(values) else None


def _percent(flags: Sequence[bool | None]) -> float | None:
    known = [f for f in flags if f is not None]
    return round(100.0 * sum(known) / len(known), 2) if known else None
