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
