"""The sleeve's clocks, in milliseconds: one home, so the player, the backends and the
daemon read the same time the same way.

Tiny on purpose (it imports only :mod:`time`): the backends import it, and a sleeve
restarted after a crash imports the backends package before it switches its motors off.
"""

from __future__ import annotations

import time


def monotonic_ms() -> float:
    """A monotonic time in milliseconds: the player's and the backends' clock."""
    return time.monotonic_ns() / 1e6


def wall_ms() -> float:
    """The wall clock in milliseconds since the Unix epoch (for events and records)."""
    return time.time_ns() / 1e6


def both_ms() -> tuple[float, float]:
    """``(monotonic_ms(), wall_ms())`` of one instant.

    Two clocks read one after the other are as far apart as the thread was kept from
    running between the reads: under load, a fraction of a millisecond. The wall clock is
    read between two readings of the monotonic one, and read again while those two are
    more than 20 µs apart (at most a few times), so that the wall times of events placed
    on the monotonic clock line up with each other.
    """

    # Written out, not a nested function made and called per reading: the sleeve reads these
    # first thing on a stroke's receipt.
    monotonic_ns, time_ns = time.monotonic_ns, time.time_ns
    before = monotonic_ns()
    wall = time_ns()
    after = monotonic_ns()
    best = (after - before, (before + after) / 2e6, wall / 1e6)
    for _ in range(3):
        if best[0] <= 20_000:
            break
        before = monotonic_ns()
        wall = time_ns()
        after = monotonic_ns()
        best = min(best, (after - before, (before + after) / 2e6, wall / 1e6))
    return best[1], best[2]
