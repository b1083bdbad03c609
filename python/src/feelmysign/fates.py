"""What became of each stroke of a drawing: the one rule that the page, ``up`` and the study
report from, so that their counts agree and add up to the strokes the sleeve answered.

Each stroke has one fate, read from the sleeve's events about it (docs/protocol.md,
"What became of a stroke"):

- ``played``: its ``played`` (or ``adjusted``) event: felt whole;
- ``cut``: cut short by a cancel while it played (a ``cancelled`` event with
  ``started``; the sender's, or the wearer's pause or stop, ``by: "wearer"``), or by a
  fault after its ``played`` (a ``safety`` event: ``chip_lost``; ``stopped`` or
  ``crashed``, the sleeve stopped or its process ended while it played): felt in part,
  counted once, here and not under played;
- ``cancelled``: dropped by a cancel before it started (a ``cancelled`` event
  without ``started``, or refused as ``cancelled`` on arrival: a stroke of a
  drawing stopped before it came);
- ``refused``: refused on arrival for any other reason (the wearer's ``paused`` and
  ``do_not_disturb`` too: never felt), or kept from playing by the duty-cycle cap (a
  ``safety`` event ``duty_cycle``).

A broker restart or a Stop makes the sleeve answer some strokes twice: the broker
delivers again a stroke whose acknowledgement was lost, and the copy is refused
(``duplicate``, or ``cancelled`` once its drawing was stopped). A copy's refusal never
changes a fate the stroke already has: the stroke's own events rank above any refusal
(cut, then played, then cancelled or capped), and of two refusals the first stands.
A ``duplicate`` of a stroke with no fate yet (its own event was lost) gives the fate
its ``original_played`` says: played, or refused (also when a sleeve older than the
field leaves it out: nothing says it was felt).

The page adds one fate no sleeve sees: ``never sent`` (dropped before it left, by Stop
or the sender's late limit). ``web/src/fates.ts`` is the page's copy of this rule;
``testdata/events/fates`` keeps the two equal.

How the sleeve kept a drawing in time (``CatchUp``, docs/protocol.md, "Catching up"): of
the strokes played, how many it played faster to catch up with the pen (their
``played`` event's ``compressed_ms``) and by how much in all, and how many it slowed to
its floor (``adjusted``); of the refused, how many it skipped as ``late``. A stroke counts
as played faster or slowed only when its duration changed by ``NOTABLE_CHANGE`` (5 %) or
more of the duration it came with: a stroke of a drawing played as drawn waits a few ms
behind the one before it (the network's jitter) and is played that much faster, which no
one feels (the page's notes leave out an adjustment below the same 5 %). The page's card,
``up``'s line and ``send --wait`` say it in the words of ``CatchUp.played_words``.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal

from feelmysign.events import Adjusted, Cancelled, Event, Played, Rejected, Safety
from feelmysign.protocol import CANCELLED, DUPLICATE, LATE

Fate = Literal["played", "cut", "cancelled", "refused"]
FATES: tuple[Fate, ...] = ("played", "cut", "cancelled", "refused")
DUTY_CYCLE = "duty_cycle"
# A change of a stroke's duration below this share of the duration it came with is not said:
# no one feels it (web/src/events.ts NOTABLE_ADJUSTMENT, for the page's notes, is the same).
NOTABLE_CHANGE = 0.05

# How much an event says about its stroke: a higher rank replaces a lower one, an equal one
# never does (the first refusal stands).
_COPY, _REFUSAL, _OWN, _PLAYED, _CUT = 1, 2, 3, 4, 5


def _notable(ms: float, event: Played) -> float:
    """``ms`` when it is ``NOTABLE_CHANGE`` or more of the duration the stroke of ``event`` came
    with (``duration_ms`` plus what catching up took off it), else 0 (no one feels it)."""
    came_ms = event.duration_ms + (event.compressed_ms or 0.0)
    return ms if ms > 0 and ms >= NOTABLE_CHANGE * came_ms else 0.0


def caught_up_ms(event: Played) -> float:
    """How much shorter the stroke of ``event`` played to catch up with its drawing; 0 when
    it played as it came or the change is below ``NOTABLE_CHANGE`` (no one feels it)."""
    return _notable(event.compressed_ms or 0.0, event)


def waited_ms(event: Played) -> float:
    """How long the stroke of ``event`` waited behind the strokes before it; 0 when that wait is
    below ``NOTABLE_CHANGE`` of its duration as it came (a few ms of the network's jitter)."""
    return _notable(event.queued_ms, event)


@dataclass(frozen=True)
class CatchUp:
    """How the sleeve kept one drawing in time: ``compressed`` strokes played faster to catch
    up, ``compressed_ms`` shorter in all; ``slowed`` strokes slowed to its floor (each counted
    under played), and ``late`` strokes skipped (counted under refused)."""

    compressed: int = 0
    compressed_ms: float = 0.0
    slowed: int = 0
    late: int = 0

    @classmethod
    def of(cls, played: Iterable[Played], late: int) -> CatchUp:
        """From the ``played`` (or ``adjusted``) events of the strokes played, each once, and
        the number of strokes refused as ``late``; changes below ``NOTABLE_CHANGE`` left out."""
        compressed, compressed_ms, slowed = 0, 0.0, 0
        for event in played:
            shorter_ms = caught_up_ms(event)
            if shorter_ms:
                compressed += 1
                compressed_ms += shorter_ms
            if isinstance(event, Adjusted):
                asked_ms = event.requested_duration_ms
                slowed += abs(event.duration_ms - asked_ms) >= NOTABLE_CHANGE * asked_ms
        return cls(compressed, compressed_ms, slowed, late)

    def played_words(self) -> str:
        """What to say of the strokes played, in brackets after their count: "3 faster to
        catch up, 210 ms shorter in all; 1 slowed to the sleeve's floor" ("": none)."""
        words = []
        if self.compressed:
            words.append(
                f"{self.compressed} faster to catch up, "
                f"{duration_words(self.compressed_ms)} shorter in all"
            )
        if self.slowed:
            words.append(f"{self.slowed} slowed to the sleeve's floor")
        return "; ".join(words)


def duration_words(ms: float) -> str:
    """A duration as the page writes one (events.ts ``seconds``): whole ms below a second, else
    seconds to a tenth; halves rounded up, as JavaScript's ``Math.round`` does."""
    if ms >= 1000:
        return f"{math.floor(ms / 100 + 0.5) / 10:.1f} s"
    return f"{math.floor(ms + 0.5)} ms"


def verdict(event: Event, played_before: bool) -> tuple[int, Fate, str | None] | None:
    """What ``event`` says of its stroke: (rank, fate, refusal reason); None when it says
    nothing (an error, a safety off outside any stroke). ``played_before``: the stroke's
    fate so far is played (a lost chip then cuts it)."""
    if isinstance(event, Played | Adjusted):
        return _PLAYED, "played", None
    if isinstance(event, Cancelled):
        return (_CUT, "cut", None) if event.started else (_OWN, "cancelled", None)
    if isinstance(event, Safety):
        if event.received_at_ms is None:
            return None  # a motor protected outside any stroke (off_failed)
        if event.reason != DUTY_CYCLE and played_before:
            return _CUT, "cut", None  # a lost chip cut it after its played event
        return _OWN, "refused", event.reason
    if isinstance(event, Rejected):
        if event.reason == DUPLICATE:
            if event.original_played:
                return _COPY, "played", None
            return _COPY, "refused", DUPLICATE
        if event.reason == CANCELLED:
            return _REFUSAL, "cancelled", None
        return _REFUSAL, "refused", event.reason
    return None


class DrawingFates:
    """The fates of one drawing's strokes, events in (each once: copies of an event are the
    caller's to drop), counts out. Strokes without a seq cannot be told apart: each of
    their events is a stroke of its own."""

    def __init__(self) -> None:
        self._by_seq: dict[int, tuple[int, Fate, str | None]] = {}
        self._unnamed: list[tuple[int, Fate, str | None]] = []
        # The played event that gave a stroke its fate played, by seq (and of unnamed strokes).
        self._played: dict[int, Played] = {}
        self._played_unnamed: list[Played] = []

    def add(self, event: Event) -> Fate | None:
        """Takes ``event`` into account; the stroke's fate now (None: it says nothing)."""
        seq = getattr(event, "seq", None)
        known = self._by_seq.get(seq) if seq is not None else None
        said = verdict(event, known is not None and known[1] == "played")
        if said is None:
            return known[1] if known is not None else None
        played = event if isinstance(event, Played) else None
        if seq is None:
            self._unnamed.append(said)
            if played is not None:
                self._played_unnamed.append(played)
            return said[1]
        if known is None or said[0] > known[0]:
            self._by_seq[seq] = said
            if played is not None:
                self._played[seq] = played
            else:
                self._played.pop(seq, None)
            return said[1]
        return known[1]

    def fate(self, seq: int) -> Fate | None:
        known = self._by_seq.get(seq)
        return None if known is None else known[1]

    def fates(self) -> dict[int, Fate]:
        return {seq: known[1] for seq, known in sorted(self._by_seq.items())}

    def counts(self) -> dict[Fate, int]:
        """How many strokes have each fate, every fate named (0 included)."""
        counts: dict[Fate, int] = dict.fromkeys(FATES, 0)
        for _, fate, _ in [*self._by_seq.values(), *self._unnamed]:
            counts[fate] += 1
        return counts

    def refusals(self) -> Counter[str]:
        """The refused strokes by reason, in the order first met."""
        return Counter(
            reason
            for _, fate, reason in [*self._by_seq.values(), *self._unnamed]
            if fate == "refused" and reason is not None
        )

    def catch_up(self) -> CatchUp:
        """Of the strokes played (by their own played event), those played faster to catch up
        and those slowed; of the refused, those skipped as ``late``."""
        played = [event for seq, event in self._played.items() if self._by_seq[seq][1] == "played"]
        return CatchUp.of([*played, *self._played_unnamed], self.refusals()[LATE])

    @property
    def answered(self) -> int:
        """Strokes with a fate."""
        return len(self._by_seq) + len(self._unnamed)
