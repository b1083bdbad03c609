"""What the sleeve did with the strokes of one drawing, read from its ``events`` topic.

``feelmysign send --wait`` subscribes before the first stroke goes out and then
waits, with a bound, until each stroke of its drawing has a final answer from
the sleeve: played (``played`` or ``adjusted``), or refused (``rejected``, a
``safety`` event that kept it from playing, a ``cancelled`` one before it
started). A stroke played and later cut (``safety`` ``chip_lost``, ``stopped`` or
``crashed``, ``cancelled`` while playing) is reported as cut; one playing when the sleeve's
status turned offline (its process died: the broker's will) is not counted played, and is
said as not known unless an answer about it comes after. Copies of an event (QoS 1
delivers at least once) are counted once (``EventCopies``). Its summary says too, in the words of
``feelmysign.fates.CatchUp`` (as the page's card and ``up``'s line), how many strokes
the sleeve played faster to catch up with the drawing and by how much in all, how many
it slowed to its floor, and how many it skipped as ``late``.
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from feelmysign.events import (
    Cancelled,
    Event,
    EventCopies,
    EventError,
    Played,
    Rejected,
    Safety,
    event_from_json,
)
from feelmysign.fates import CatchUp
from feelmysign.player import WEARER
from feelmysign.protocol import CANCELLED, LATE
from feelmysign.wearer_status import WEARER_REASONS

if TYPE_CHECKING:
    import paho.mqtt.client as mqtt


@dataclass
class StrokeOutcome:
    """One stroke's answer: its played event, or why it was refused; and a cut after playing."""

    played: Played | None = None
    refused_reason: str | None = None
    refused_message: str | None = None
    cut_reason: str | None = None
    # When the played event arrived (monotonic s): the stroke ends on the skin duration later.
    played_seen_s: float | None = None
    # Cut or dropped by the wearer's pause or stop (a ``cancelled`` event ``"by": "wearer"``),
    # not by a sender's control message.
    by_wearer: bool = False

    # Never sent: the sender stopped once the sleeve refused a stroke as its wearer paused it.
    held: bool = False
    # Playing when the sleeve went offline (its status, the broker's will when its process
    # died): how much was felt is not known here until the sleeve, restarted, says (``crashed``).
    offline: bool = False

    @property
    def final(self) -> bool:
        return self.played is not None or self.refused_reason is not None or self.held


class DrawingOutcome:
    """The answers for the ``count`` strokes (seq 0..count-1) of ``drawing``, from paho's thread.

    ``on_event`` is told of each stroke's first final answer and of a cut, as
    ``(seq, outcome, event_json)``, on paho's thread.
    """

    def __init__(self, drawing: str, count: int, on_event: Any = None) -> None:
        self.drawing = drawing
        self.count = count
        self.strokes = [StrokeOutcome() for _ in range(count)]
        self._condition = threading.Condition()
        self._copies = EventCopies()
        self._on_event = on_event

    def on_message(self, _client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        try:
            event = event_from_json(bytes(message.payload))
        except EventError:
            return  # not an event this reader understands: an older or newer sleeve's
        seq = getattr(event, "seq", None)
        if getattr(event, "drawing", None) != self.drawing or seq is None:
            return
        if not 0 <= seq < self.count:
            return
        with self._condition:
            if self._copies.is_copy(event):
                return
            told = self._record(self.strokes[seq], event)
            if told and isinstance(event, Cancelled) and event.by == WEARER:
                self.strokes[seq].by_wearer = True
            self._condition.notify_all()
        if told and self._on_event is not None:
            self._on_event(seq, self.strokes[seq], event)

    @staticmethod
    def _record(stroke: StrokeOutcome, event: Event) -> bool:
        """Note ``event`` for its stroke; True when it changed what is known of it."""
        if isinstance(event, Played):
            if stroke.final:
                return False
            stroke.played, stroke.played_seen_s = event, time.monotonic()
            return True
        if isinstance(event, Rejected):
            if stroke.final:  # a 'duplicate' for a copy of a stroke already answered
                return False
            stroke.refused_reason, stroke.refused_message = event.reason, event.message
            return True
        if isinstance(event, Safety | Cancelled):
            if stroke.played is not None:
                if stroke.cut_reason is not None:
                    return False
                stroke.cut_reason = event.reason
                return True
            if stroke.final and not _stopped_after_pause(stroke, event):
                return False
            stroke.refused_reason = event.reason
            stroke.refused_message = event.message
            return True
        return False

    def went_offline(self) -> None:
        """The sleeve's status said offline: a stroke it was playing then (its played event
        seen, its time on the skin not over, no cut told) may have been cut; it is not counted
        played, unless an answer about it comes after all."""
        now = time.monotonic()
        with self._condition:
            for stroke in self.strokes:
                if (
                    stroke.played is not None
                    and stroke.played_seen_s is not None
                    and stroke.cut_reason is None
                    and now < stroke.played_seen_s + stroke.played.duration_ms / 1000
                ):
                    stroke.offline = True
            self._condition.notify_all()

    def held_by_wearer(self) -> bool:
        """Whether the sleeve refused a stroke as its wearer paused it (or asked not to be
        disturbed), or the wearer's pause or stop cut or dropped one: what is not sent yet
        would be refused as well."""
        with self._condition:
            return any(s.refused_reason in WEARER_REASONS or s.by_wearer for s in self.strokes)

    def stopped(self) -> bool:
        """Whether a sender's stop (``feelmysign stop``, the page's) cancelled a stroke of the
        drawing: it is over for its sender, so the rest is not sent (a stop of every drawing
        does not refuse later strokes). The wearer's: ``held_by_wearer``."""
        with self._condition:
            return any(
                CANCELLED in (s.refused_reason, s.cut_reason) and not s.by_wearer
                for s in self.strokes
            )

    def hold(self, seqs: range) -> None:
        """These strokes were not sent (the wearer's hold): final, with no answer to wait for."""
        with self._condition:
            for seq in seqs:
                self.strokes[seq].held = True
            self._condition.notify_all()

    def wait_answered(self, deadline_s: float) -> None:
        """Until every stroke has a final answer, or the monotonic ``deadline_s``."""
        with self._condition:
            self._condition.wait_for(
                lambda: all(s.final for s in self.strokes), max(0.0, deadline_s - time.monotonic())
            )

    def felt_by_s(self) -> float | None:
        """When (monotonic s) the last played stroke ends on the skin, as far as known."""
        with self._condition:
            ends = [
                s.played_seen_s + s.played.duration_ms / 1000
                for s in self.strokes
                if s.played is not None and s.played_seen_s is not None
            ]
        return max(ends) if ends else None

    def summary(self) -> DrawingSummary:
        with self._condition:
            # One fate a stroke, as feelmysign.fates counts them: one cut part-way is not played.
            played = [
                s.played
                for s in self.strokes
                if s.played is not None and not s.cut_reason and not s.offline
            ]
            refused = Counter(s.refused_reason for s in self.strokes if s.refused_reason)
            cut = Counter(s.cut_reason for s in self.strokes if s.cut_reason)
            unheard = [i for i, s in enumerate(self.strokes) if not s.final]
            held = [i for i, s in enumerate(self.strokes) if s.held]
            offline = [i for i, s in enumerate(self.strokes) if s.offline and not s.cut_reason]
        catch_up = CatchUp.of(played, refused[LATE])
        return DrawingSummary(
            self.count, len(played), refused, cut, unheard, held, catch_up, offline
        )


@dataclass(frozen=True)
class DrawingSummary:
    count: int
    played: int
    refused: Counter[str]
    cut: Counter[str]
    unheard: list[int]  # seqs with no answer
    held: list[int] = field(default_factory=list)  # seqs not sent: the wearer's hold
    # Played faster to catch up, slowed to the floor, skipped as late (refused[LATE] too).
    catch_up: CatchUp = field(default_factory=CatchUp)
    # seqs playing when the sleeve went offline, with no answer since (``went_offline``)
    offline: list[int] = field(default_factory=list)

    @property
    def all_played(self) -> bool:
        return self.played == self.count and not self.cut and not self.offline

    def text(self) -> str:
        parts = [f"played {self.played} of {self.count} strokes"]
        if pace := self.catch_up.played_words():
            parts[0] += f" ({pace})"
        refused = Counter(self.refused)
        if late := refused.pop(LATE, 0):
            parts.append(f"skipped {late} as late")
        if refused:
            parts.append(f"refused {sum(refused.values())} ({_reasons(refused)})")
        if self.cut:
            parts.append(f"cut {sum(self.cut.values())} part-way ({_reasons(self.cut)})")
        if self.offline:
            numbers = ", ".join(str(seq + 1) for seq in self.offline)
            parts.append(
                f"went offline while it played stroke(s) {numbers}: how much of them was felt "
                "is not known (the sleeve says when it is back: see its log)"
            )
        text = "The sleeve " + ", ".join(parts)
        if self.held:
            text += f"; {len(self.held)} not sent (from stroke {self.held[0] + 1} on)"
        return text


def _stopped_after_pause(stroke: StrokeOutcome, event: Safety | Cancelled) -> bool:
    """The wearer's long press pauses at once and then stops the drawing: a stroke refused
    ``paused`` during the press is then ``cancelled`` by the wearer, the word that stands (as
    in feelmysign.fates, where a stroke's own cancel ranks above a refusal)."""
    return (
        isinstance(event, Cancelled)
        and event.by == WEARER
        and stroke.played is None
        and stroke.refused_reason in WEARER_REASONS
    )


def _reasons(counts: Counter[str]) -> str:
    return ", ".join(f"{reason} x{n}" if n > 1 else reason for reason, n in counts.most_common())
