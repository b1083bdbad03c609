"""Keeping the sleeve in real time with its senders: stale strokes and a way back after a stall.

A stroke is the sender's touch at the moment it was drawn; felt half a minute
later it is no longer that touch. Two rules, both on the stroke's
``sent_at_ms`` (the sender's wall clock), so a stroke without it (the legacy
format) is never refused by them:

- **stale**: a stroke received more than ``max_age_ms`` after it was sent is
  refused. This catches strokes the broker kept while the sleeve was away. It
  compares two clocks, the sender's and the sleeve's, so it needs them to agree
  to well within ``max_age_ms`` (NTP does; a sender whose clock is behind or
  ahead by more gets every stroke refused, and the message says to check its
  clock: a stroke stamped further ahead cannot be told from one held all night).
- **late**: a stroke that would start more than ``max_lag_ms`` after it was due
  is skipped. When a stroke is due is the sender's own time line: its
  ``sent_at_ms``, but never before the stroke before it in the same drawing has
  ended (a drawing sent all at once is due back to back): the queue's start-time
  rule (:func:`feelmysign.sleeve.queue.start_ms`) on the sender's clock. How late it starts is
  measured against the smallest delay seen in that drawing, so a constant
  clock difference between sender and sleeve cancels out. After a stall (the
  network or the broker away for 10 s) the backlog arrives at once: the sleeve
  skips strokes until it is back within ``catch_up_ms`` of the sender's time line
  (a quarter of ``max_lag_ms``), so it is back in real time at once instead of
  running 10 s late for the rest of the drawing. A stroke that comes after a
  later one of its drawing (a broker that failed over delivers it again) is due
  at its own ``sent_at_ms`` and leaves the time line as it was: it is late when
  it starts more than ``max_lag_ms`` after that, and neither pushes the
  strokes after it back nor starts a catch-up.

The policy is pure (numbers in, a verdict out); the daemon feeds it and reports
the verdicts as ``rejected`` events with reason ``stale`` or ``late``.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Iterable
from dataclasses import dataclass

from feelmysign.frozen_init import dict_init
from feelmysign.protocol import LATE, STALE
from feelmysign.sleeve.queue import REMEMBERED_DRAWINGS, start_ms

__all__ = ["LATE", "MAX_AGE_MS", "MAX_LAG_MS", "STALE", "PacePolicy", "Verdict"]

# Strokes older than this are refused. Long enough for a sender's clock a few seconds off
# and for a broker restart; short enough that a drawing is not felt long after the fact.
MAX_AGE_MS = 10_000.0
# How far playback may trail the sender's time line before strokes are skipped to catch up:
# above network jitter on a busy machine, below what feels like a different moment.
MAX_LAG_MS = 1_000.0
# Once skipping, skip down to this much behind: strokes of a drawing play back to back, so
# the lag left when skipping stops stays for the rest of the drawing.
CATCH_UP_FRACTION = 0.25


@dict_init
@dataclass(frozen=True)
class Verdict:
    """``reason`` None: play it. ``age_ms`` and ``lag_ms`` are None without ``sent_at_ms``.

    Made with one dict update (``dict_init``): one per stroke, before its first motor command.
    """

    reason: str | None = None
    message: str = ""
    age_ms: float | None = None
    lag_ms: float | None = None


@dataclass
class _TimeLine:
    smallest_delay_ms: float  # receive minus send: transit time plus the clocks' difference
    due_end_ms: float  # when the stroke before ends on the sender's time line
    catching_up: bool = False
    last_seq: int | None = None  # the highest seq checked so far


def _why_late(held_ms: float, queued_ms: float) -> str:
    """Why a stroke is late, from the larger of its two parts: ``held_ms``, how much later than
    the quickest stroke of its drawing it arrived (the sender, the network or the broker held
    it); ``queued_ms``, how much longer than its own drawing's time line it would wait behind
    the strokes queued on the sleeve before it (another drawing playing, or a backlog of its own
    that a sleeve back from away received at once)."""
    if held_ms >= queued_ms:
        return (
            f"it arrived {held_ms / 1000:.2f} s later than its drawing's quickest stroke, held on "
            "the way (the sleeve, the sender, the network or the broker was away)"
        )
    return (
        f"it would wait {queued_ms / 1000:.2f} s behind the strokes queued on the sleeve before it"
    )


class PacePolicy:
    """Call ``check`` once per stroke, in the order the strokes arrive (one thread)."""

    def __init__(self, *, max_age_ms: float = MAX_AGE_MS, max_lag_ms: float = MAX_LAG_MS) -> None:
        self.max_age_ms = max_age_ms
        self.max_lag_ms = max_lag_ms
        self.catch_up_ms = max_lag_ms * CATCH_UP_FRACTION
        self._drawings: OrderedDict[str, _TimeLine] = OrderedDict()

    def check(
        self,
        drawing: str | None,
        sent_at_ms: float | None,
        received_wall_ms: float,
        start_wall_ms: float,
        duration_ms: float,
        seq: int | None = None,
    ) -> Verdict:
        """The verdict on a stroke received at ``received_wall_ms`` that would start at
        ``start_wall_ms`` (both on the sleeve's wall clock) and last ``duration_ms``.
        (Positional too: the sleeve calls it on the path from a message to its first command.)"""
        if sent_at_ms is None:
            return Verdict()
        age_ms = received_wall_ms - sent_at_ms
        line = self._time_line(drawing, sent_at_ms)
        if seq is not None and line.last_seq is not None and seq < line.last_seq:
            line = _TimeLine(line.smallest_delay_ms, sent_at_ms)  # on its own, not kept
        elif seq is not None:
            line.last_seq = seq
        # The sleeve's queue rule, on the sender's time line.
        due_ms = start_ms(sent_at_ms, line.due_end_ms)
        line.due_end_ms = due_ms + duration_ms
        if age_ms > self.max_age_ms:
            return Verdict(
                STALE,
                f"the stroke was sent {age_ms / 1000:.1f} s ago (by the sender's clock); the "
                f"sleeve plays strokes at most {self.max_age_ms / 1000:g} s old. It was held on "
                "the way (the sleeve or its broker was away), or, if it was just sent, the "
                "sender's clock is behind the sleeve's: set both by NTP",
                age_ms=age_ms,
            )
        if age_ms < -self.max_age_ms:
            # Its age cannot be told: a stroke the broker held all night, stamped ahead by a
            # clock that runs fast (or on purpose), would otherwise play when the sleeve
            # comes on.
            return Verdict(
                STALE,
                f"the stroke is stamped {-age_ms / 1000:.1f} s ahead of the sleeve's clock (by "
                "the sender's clock), so how old it is cannot be told; the sleeve plays strokes "
                f"stamped at most {self.max_age_ms / 1000:g} s either side of its own time. The "
                "sender's clock is ahead of the sleeve's: set both by NTP",
                age_ms=age_ms,
            )
        line.smallest_delay_ms = min(line.smallest_delay_ms, age_ms)
        lag_ms = start_wall_ms - due_ms - line.smallest_delay_ms
        line.catching_up = lag_ms > (self.catch_up_ms if line.catching_up else self.max_lag_ms)
        if line.catching_up:
            held_ms = age_ms - line.smallest_delay_ms
            return Verdict(
                LATE,
                f"the stroke would start {lag_ms / 1000:.2f} s after it was due: "
                f"{_why_late(held_ms, lag_ms - held_ms)}; a sleeve more than "
                f"{self.max_lag_ms / 1000:g} s behind its sender skips strokes until it is "
                f"within {self.catch_up_ms / 1000:g} s",
                age_ms=age_ms,
                lag_ms=lag_ms,
            )
        return Verdict(age_ms=age_ms, lag_ms=max(lag_ms, 0.0))

    def remember(self, drawings: Iterable[tuple[str, float]]) -> None:
        """Time lines kept from before a restart (``feelmysign.sleeve.pace_memory``), oldest
        first: each drawing's smallest delay. A stroke the broker held while the sleeve was
        away is then measured against it, as before the restart, and is late by how long it
        was held (the sleeve catches up by skipping, as after a stall), where the first of
        such strokes to arrive would otherwise set the drawing's time line and the newer
        strokes behind them would be skipped. The line's end is not kept: the first stroke
        after the restart is due at its own ``sent_at_ms``."""
        for drawing, smallest_delay_ms in drawings:
            self._drawings[drawing] = _TimeLine(smallest_delay_ms, -math.inf)
            self._drawings.move_to_end(drawing)
        while len(self._drawings) > REMEMBERED_DRAWINGS:
            self._drawings.popitem(last=False)

    def _time_line(self, drawing: str | None, sent_at_ms: float) -> _TimeLine:
        if drawing is None:  # no drawing: nothing to chain or compare with
            return _TimeLine(float("inf"), sent_at_ms)
        line = self._drawings.get(drawing)
        if line is None:
            line = self._drawings[drawing] = _TimeLine(float("inf"), sent_at_ms)
            while len(self._drawings) > REMEMBERED_DRAWINGS:
                self._drawings.popitem(last=False)
        self._drawings.move_to_end(drawing)
        return line
