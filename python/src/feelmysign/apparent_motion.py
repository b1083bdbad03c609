"""Apparent tactile motion: when each burst of a stroke starts and how long it lasts.

Israr and Poupyrev (CHI 2011): actuators switched on in sequence, overlapping
in time, are felt as one moving touch when the stimulus onset asynchrony is
``SOA = 0.32 d + 47.3`` ms for bursts of ``d`` ms. Given the peak times of a
stroke's virtual actuators (fractions of its duration T), ``timings`` solves the
model for every onset and duration, each affine in T; ``fits`` says whether all
of them reach the minimum burst at a given T, ``thinned`` which crossings to
keep when they do not, and ``shortest_planned_ms`` the least T of any stroke.

Every float is computed with the same operations in the same order as the
published formulas: the shared vectors in testdata/planner are compared bit
for bit.
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Iterable, Iterator, Sequence

SOA_SLOPE = 0.32  # Israr & Poupyrev 2011, eq. 1: SOA = 0.32 d + 47.3 (ms)
SOA_INTERCEPT_MS = 47.3  # ibid.; also the least time between two peaks of a moving touch

# (onset a, onset b, duration a, duration b) of one burst: every time in the
# motion model is affine in the stroke duration T, onset = a T + b and so on.
Timing = tuple[float, float, float, float]

_SOA_SCALE = 1.0 / (1.0 + SOA_SLOPE)  # solves SOA = 0.32 (d + SOA) + 47.3 for SOA


def timings(fractions: Sequence[float]) -> list[Timing]:
    """(onset, duration) of each burst, as affine functions of the stroke duration T.

    The Tactile Brush recursion (``tactile-brush.md``, "Durations and onsets"):
    ``SOA_i = (0.32 (d_i- + tau_{i+1} - S) + 47.3) / 1.32``, ``S += SOA_i``,
    ``d_{i+1}- = d_i+ = tau_{i+1} - S``, and finally ``d_n- = T - S``.

    Each time is carried as its two coefficients (``a`` of T, then ``b``); a
    peak ``tau`` is ``f T + 0``. Adding that 0 could only turn a -0.0 into 0.0,
    which never reaches an onset or a duration, so it is left out; subtracting
    from it (``0.0 - next_b``) is kept. Every float is the formula's, bit for bit.
    """
    return list(each_timing(fractions))


def each_timing(fractions: Sequence[float]) -> Iterator[Timing]:
    """The timings of ``timings``, one by one: the first bursts of a long stroke are timed
    (and started) before the rest."""
    if len(fractions) == 1:
        yield (0.0, 0.0, 1.0, 0.0)
        return
    onset_a = onset_b = 0.0
    before_a = before_b = 0.0  # d_i minus
    for tau in itertools.islice(fractions, 1, None):
        soa_a = (before_a + tau - onset_a) * SOA_SLOPE * _SOA_SCALE
        soa_b = ((before_b - onset_b) * SOA_SLOPE + SOA_INTERCEPT_MS) * _SOA_SCALE
        next_a, next_b = onset_a + soa_a, onset_b + soa_b
        after_a, after_b = tau - next_a, 0.0 - next_b  # d_i plus, which is d_{i+1} minus
        yield (onset_a, onset_b, before_a + after_a, before_b + after_b)
        onset_a, onset_b, before_a, before_b = next_a, next_b, after_a, after_b
    yield (onset_a, onset_b, 1.0 - onset_a, 0.0 - onset_b)


def surely_fits(fractions: Sequence[float], duration_ms: float, min_command_ms: float) -> bool:
    """Whether ``timings(fractions)`` surely ``fits`` at ``duration_ms``, judged from the two
    closest peaks alone, in C: no timing is computed (a sufficient condition, not a necessary one).

    Between peaks ``g`` ms apart, the recursion of ``timings`` gives each burst's onset a
    lag behind its own peak of ``e' = (g + 0.68 e - 47.3) / 1.32``, from the lag ``e``
    before it (0 at the first burst); each burst lasts ``e + e'``, the last one its own
    lag. The lag grows with ``g`` and ``e``: with every ``g`` at least ``G``, every lag from
    the second burst on is at least ``(G - 47.3) / 1.32``, and so is every burst. The margin
    is far above the floats' rounding, far below a burst a skin could tell apart.
    """
    closest: float = min(map(operator.sub, itertools.islice(fractions, 1, None), fractions))
    least_lag_ms = (closest * duration_ms - SOA_INTERCEPT_MS) * _SOA_SCALE
    return least_lag_ms >= min_command_ms + _SURE_MARGIN_MS


_SURE_MARGIN_MS = 1e-3


def lengths_bound_ms(fractions: Sequence[float], duration_ms: float) -> float:
    """At least the sum of the bursts' lengths of ``timings(fractions)`` at ``duration_ms``
    when the last one lasts 0 ms or more (as when they fit), without computing them.

    Summing the lags of ``surely_fits`` over the ``n`` steps between peaks, which add up to
    the duration T: the lengths add up to ``(T - 0.68 e_n - 47.3 n) / 0.32``, ``e_n`` the
    last burst's length; so to at most ``(T - 47.3 n) / 0.32``.
    """
    steps = len(fractions) - 1
    return (duration_ms - SOA_INTERCEPT_MS * steps) / SOA_SLOPE


def fitting_timings(
    fractions: Sequence[float], duration_ms: float, min_command_ms: float
) -> list[Timing] | None:
    """``timings(fractions)`` if they ``fits`` at ``duration_ms``, else None.

    One pass that stops at the first burst too short: thinning asks this of
    each count it tries, and most of those fail early. The same floats as
    ``timings`` and the same test as ``fits``.
    """
    floor = min_command_ms * (1 - 1e-12) - 1e-9  # as in fits
    if len(fractions) == 1:
        return [(0.0, 0.0, 1.0, 0.0)] if 1.0 * duration_ms + 0.0 >= floor else None
    onset_a = onset_b = 0.0
    before_a = before_b = 0.0
    result: list[Timing] = []
    append = result.append
    for tau in itertools.islice(fractions, 1, None):
        soa_a = (before_a + tau - onset_a) * SOA_SLOPE * _SOA_SCALE
        soa_b = ((before_b - onset_b) * SOA_SLOPE + SOA_INTERCEPT_MS) * _SOA_SCALE
        next_a, next_b = onset_a + soa_a, onset_b + soa_b
        after_a, after_b = tau - next_a, 0.0 - next_b
        length_a, length_b = before_a + after_a, before_b + after_b
        if not length_a * duration_ms + length_b >= floor:
            return None
        append((onset_a, onset_b, length_a, length_b))
        onset_a, onset_b, before_a, before_b = next_a, next_b, after_a, after_b
    length_a, length_b = 1.0 - onset_a, 0.0 - onset_b
    if not length_a * duration_ms + length_b >= floor:
        return None
    append((onset_a, onset_b, length_a, length_b))
    return result


def fastest_feasible_ms(burst_timings: Iterable[Timing], min_command_ms: float) -> float:
    """The least T for which every burst lasts at least ``min_command_ms``.

    Every duration grows with T (its slope is positive: each onset is a
    weighted mean of earlier peaks, so it trails its own peak), hence the
    feasible durations are one interval [T_min, inf).
    """
    needed = 0.0
    for _, _, duration_a, duration_b in burst_timings:
        if duration_a > 0:
            needed = max(needed, (min_command_ms - duration_b) / duration_a)
    # Rounded up to the microsecond: every burst reaches the minimum despite
    # float rounding, and the adjusted duration reads well.
    return math.ceil(needed * 1000.0 * (1 + 1e-12)) / 1000.0


_TWO_PHANTOMS = timings([0.0, 1.0])


def shortest_planned_ms(min_command_ms: float) -> float:
    """The least duration of any stroke: two end phantoms, each burst ``min_command_ms``.

    Two bursts in apparent motion last ``d = (T - 47.3) / 1.32`` each, so
    ``T = 1.32 d + 47.3`` (73.7 ms for 20 ms bursts), rounded up to the
    microsecond. A point is held for at least as long, so that the duration does
    not jump as a stroke shrinks to a point.
    """
    # Asked once per stroke planned, with one of a few minimum bursts: kept.
    shortest = _SHORTEST_MS.get(min_command_ms)
    if shortest is None:
        shortest = fastest_feasible_ms(_TWO_PHANTOMS, min_command_ms)
        if len(_SHORTEST_MS) < _SHORTEST_KEPT:
            _SHORTEST_MS[min_command_ms] = shortest
    return shortest


_SHORTEST_MS: dict[float, float] = {}
_SHORTEST_KEPT = 64  # minimum bursts come from layouts and options: a handful


def fits(burst_timings: Iterable[Timing], duration_ms: float, min_command_ms: float) -> bool:
    """Whether every burst lasts at least ``min_command_ms`` at ``duration_ms``."""
    # The same floor as fastest_feasible_ms, whose rounding up makes its result fit.
    floor = min_command_ms * (1 - 1e-12) - 1e-9
    # A loop, not all(): no generator per stroke planned.
    for _, _, a, b in burst_timings:  # noqa: SIM110
        if not a * duration_ms + b >= floor:
            return False
    return True


def thinned(fractions: Sequence[float], duration_ms: float, min_command_ms: float) -> list[int]:
    """Indices of the virtual actuators kept so that every burst fits ``duration_ms``.

    Apparent motion needs its peaks about 54 ms apart at the least (74 ms for
    the first and last step): peaks closer than that cannot each get a burst the
    skin feels, and are fused anyway. So the most crossings that fit are kept,
    chosen evenly spread in time (a steady apparent speed): for ``count``
    crossings, the one nearest each of ``count`` evenly spaced times. The two
    endpoints are always kept, and they alone fit any duration of at least
    ``shortest_planned_ms``.

    Fewer crossings leave wider gaps, so whether ``count`` fits falls with
    ``count``: a bisection finds the most that fit in a few tries, which
    matters on a large grid (a stroke across 64 columns crosses 100 lines).
    """
    last = len(fractions) - 1
    best = [0, last]
    fitting, failing = 0, last - 1  # counts known to fit (none) and not to (all crossings)
    while failing - fitting > 1:
        count = (fitting + failing) // 2
        kept = _evenly_spread(fractions, count)
        if fitting_timings([fractions[i] for i in kept], duration_ms, min_command_ms) is not None:
            fitting, best = count, kept
        else:
            failing = count
    return best


def _evenly_spread(fractions: Sequence[float], count: int) -> list[int]:
    """The ends and, for each of ``count`` evenly spaced times, the crossing nearest to it.

    A crossing nearest to two of the times is kept once. The targets increase,
    so one forward walk over the crossings finds every nearest one.
    """
    last = len(fractions) - 1
    kept = [0]
    j = 1
    for k in range(1, count + 1):
        target = k / (count + 1)
        while j < last - 1 and abs(fractions[j + 1] - target) < abs(fractions[j] - target):
            j += 1
        if j != kept[-1]:
            kept.append(j)
    kept.append(last)
    return kept
