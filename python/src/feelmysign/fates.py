"""What became of each stroke of a drawing: the one rule that the page, ``up`` and the study
report from, so that their counts agree and add up to the strokes the sleeve answered.

Each stroke has one fate, read from the sleeve's events about it (docs/protocol.md,
"What became of a stroke"):

- ``played``: its ``played`` (or ``adjusted``) event: felt whole;
- ``cut``: cut short by a cancel while it played (a ``cancelled`` event with
  ``started``): felt in part, counted once, here and not under played;
- ``cancelled``: dropped by a cancel before it started (a ``cancelled`` event
  without ``started``, or refused as ``cancelled`` on arrival: a stroke of a
  drawing stopped before it came);
- ``refused``: refused on arrival for any other reason, or kept from playing by the
  duty-cycle cap (a ``safety`` event ``duty_cycle``).

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
"""

from __future__ import annotations

from collections import Counter
from typing import Literal

from feelmysign.events import Adjusted, Cancelled, Event, Played, Rejected, Safety
from feelmysign.protocol import CANCELLED, DUPLICATE

Fate = Literal["played", "cut", "cancelled", "refused"]
FATES: tuple[Fate, ...] = ("played", "cut", "cancelled", "refused")
DUTY_CYCLE = "duty_cycle"

# How much an event says about its stroke: a higher rank replaces a lower one, an equal one
# never does (the first refusal stands).
_COPY, _REFUSAL, _OWN, _PLAYED, _CUT = 1, 2, 3, 4, 5


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

    def add(self, event: Event) -> Fate | None:
        """Takes ``event`` into account; the stroke's fate now (None: it says nothing)."""
        seq = getattr(event, "seq", None)
        known = self._by_seq.get(seq) if seq is not None else None
        said = verdict(event, known is not None and known[1] == "played")
        if said is None:
            return known[1] if known is not None else None
        if seq is None:
            self._unnamed.append(said)
            return said[1]
        if known is None or said[0] > known[0]:
            self._by_seq[seq] = said
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

    @property
    def answered(self) -> int:
        """Strokes with a fate."""
        return len(self._by_seq) + len(self._unnamed)
