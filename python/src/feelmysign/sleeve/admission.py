"""Whether an arriving stroke is played: the sleeve's admission rules, in their one order.

A message on the sleeve's strokes topic (or the legacy one) meets these rules in
this order; the first that refuses decides, and its reason code
(:mod:`feelmysign.protocol`) is what the sleeve's event says:

1. ``retained``: a message the broker kept would play again at every start;
2. the payload (:func:`feelmysign.protocol.parse` and its reasons);
3. ``cancelled``: a stroke of a drawing cancelled lately (a ``cancelled`` event);
4. ``held``: a copy of a stroke accepted and still waiting to play, when the copy
   can be acknowledged later (QoS 1): it waits with the original, and no event
   is published for it;
5. ``duplicate``: a copy of a stroke played or refused before;
6. ``rate_limited``: more than ``rate_per_s`` on average (bursts of ``burst``);
7. the plan (:func:`feelmysign.planner.outline` and its reasons);
8. the pace (:mod:`feelmysign.pace`): ``stale``, then ``late``.

Copies (3 to 5) come before the rate limit and the pace so that a copy counts
for neither and is reported as what it is. Then the player places the stroke
(``queue_full``: :func:`queue_full`, ``player_stopped``), and the duty-cycle cap
is checked when the stroke starts, in the timeline (a ``safety`` event).

Pure: no MQTT, no clock, no thread. Times come in as arguments, and what only the
queue knows (is a copy's original still waiting, was this seq seen, how long
would a stroke wait) is asked of a :class:`QueueState`: the player answers under
its lock, a simulation from its own :class:`feelmysign.sleeve.queue.Queue`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import replace
from typing import NamedTuple, Protocol

from feelmysign.errors import StrokeError
from feelmysign.events import StrokeRef
from feelmysign.layout import Layout
from feelmysign.pace import MAX_AGE_MS, MAX_LAG_MS, PacePolicy
from feelmysign.planner import Outline, outline
from feelmysign.protocol import (
    CANCELLED,
    DUPLICATE,
    HELD,
    RATE_LIMITED,
    RETAINED,
    Accepted,
    parse,
)
from feelmysign.sleeve.queue import CancelledDrawings

RATE_PER_S = 30.0  # sustained strokes per second; a fast drawing sends about 10
MAX_PENDING = 256  # strokes accepted and not yet started
MAX_BACKLOG_MS = 30_000.0  # a touch felt later than this after it arrived is no longer the sender's
# Strokes accepted at once: as many as the player may hold, so that a drawing the broker
# kept for a sleeve that was away is not rate-limited on its return.
BURST = MAX_PENDING

RETAINED_MESSAGE = (
    "a retained stroke is not played: publish strokes without "
    "the retain flag, and clear this one with an empty retained message"
)


class QueueState(Protocol):
    """What admission asks of the sleeve's queue about a stroke arriving at ``now_ms``."""

    def waiting(self, drawing: object, seq: object, now_ms: float) -> bool:
        """Accepted and not yet started (nor dropped): a copy of it waits with it."""
        ...

    def seen(self, drawing: object, seq: object) -> bool:
        """Accepted or settled before: a copy of it is a duplicate."""
        ...

    def wait_ms(self, now_ms: float) -> float:
        """How long a stroke arriving at ``now_ms`` would wait for the strokes before it."""
        ...


# Play it: the stroke's outline (the player plans the rest of it once its first commands are
# out) and what its events name it by. A plain pair: it is made on the path from a stroke's
# message to its first command, and a named tuple's constructor is a Python call.
Admitted = tuple[Outline, StrokeRef]


class Refused(NamedTuple):
    """Not played: why (a reason code of :mod:`feelmysign.protocol`, a sentence), what is
    known of the stroke, and for ``cancelled`` when its drawing's cancel came."""

    reason: str
    message: str
    ref: StrokeRef
    cancelled_at_ms: float | None = None


class TokenBucket:
    """At most ``rate_per_s`` on average, ``burst`` at once (full to start with)."""

    def __init__(self, rate_per_s: float, burst: float) -> None:
        self._rate_per_ms = rate_per_s / 1000.0
        self._burst = burst
        self._tokens = float(burst)
        self._last_ms: float | None = None

    def take(self, now_ms: float) -> bool:
        if self._last_ms is not None:
            gained = (now_ms - self._last_ms) * self._rate_per_ms
            self._tokens = min(self._burst, self._tokens + gained)
        self._last_ms = now_ms
        if self._tokens >= 1.0:
            self._tokens -= 1.0
            return True
        return False


CANCELLED_MESSAGE = "dropped by a control message before it played"
HELD_MESSAGE = "a copy of a stroke waiting to play: it waits with it"


def duplicate_message(drawing: object, seq: object, played: bool | None = None) -> str:
    """The sentence of a ``duplicate`` refusal; ``played``: whether the original started."""
    if played is None:
        return f"stroke {seq} of drawing {drawing} was already played or refused"
    if played:
        return f"stroke {seq} of drawing {drawing} came again; it was played once already"
    return f"stroke {seq} of drawing {drawing} came again; it was not played before either"


def copy_of(
    drawing: str | None,
    seq: int | None,
    now_ms: float,
    holdable: bool,
    cancelled: Mapping[str, float],
    queue: QueueState,
) -> str | None:
    """Rules 3 to 5, on the identity of a stroke arriving at ``now_ms``: ``cancelled``,
    ``held`` (when ``holdable``) or ``duplicate``; None for a stroke met for the first time.
    (Positional: this is on the path from a stroke's message to its first command.)"""
    if drawing is not None and drawing in cancelled:
        # A stroke of a cancelled drawing (one the broker held, or sent just after the cancel).
        return CANCELLED
    if holdable and queue.waiting(drawing, seq, now_ms):
        # The broker's copy of a stroke still waiting to play (the connection dropped before
        # it was acknowledged): acknowledged when the stroke plays, not now, and not checked
        # again (the pace rules and the rate limit took the original).
        return HELD
    if queue.seen(drawing, seq):
        # A copy of a stroke played or refused before, whose acknowledgement was lost (a
        # dropped connection, a failed server).
        return DUPLICATE
    return None


def queue_full(
    pending: int, backlog_ms: float, max_pending: int, max_backlog_ms: float
) -> str | None:
    """Why a stroke placed behind ``pending`` strokes (``backlog_ms`` of them) is refused as
    ``queue_full``; None when there is room."""
    if pending >= max_pending or backlog_ms > max_backlog_ms:
        return (
            f"{pending} strokes ({backlog_ms / 1000:.1f} s) are waiting to play; the sleeve "
            f"keeps at most {max_pending} strokes or {max_backlog_ms / 1000:g} s: send more "
            "slowly"
        )
    return None


class Admission:
    """The state of the rules (cancelled drawings, the rate's bucket, the pace's time lines):
    call ``admit`` once per stroke, in the order they arrive (one thread)."""

    def __init__(
        self,
        layout: Layout,
        *,
        strict: bool = False,
        rate_per_s: float = RATE_PER_S,
        burst: int = BURST,
        max_age_ms: float = MAX_AGE_MS,
        max_lag_ms: float = MAX_LAG_MS,
    ) -> None:
        self.layout = layout
        self.strict = strict
        self.rate_per_s = rate_per_s
        self.burst = burst
        self.cancelled = CancelledDrawings()  # drawing -> when its cancel came (wall clock)
        self._bucket = TokenBucket(rate_per_s, burst)
        self._pace = PacePolicy(max_age_ms=max_age_ms, max_lag_ms=max_lag_ms)
        # The wearer's intensity ceiling (feelmysign.sleeve.controls): a stroke asking more is
        # planned at it, so its phantoms keep their proportions below it.
        self.ceiling: float | None = None

    def remember(self, drawings: Iterable[tuple[str, float]]) -> None:
        """The pace's time lines kept from before a restart (``PacePolicy.remember``)."""
        self._pace.remember(drawings)

    def admit(
        self,
        payload: object,
        topic: str | None,
        legacy: bool,
        retained: bool,
        holdable: bool,
        received_at_ms: float,
        received_wall_ms: float,
        queue: QueueState,
    ) -> Admitted | Refused:
        """The verdict on a message received on ``topic`` at ``received_at_ms`` (the queue's
        clock) and ``received_wall_ms`` (the wall clock the pace compares with the sender's).
        ``legacy``: the payload is read as the legacy format. ``retained``: the broker kept the
        message. ``holdable``: the message can be acknowledged later (QoS 1), so a copy of a
        stroke waiting to play can wait with it. (Positional too: the sleeve calls it on the
        path from a message to its first command.)"""
        if retained:
            return Refused(
                RETAINED, RETAINED_MESSAGE, StrokeRef(topic, received_at_ms=received_wall_ms)
            )
        result = parse(payload, self.layout, format="legacy" if legacy else "json")
        if not isinstance(result, Accepted):
            # Named when its drawing and seq could be read: its sender finds which stroke it was.
            ref = StrokeRef(topic, result.drawing, result.seq, received_at_ms=received_wall_ms)
            return Refused(result.reason, result.message, ref)
        stroke = result.stroke
        drawing, seq, sent_at_ms = stroke.drawing, stroke.seq, stroke.sent_at_ms
        copy = copy_of(drawing, seq, received_at_ms, holdable, self.cancelled, queue)
        if copy is not None:
            ref = StrokeRef(topic, drawing, seq, sent_at_ms, received_at_ms=received_wall_ms)
            if copy == CANCELLED and drawing is not None:
                return Refused(CANCELLED, CANCELLED_MESSAGE, ref, self.cancelled[drawing])
            if copy == HELD:
                return Refused(HELD, HELD_MESSAGE, ref)
            return Refused(DUPLICATE, duplicate_message(drawing, seq), ref)
        if not self._bucket.take(received_at_ms):
            message = (
                f"more than {self.rate_per_s:g} strokes per second (bursts of {self.burst}); "
                "send more slowly"
            )
            ref = StrokeRef(topic, drawing, seq, sent_at_ms, received_at_ms=received_wall_ms)
            return Refused(RATE_LIMITED, message, ref)
        ceiling = self.ceiling
        if ceiling is not None and _asks_above(stroke.intensity, self.layout, ceiling):
            stroke = replace(stroke, intensity=ceiling)
        try:
            # Its bursts only: the commands are planned by the player, the first ones first.
            planned = outline(stroke, self.layout, strict=self.strict)
        except StrokeError as error:
            ref = StrokeRef(topic, drawing, seq, sent_at_ms, received_at_ms=received_wall_ms)
            return Refused(error.reason, error.message, ref)
        start_wall_ms = received_wall_ms + queue.wait_ms(received_at_ms)
        verdict = self._pace.check(
            drawing, sent_at_ms, received_wall_ms, start_wall_ms, planned.duration_ms, seq
        )
        age_ms, lag_ms = verdict.age_ms, verdict.lag_ms
        # Positional: this one is on the path from a stroke's message to its first command.
        ref = StrokeRef(
            topic,
            drawing,
            seq,
            sent_at_ms,
            None if age_ms is None else round(age_ms, 1),
            None if lag_ms is None else round(lag_ms, 1),
            received_wall_ms,
        )
        if verdict.reason is not None:
            return Refused(verdict.reason, verdict.message, ref)
        return planned, ref


def _asks_above(intensity: float | None, layout: Layout, ceiling: float) -> bool:
    """Whether a stroke of ``intensity`` (None: the layout's default) asks more than
    ``ceiling``."""
    return (layout.default_intensity if intensity is None else intensity) > ceiling
