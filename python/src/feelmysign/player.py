"""The player: plays planned strokes on a backend at their planned times, in one real-time thread.

Strokes play back to back: a stroke that arrives while another is playing
starts the moment the one before it ends (its duration T), so the strokes of
a drawing feel like one continuous touch; a stroke that arrives to an idle
sleeve starts at once. Strokes play in the order they arrive, each ``seq`` of a
drawing once: a copy of a stroke already played or refused (a redelivery) is
dropped as a ``duplicate``, a gap (the sender drops strokes too short to feel)
never waits for the missing one, and a missing one that comes after all still
plays (a broker that fails over delivers a stroke again, after later ones,
when the acknowledgement died with the server or it never reached the
sleeve: the sender was told it was delivered). A copy of a
stroke still waiting to play (the broker sends again what was not acknowledged
when a connection dropped) is not dropped but ``hold``: its acknowledgement
waits for the stroke, so the broker keeps it until it is felt.

A stroke that arrives while the sleeve is behind its own drawing is played
faster, down to the sleeve's floor, so the drawing catches up with the pen
(``catch_up_ms`` in :mod:`feelmysign.sleeve.queue`): it is planned again with
the shorter duration (same path, fewer crossings if they no longer fit), and its
``played`` event says by how much (``compressed_ms``). Such a stroke waits by
definition, so this is never on the path to a first command.

The queue is bounded: a stroke that would start more than ``max_backlog_ms``
from now, or beyond ``max_pending`` strokes not yet started, is refused
(``queue_full``) rather than played late: a touch felt half a minute after it
was drawn is no longer the sender's.

Timing: the thread sleeps until just before the next change and spins the last
``spin_ms``, so writes land within a fraction of a millisecond of the plan;
each write's lateness is kept for ``timing_errors_ms``.

A stroke due at once (an idle sleeve) does not wait for the player's thread to
wake: the thread that submits it writes its first commands itself, through the
same steps under the same lock, and the player's thread plays the rest. Waking a
thread costs tens of microseconds at best and milliseconds on a loaded machine.
"""

from __future__ import annotations

import logging
import sys
import threading
import time
from collections import OrderedDict, deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Any

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.backends.base import Backend
from feelmysign.clock import monotonic_ms
from feelmysign.control import CANCEL_ALL, Cancel
from feelmysign.events import (
    NO_STROKE,
    Adjusted,
    Cancelled,
    ErrorEvent,
    Event,
    Played,
    Rejected,
    Safety,
    StrokeRef,
)
from feelmysign.layout import Layout
from feelmysign.planner import Outline, outline
from feelmysign.protocol import (
    CANCELLED,
    DUPLICATE,
    LATE,
    PLAYER_STOPPED,
    QUEUE_FULL,
    SILENCED,
)
from feelmysign.schedule import Schedule
from feelmysign.sleeve.admission import MAX_BACKLOG_MS, MAX_PENDING, duplicate_message, queue_full
from feelmysign.sleeve.queue import REMEMBERED_CANCELS, Queue
from feelmysign.timeline import Capped, Change, Timeline

log = logging.getLogger(__name__)

SPIN_MS = 0.5  # spin, not sleep, for the last half millisecond: sleep wakes up late
# A thread woken by another waits for the interpreter lock until the running
# thread blocks or this interval passes (5 ms by default): far too long when a
# stroke's first command should follow its message within a millisecond.
SWITCH_INTERVAL_S = 0.0002
STOP_WAIT_S = 5.0  # how long stop waits for a write under way before every motor goes off
IDLE_WAIT_S = 1.0  # nothing planned: wake now and then anyway (stop requests also wake us)
TIMING_SAMPLES = 100_000
# How often a chip that stopped answering is tried again: once it answers, its motor (which
# may have run on, without an enable line) is off within this, well inside a second.
RETRY_LOST_S = 0.2
# How often, with an enable line, the chips whose motors run are read while nothing else is
# written: a wire that comes loose mid-stroke drops the line within this (plus a read).
CHECK_DRIVEN_S = 0.005
WEARER = "wearer"  # the ``by`` of the events of strokes the wearer stopped or paused
STOPPED_MESSAGE = "the wearer stopped this drawing; a new drawing plays"
# The player wakes within a few ms of what is due; on a loaded machine its process can wait
# for a core for half a second. Woken a second or more late, it did not run meanwhile
# (stopped, swapped out): a stroke whose whole time passed then is not played at all (every
# command of it written at once is felt as nothing) but refused as late, and not called
# played. A shorter wait is caught up as before.
STALL_MS = 1000.0


@dataclass
class PlannedStroke:
    """A stroke ready to play, with what the events report about it."""

    # An outline until the player needs the whole schedule: a stroke that starts at once
    # gets its first motors on before the rest of it is planned.
    schedule: Schedule | Outline
    received_at_ms: float  # player clock (monotonic)
    ref: StrokeRef  # which stroke it is, received when by the wall clock: named in its events
    start_ms: float = 0.0
    # Called once the event saying what became of the stroke is out (played, refused by the
    # duty-cycle cap, cancelled): the daemon then acknowledges the message to the broker.
    acknowledge: Callable[[], None] | None = None
    number: int = -1  # the order it was accepted in: a cancel covers those accepted before it
    compressed_ms: float | None = None  # how much shorter it plays to catch up, if it does
    started: bool = False  # its first command went out and its played event with it

    @property
    def received_wall_ms(self) -> float:
        received = self.ref.received_at_ms
        return 0.0 if received is None else received

    def planned(self) -> Schedule:
        """The whole schedule (planned now if it was an outline)."""
        if isinstance(self.schedule, Outline):
            self.schedule = self.schedule.schedule()
        return self.schedule


@dataclass(frozen=True)
class Refusal:
    reason: str
    message: str
    # ``cancelled``: when the cancel came (wall clock ms), and who sent it ("wearer").
    cancelled_at_ms: float | None = None
    by: str | None = None


@dataclass(frozen=True)
class _CancelRequest:
    cancel: Cancel
    accepted_before: int  # strokes numbered below this one were accepted before the cancel
    received_wall_ms: float
    by: str | None = None  # "wearer": the wearer's stop or pause, said in the events
    # The wearer paused (or "do not disturb"): the strokes not yet started are refused for
    # this, not cancelled. None: dropped as cancelled.
    refusal: Refusal | None = None


def _duplicate(drawing: object, seq: object) -> Refusal:
    return Refusal(DUPLICATE, duplicate_message(drawing, seq))


class Player:
    """Call ``start`` once, ``submit`` from any thread, ``stop`` to end with every motor off."""

    def __init__(
        self,
        backend: Backend,
        layout: Layout,
        *,
        on_event: Callable[[Event], None] = lambda event: None,
        clock: Callable[[], float] = monotonic_ms,
        max_pending: int = MAX_PENDING,
        max_backlog_ms: float = MAX_BACKLOG_MS,
        spin_ms: float = SPIN_MS,
        floor_ms: float | None = None,
        stall_ms: float = STALL_MS,
        sleeve_id: str | None = None,
    ) -> None:
        self._backend = backend
        # Its log lines name the sleeve, as the daemon's do ("sleeve <id>: ...").
        self._log_prefix = "" if sleeve_id is None else f"sleeve {sleeve_id}: "
        # How late the player may wake before the strokes whose time passed are refused
        # (a test whose clock jumps ahead to let every stroke play gives math.inf).
        self._stall_ms = stall_ms
        self._timeline = Timeline(layout)
        self._on_event = on_event
        self._clock = clock
        self._max_pending = max_pending
        self._max_backlog_ms = max_backlog_ms
        self._spin_ms = spin_ms
        self._lock = threading.Lock()
        # Held while the timeline is read or changed and while motors are written: by the
        # player's thread for each round of its loop (never while it sleeps), and by a
        # thread that submits a stroke due at once, which then writes its first commands
        # itself (see submit). One writer at a time, so the writes keep their order.
        self._play_lock = threading.Lock()
        self._wake = threading.Event()
        self._inbox: deque[PlannedStroke] = deque()
        self._pending = 0
        # When each stroke starts, and per drawing the seqs accepted or settled (see
        # remember): a copy of one is a duplicate.
        self._queue = Queue()
        self._layout = layout
        # The shortest stroke played without slowing it, or the floor the sleeve advertises
        # (raised to its wearer's measured limits): catching up stops there.
        self._floor_ms = (
            shortest_planned_ms(layout.shortest_burst_ms) if floor_ms is None else floor_ms
        )
        # Accepted, with a drawing and seq, and not yet started, refused or dropped: what a
        # redelivered copy must wait for (see hold).
        self._unplayed: dict[tuple[str, int], PlannedStroke] = {}
        self._running = False
        self._accepted = 0
        self._cancels: list[_CancelRequest] = []
        # The wearer paused the sleeve (or "do not disturb" runs): every stroke is refused so.
        self._refusal: Refusal | None = None
        # Drawings the wearer stopped, each with when: their later strokes are refused as
        # cancelled (checked here, under the lock, as well as on arrival: a stroke admitted
        # just before the stop and placed just after it must not play).
        self._stopped_drawings: OrderedDict[str, float] = OrderedDict()
        self._started_drawing: str | None = None  # the drawing of the stroke started last
        self._thread: threading.Thread | None = None
        self._beat_s = time.monotonic()  # when the player's loop last went round (``alive``)
        self.timing_errors_ms: deque[float] = deque(maxlen=TIMING_SAMPLES)
        self.played = 0
        self.capped = 0
        self.stalled = 0  # strokes refused as late because the player did not run in their time
        self.cut = 0  # strokes cut for a chip that stopped answering
        # Set by stop: the strokes playing when it switched every motor off (cut short by it).
        self.cut_by_stop: list[PlannedStroke] = []
        self._retry_at_s = 0.0  # when the lost chips are tried again next
        self._check_at_s = 0.0  # when the driven chips are read again next

    # --- any thread ------------------------------------------------------------

    def submit(self, stroke: PlannedStroke) -> Refusal | None:
        """Queue a stroke; None when accepted, else why not (nothing is queued then)."""
        drawing, seq = stroke.ref.drawing, stroke.ref.seq
        if not self._running:
            return Refusal(PLAYER_STOPPED, "the sleeve's player has stopped; restart the sleeve")
        if self._silenced():
            return Refusal(SILENCED, self._silenced_message())
        # A stroke that will wait may play faster (catch up): planned before the lock, so the
        # player's thread is not held up meanwhile; checked under the lock (a cancel may have
        # moved the tail since). An idle sleeve's stroke pays one comparison here.
        faster = self._faster(stroke) if self._queue.tail_ms > stroke.received_at_ms else None
        with self._lock:
            if self._stopped_drawings and drawing in self._stopped_drawings:
                at_ms = self._stopped_drawings[drawing]  # type: ignore[index]
                return Refusal(CANCELLED, STOPPED_MESSAGE, at_ms, WEARER)
            if self._refusal is not None:  # under the lock: a pause covers every stroke
                return self._refusal
            if self._queue.seen(drawing, seq):
                return _duplicate(drawing, seq)
            backlog_ms = max(0.0, self._queue.tail_ms - stroke.received_at_ms)
            full = queue_full(self._pending, backlog_ms, self._max_pending, self._max_backlog_ms)
            if full is not None:
                return Refusal(QUEUE_FULL, full)
            duration_ms = stroke.schedule.duration_ms
            if isinstance(drawing, str) and isinstance(seq, int):
                fast_ms = self._queue.catch_up_ms(
                    stroke.received_at_ms, duration_ms, self._floor_ms, drawing
                )
                if fast_ms < duration_ms:  # behind its drawing: it waits, so no first command
                    duration_ms = self._catch_up(stroke, fast_ms, faster)
                self._unplayed[(drawing, seq)] = stroke
                start_ms = self._queue.place(stroke.received_at_ms, duration_ms, drawing, seq)
            else:
                start_ms = self._queue.place(stroke.received_at_ms, duration_ms)
            stroke.start_ms = start_ms
            stroke.number = self._accepted
            self._accepted += 1
            self._pending += 1
            self._inbox.append(stroke)
            due_now = stroke.start_ms <= stroke.received_at_ms
        if due_now:
            self._play_due()
        self._wake.set()  # the player plans its next wake-up (and plays the stroke if we did not)
        return None

    def _faster(self, stroke: PlannedStroke) -> Outline | None:
        """Outside the lock: the stroke planned to catch up with its drawing as the queue stands
        now (a hint: the tail is read without the lock), or None."""
        drawing, given = stroke.ref.drawing, stroke.schedule
        if not isinstance(drawing, str):
            return None
        fast_ms = self._queue.catch_up_ms(
            stroke.received_at_ms, given.duration_ms, self._floor_ms, drawing
        )
        return caught_up(given, fast_ms, self._layout) if fast_ms < given.duration_ms else None

    def _catch_up(self, stroke: PlannedStroke, duration_ms: float, hint: Outline | None) -> float:
        """Under the lock: the stroke planned again to play in ``duration_ms`` (``hint`` when it
        was planned so before the lock, else now); the duration it now plays in."""
        given = stroke.schedule
        if hint is not None and hint.duration_ms == duration_ms:
            faster: Outline | None = hint
        else:
            faster = caught_up(given, duration_ms, self._layout)
        if faster is None:
            return given.duration_ms
        stroke.schedule = faster
        stroke.compressed_ms = round(given.duration_ms - faster.duration_ms, 3)
        return faster.duration_ms

    def _play_due(self) -> None:
        """On the submitting thread: what is due now, written as the player's thread would
        (same steps, same order), so a stroke for an idle sleeve needs no thread switch to
        start. Only when the player is between rounds: when its thread holds the timeline
        (a round, or the spin before a change), it plays the stroke itself right after."""
        if not self._play_lock.acquire(blocking=False):
            return
        try:
            if not self._running:
                return  # stopping: stop() switches every motor off under this lock
            self._take_inbox()
            if self._cancels:  # read without the lock: one appended meanwhile wakes the player
                self._apply_cancels()
            next_ms = self._timeline.next_ms()
            if next_ms is not None and next_ms <= self._clock():
                self._play()
        except Exception:  # as in the player's thread: every motor off, and the player stops
            log.exception(
                "%splayer stopped by an unexpected error; all motors off", self._log_prefix
            )
            self._running = False
            self._on_event(ErrorEvent(reason="player_crashed"))
            try:
                self._backend.all_off()
            except Exception as error:  # a lost chip: stop() tries again and says so
                log.warning("%sall motors off as the player stops: %s", self._log_prefix, error)
        finally:
            self._play_lock.release()

    def hold(self, drawing: object, seq: object, acknowledge: Callable[[], None]) -> bool:
        """A copy of a stroke accepted and not yet played: True, and ``acknowledge`` is called
        when the stroke is done with (played, refused by the duty-cycle cap or cancelled), not
        before. False when no such stroke waits (the copy is then checked like any stroke).

        Acknowledging the copy at once would let the broker forget a stroke that so far only
        this process holds: a ``kill -9`` before it plays would lose it.
        """
        if not isinstance(drawing, str) or not isinstance(seq, int):
            return False
        with self._lock:
            original = self._unplayed.get((drawing, seq))
            if original is None:
                return False
            original.acknowledge = _both(original.acknowledge, acknowledge)
            return True

    def _done(self, stroke: PlannedStroke) -> Callable[[], None] | None:
        """Under the lock: the stroke leaves the unplayed ones; its acknowledgement, to call."""
        drawing, seq = stroke.ref.drawing, stroke.ref.seq
        if isinstance(drawing, str) and isinstance(seq, int):
            self._unplayed.pop((drawing, seq), None)
        return stroke.acknowledge

    def wait_ms(self, now_ms: float) -> float:
        """How long a stroke submitted at ``now_ms`` would wait for the strokes before it."""
        with self._lock:
            return max(0.0, self._queue.tail_ms - now_ms)

    def waiting(self, drawing: object, seq: object, now_ms: float) -> bool:
        """Accepted and not yet started (nor refused or dropped): a copy of it can be held
        (see ``hold``). ``now_ms`` is not needed: the player's thread knows what started."""
        if not isinstance(drawing, str) or not isinstance(seq, int):
            return False
        with self._lock:
            return (drawing, seq) in self._unplayed

    def seen(self, drawing: object, seq: object) -> bool:
        """Accepted or settled before: a copy of it is a duplicate. For checking a copy
        before anything else counts it (the rate limit, the pace rules)."""
        with self._lock:
            return self._queue.seen(drawing, seq)

    def started(self, drawing: object, seq: object) -> bool:
        """Whether this stroke started playing: a ``duplicate`` refusal of a copy says so."""
        with self._lock:
            return self._queue.started(drawing, seq)

    def remember(self, drawing: object, seq: object) -> None:
        """A stroke settled without playing (refused and acknowledged): a copy of it the broker
        delivers again is a ``duplicate`` too, not a second verdict."""
        if isinstance(drawing, str) and isinstance(seq, int):
            with self._lock:
                self._queue.remember(drawing, seq)

    def cancel(self, cancel: Cancel, received_wall_ms: float, *, by: str | None = None) -> None:
        """Cancel the strokes of a drawing (or all) accepted so far, from any thread.

        The player thread wakes at once, switches their motors off, drops those not started,
        and reports each one as ``cancelled`` (``by`` in the events: ``"wearer"`` for the
        wearer's stop); strokes accepted later are not touched.
        """
        with self._lock:
            self._cancels.append(_CancelRequest(cancel, self._accepted, received_wall_ms, by))
        self._wake.set()

    def stop_drawings(self, drawings: Iterable[str], received_wall_ms: float) -> set[str]:
        """The wearer's stop: every stroke accepted so far is cut (playing) or dropped
        (waiting), reported ``cancelled`` by the wearer, and every later stroke of
        ``drawings`` and of the drawings with strokes accepted is refused as ``cancelled``.
        Returns the drawings stopped."""
        with self._lock:
            # The timeline is the player thread's: what waits is in _unplayed, the drawing
            # playing is the last one started.
            stopped = set(drawings) | {drawing for drawing, _ in self._unplayed}
            if self._started_drawing is not None:
                stopped.add(self._started_drawing)
            for drawing in stopped:
                self._stopped_drawings[drawing] = received_wall_ms
                self._stopped_drawings.move_to_end(drawing)
            while len(self._stopped_drawings) > REMEMBERED_CANCELS:
                self._stopped_drawings.popitem(last=False)
            self._cancels.append(
                _CancelRequest(Cancel(CANCEL_ALL), self._accepted, received_wall_ms, WEARER)
            )
        self._wake.set()
        return stopped

    def refuse(self, refusal: Refusal | None, received_wall_ms: float) -> None:
        """The wearer paused the sleeve (or set "do not disturb"): from now on every stroke is
        refused with ``refusal``, and what was accepted before is cut by the next pass of the
        player as a cancel of everything is (the stroke playing reported ``cancelled`` by
        the wearer, the ones waiting refused with ``refusal``). None: strokes play again.

        The refusal and the cut are set under one lock, so no stroke slips between them.
        """
        with self._lock:
            self._refusal = refusal
            if refusal is not None:
                request = _CancelRequest(
                    Cancel(CANCEL_ALL), self._accepted, received_wall_ms, WEARER, refusal
                )
                self._cancels.append(request)
        if refusal is not None:
            # The cut on this thread, as a stroke due at once is played (when the player's
            # thread is between rounds): the motors need not wait for it to wake.
            self._play_due()
        self._wake.set()

    def set_ceiling(self, ceiling: float | None) -> None:
        """The wearer's intensity ceiling: no motor driven above it from its next change."""
        self._timeline.set_ceiling(ceiling)

    def start(self) -> None:
        sys.setswitchinterval(min(sys.getswitchinterval(), SWITCH_INTERVAL_S))
        self._backend.open()
        self._running = True
        self._thread = threading.Thread(target=self._run, name="feelmysign-player", daemon=True)
        self._thread.start()

    def stop(self) -> list[PlannedStroke]:
        """Stop playing and switch every motor off (also when the thread died).

        Returns the strokes accepted but not started, which will never play; those that had
        started and not ended, cut short by the stop, are in ``cut_by_stop`` then.
        """
        self._running = False
        self._hold_low()  # an enable line low at once, before the wait and any I2C "off"
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=STOP_WAIT_S)
        # After any write a submitting thread is making (it saw the player running): that
        # thread checks _running under this lock, so nothing is written after this all-off.
        # A thread stuck in a write (a hung bus) must not keep the motors from going off.
        locked = self._play_lock.acquire(timeout=STOP_WAIT_S)
        try:
            self._backend.all_off()
            stopped_ms = self._clock()
        finally:
            if locked:
                self._play_lock.release()
        with self._lock:
            unstarted = [
                tag for tag in self._timeline.unstarted() if isinstance(tag, PlannedStroke)
            ]
            # (Not one the duty-cycle cap refused at its start: it never played.)
            self.cut_by_stop = [
                tag
                for tag in self._timeline.tags()
                if isinstance(tag, PlannedStroke)
                and tag.started
                and tag.start_ms + tag.schedule.duration_ms > stopped_ms
            ]
            unplayed = list(self._inbox) + unstarted
            self._inbox.clear()
            self._unplayed.clear()  # never acknowledged: the broker sends them again
        return unplayed

    @property
    def idle(self) -> bool:
        with self._lock:
            return not self._inbox and not self._timeline.busy

    # --- the player thread --------------------------------------------------------

    def alive(self, max_age_s: float) -> bool:
        """The player's thread went round its loop in the last ``max_age_s`` (it is not stuck)."""
        thread = self._thread
        fresh = time.monotonic() - self._beat_s <= max_age_s
        return thread is not None and thread.is_alive() and self._running and fresh

    def _run(self) -> None:
        try:
            while self._running:
                self._beat_s = time.monotonic()
                self._wake.clear()
                with self._play_lock:
                    if not self._running:
                        break
                    self._take_inbox()
                    self._apply_cancels()
                    wait_s = self._step()
                    if wait_s is not None:
                        wait_s = self._check_driven(wait_s)
                    if self._lost():
                        wait_s = self._retry_lost(wait_s)
                if wait_s is not None:
                    self._wake.wait(wait_s)
        except Exception:  # the thread must never die with motors on
            log.exception(
                "%splayer stopped by an unexpected error; all motors off", self._log_prefix
            )
            self._on_event(ErrorEvent(reason="player_crashed"))
        finally:
            self._running = False
            self._hold_low()
            # After a write a submitting thread may be making (see stop).
            locked = self._play_lock.acquire(timeout=STOP_WAIT_S)
            try:
                self._backend.all_off()
            except Exception as error:  # a lost chip: stop() tries again and says so
                log.warning("%sall motors off as the player stops: %s", self._log_prefix, error)
            finally:
                if locked:
                    self._play_lock.release()

    def _take_inbox(self) -> None:
        now = self._clock()
        with self._lock:  # a stroke is in the inbox or the timeline, never between (idle)
            while self._inbox:
                stroke = self._inbox.popleft()
                schedule = stroke.schedule
                if isinstance(schedule, Outline) and stroke.start_ms <= now:
                    # Due now: its first commands go out before the rest is planned
                    # (completed right after they are written, see _step).
                    self._timeline.add_outline(schedule, stroke.start_ms, stroke)
                else:
                    self._timeline.add(stroke.planned(), stroke.start_ms, stroke)

    def _apply_cancels(self) -> None:
        with self._lock:
            requests, self._cancels = self._cancels, []
        for request in requests:
            cancel, before = request.cancel, request.accepted_before

            def chosen(tag: object, cancel: Cancel = cancel, before: int = before) -> bool:
                return (
                    isinstance(tag, PlannedStroke)
                    and tag.number < before
                    and cancel.matches(tag.ref.drawing)
                )

            cut = self._timeline.cancel(chosen, self._clock())
            self._write(cut.changes)
            if cancel.everything:
                self._all_off_quietly("cancel everything")  # nothing may run on after it
            with self._lock:
                acknowledgements = self._forget_unstarted(cut.unstarted)
            for tags, started in ((cut.started, True), (cut.unstarted, False)):
                for tag in tags:
                    if isinstance(tag, PlannedStroke):
                        self._on_event(_cut_event(request, tag.ref, started=started))
                        acknowledge = acknowledgements.get(id(tag))  # a started one was
                        if acknowledge is not None:
                            acknowledge()

    def _step(self) -> float | None:
        """Play what is due; else how long to sleep (s) before looking again."""
        next_ms = self._timeline.next_ms()
        if next_ms is None:
            return IDLE_WAIT_S
        wait_ms = next_ms - self._clock() - self._spin_ms
        if wait_ms > 0:
            # Never longer than when idle: the service's watchdog needs the loop to go round.
            return min(wait_ms / 1000.0, IDLE_WAIT_S)  # new strokes may come in: look again
        while self._clock() < next_ms:
            time.sleep(0)  # let the network thread take the interpreter meanwhile
        self._play()
        return None

    def _play(self) -> None:
        """Write everything due now, then plan the rest of the strokes that started."""
        if self._silenced():
            self._refuse_all_silenced()
            return
        now_ms = self._clock()
        self._skip_stalled(now_ms)
        due = self._timeline.pop_due(now_ms)
        written_at_ms = self._clock()  # the first command of a stroke goes out now
        lost = self._write(due.changes)
        self._timeline.complete()  # the rest of a stroke just started, while it plays
        if lost is not None:
            self._chip_lost(*lost, not_yet_played=due.started)
        for tag in due.started:
            if isinstance(tag, PlannedStroke) and not (lost and any(tag is t for t in lost[2])):
                self._started(tag, written_at_ms)
        for capped in due.capped:
            self._capped(capped)

    def _skip_stalled(self, now_ms: float) -> None:
        """Refuse as ``late`` the strokes not yet started whose whole time passed while the
        player did not run (``STALL_MS`` or more late): written now, each would switch its
        motors on and off at once, felt as nothing, and be called played."""
        next_ms = self._timeline.next_ms()
        if next_ms is None or now_ms - next_ms < self._stall_ms:
            return
        missed = {
            id(tag)
            for tag in self._timeline.unstarted()
            if isinstance(tag, PlannedStroke) and tag.start_ms + tag.schedule.duration_ms < now_ms
        }
        if not missed:
            return
        cut = self._timeline.cancel(lambda tag: id(tag) in missed, now_ms)
        self._write(cut.changes)  # (none: they had not started)
        with self._lock:
            acknowledgements = self._forget_unstarted(cut.unstarted)
        stalled_ms = now_ms - next_ms
        refused = [tag for tag in cut.unstarted if isinstance(tag, PlannedStroke)]
        for tag in refused:
            self.stalled += 1
            self._on_event(
                Rejected(
                    reason=LATE,
                    message=(
                        f"not played: the sleeve's player did not run for {stalled_ms:.0f} ms "
                        "(its process was stopped or starved), and the stroke's whole time "
                        "passed meanwhile"
                    ),
                    stroke=stalled_ref(tag, now_ms),
                )
            )
            acknowledge = acknowledgements[id(tag)]
            if acknowledge is not None:
                acknowledge()  # refused, and said so: the broker must not send it again
        log.warning(
            "%sthe player ran %.0f ms late (its process did not run): %d stroke(s) whose time "
            "passed meanwhile refused as late",
            self._log_prefix,
            stalled_ms,
            len(refused),
        )

    def _forget_unstarted(self, unstarted: list[object]) -> dict[int, Callable[[], None] | None]:
        """Under the lock: strokes taken off the timeline before they started leave the pending
        and unplayed ones, and the queue is planned again without them. Their acknowledgements
        (by the tag's id), to call once their event is out."""
        self._pending -= len(unstarted)
        acknowledgements = {
            id(tag): self._done(tag) for tag in unstarted if isinstance(tag, PlannedStroke)
        }
        self._queue.replan(
            (tag.start_ms + tag.schedule.duration_ms, tag.ref.drawing)
            for tag in [*self._timeline.tags(), *self._inbox]
            if isinstance(tag, PlannedStroke)
        )
        return acknowledgements

    def _write(self, changes: list[Change]) -> tuple[Change, str, list[PlannedStroke]] | None:
        """Output ``changes``; a stroke's motor that could not be switched on is a lost chip:
        returns that change, the error and the strokes cut for it (after every motor went off)."""
        lost: tuple[Change, str, list[PlannedStroke]] | None = None
        if not changes:
            return None
        # A recording backend (the simulator) is told whose command each change is.
        note: Callable[[object, object], None] | None = getattr(self._backend, "note_source", None)
        # The telemetry (previews) hears of the changes once they are all written: a burst's
        # motors start together, none waiting for a frame of the ones before it.
        hold: Callable[[], None] | None = getattr(self._backend, "hold_telemetry", None)
        if hold is not None:
            hold()
        try:
            lost = self._write_each(changes, note)
        finally:
            release: Callable[[], None] | None = getattr(self._backend, "release_telemetry", None)
            if release is not None:
                release()
        return lost

    def _write_each(
        self, changes: list[Change], note: Callable[[object, object], None] | None
    ) -> tuple[Change, str, list[PlannedStroke]] | None:
        lost: tuple[Change, str, list[PlannedStroke]] | None = None
        for change in changes:
            if lost is not None and any(change.tag is stroke for stroke in lost[2]):
                continue  # cut, its motors off: nothing of it plays on
            self.timing_errors_ms.append(self._clock() - change.t_ms)
            try:
                if note is not None:
                    ref = change.tag.ref if isinstance(change.tag, PlannedStroke) else NO_STROKE
                    note(ref.drawing, ref.seq)
                self._backend.set_intensity(change.row, change.column, change.intensity)
            except Exception as error:  # a motor that fails must not stop the others
                log.warning(
                    "%sactuator (%d, %d): %s", self._log_prefix, change.row, change.column, error
                )
                self._on_event(
                    ErrorEvent(
                        reason="backend", message=str(error), row=change.row, column=change.column
                    )
                )
                if change.intensity == 0.0 and self._off_again(change):
                    continue  # a glitch: the second "off" went through
                if lost is None:
                    lost = (change, str(error), self._cut_playing())
        if note is not None:
            note(None, None)  # what follows (an all-off at exit) belongs to no stroke
        return lost

    def _cut_playing(self) -> list[PlannedStroke]:
        """Every stroke that has started, cut, and every motor off: a chip that stopped
        answering cannot be trusted to be silent, and a stroke missing a motor is not felt."""
        now = self._clock()
        cut = self._timeline.cancel(
            lambda tag: isinstance(tag, PlannedStroke) and tag.start_ms <= now, now
        )
        # Tries every chip; the lost one fails again (an enable line went low first, at the
        # failed write: every motor, the lost one's included, stopped then).
        self._all_off_quietly("after a lost chip")
        return [tag for tag in cut.started if isinstance(tag, PlannedStroke)]

    def _all_off_quietly(self, when: str) -> None:
        """Every motor off; a chip that does not take it is left to ``_retry_lost``."""
        try:
            self._backend.all_off()
        except Exception as error:
            log.warning("%sall motors off %s: %s", self._log_prefix, when, error)

    # --- chips that stopped answering ---------------------------------------------

    def _hold_low(self) -> None:
        """Stopping: the backend's enable line (if it has one) low, and kept low."""
        hold_low: Callable[[], None] | None = getattr(self._backend, "hold_low", None)
        if hold_low is not None:
            hold_low()

    def _lost(self) -> dict[tuple[int, int], str]:
        """(row, column) -> why, for each chip the backend could not switch off (none for a
        backend that cannot lose one)."""
        lost: dict[tuple[int, int], str] | None = getattr(self._backend, "lost", None)
        return lost or {}

    def _silenced(self) -> bool:
        """An enable line held low for a chip that does not answer: nothing can be felt."""
        return bool(getattr(self._backend, "silenced", False))

    def _silenced_message(self) -> str:
        lost = self._lost()
        describe: Callable[[tuple[int, int]], str] | None = getattr(self._backend, "describe", None)
        chips = "; ".join(describe(key) if describe else str(key) for key in sorted(lost))
        return (
            "the sleeve is silent: its enable line is held low, every motor off, because a "
            f"DRV2605L does not answer ({chips or 'a chip failed its check'}); it cannot be "
            "switched off on its own, so no motor runs until it answers again (check its wire)"
        )

    def _retry_lost(self, wait_s: float | None) -> float | None:
        """Now and then, "off" again to each chip that stopped answering; a ``chip_back``
        event for each that took it. How long the loop may sleep now."""
        now_s = time.monotonic()
        if now_s < self._retry_at_s:
            return min(wait_s if wait_s is not None else 0.0, self._retry_at_s - now_s)
        self._retry_at_s = now_s + RETRY_LOST_S
        retry: Callable[[], list[tuple[int, int]]] | None = getattr(
            self._backend, "retry_lost", None
        )
        back = [] if retry is None else retry()
        for row, column in back:
            log.warning(
                "%sactuator (%d, %d): its chip answers again and is off",
                self._log_prefix,
                row,
                column,
            )
            self._on_event(
                Safety(
                    reason="chip_back",
                    row=row,
                    column=column,
                    message=(
                        "its DRV2605L answers again: switched off at once, and set up again "
                        "for the next stroke"
                        + ("" if not self._silenced() else "; the sleeve is still silent")
                    ),
                )
            )
        return RETRY_LOST_S if wait_s is None else min(wait_s, RETRY_LOST_S)

    def _check_driven(self, wait_s: float) -> float:
        """With nothing due for a while: read the chips whose motors run (a backend with an
        enable line only), and report one that no longer answers as lost. How long the loop
        may sleep now."""
        check: Callable[[], tuple[tuple[int, int], str] | None] | None = getattr(
            self._backend, "check_driven", None
        )
        if check is None or getattr(self._backend, "enable", None) is None:
            return wait_s
        if not self._timeline.busy:
            return wait_s
        now_s = time.monotonic()
        if now_s >= self._check_at_s and wait_s * 1000 > self._spin_ms + 1.0:
            self._check_at_s = now_s + CHECK_DRIVEN_S
            failed = check()
            if failed is not None:
                (row, column), error = failed
                log.warning("%sactuator (%d, %d): %s", self._log_prefix, row, column, error)
                self._on_event(ErrorEvent(reason="backend", message=error, row=row, column=column))
                cut = self._cut_playing()
                self._chip_lost(
                    Change(self._clock(), row, column, 0.0), error, cut, not_yet_played=[]
                )
                return 0.0  # look at the timeline again at once
        return min(wait_s, max(0.0, self._check_at_s - now_s))

    def _refuse_all_silenced(self) -> None:
        """Silenced: every stroke in the timeline is cut and said so, none is called played."""
        cut = self._timeline.cancel(lambda tag: isinstance(tag, PlannedStroke), self._clock())
        message = f"not played: {self._silenced_message()}"
        for tags, fresh in ((cut.started, False), (cut.unstarted, True)):
            for tag in tags:
                if not isinstance(tag, PlannedStroke):
                    continue
                acknowledge = None
                if fresh:
                    with self._lock:
                        self._pending -= 1
                        acknowledge = self._done(tag)
                self.cut += 1
                self._on_event(
                    Safety(reason="silenced", row=0, column=0, message=message, stroke=tag.ref)
                )
                if acknowledge is not None:
                    acknowledge()

    def _chip_lost(
        self, change: Change, error: str, cut: list[PlannedStroke], *, not_yet_played: list[object]
    ) -> None:
        """Each stroke cut for a lost chip: a ``safety`` event naming the chip; one whose first
        command was this step's is never reported played (and is acknowledged here). With no
        stroke cut (the chip was lost switching a motor off), one event naming the chip."""
        if self._silenced():
            after = (
                "The enable line went low first: every motor is off, this one's included, and "
                "the sleeve stays silent until the chip answers again."
            )
        elif getattr(self._backend, "enable", None) is not None:
            after = "The enable line went low first: every motor is off."
        else:
            after = (
                "Every other motor was switched off; this one cannot be (no enable line): it is "
                "tried again until it answers."
            )
        error = error if error.endswith(".") else f"{error}."  # a sentence before the next
        if not cut:
            self._on_event(
                Safety(
                    reason="chip_lost",
                    row=change.row,
                    column=change.column,
                    message=f"{error} {after}",
                )
            )
        for stroke in cut:
            fresh = any(stroke is tag for tag in not_yet_played)
            acknowledge = None
            if fresh:
                with self._lock:
                    self._pending -= 1
                    acknowledge = self._done(stroke)
            self.cut += 1
            when = "before it was felt" if fresh else "part-way, after its played event"
            self._on_event(
                Safety(
                    reason="chip_lost",
                    row=change.row,
                    column=change.column,
                    message=f"cut {when}: {error} {after}",
                    stroke=stroke.ref,
                )
            )
            if acknowledge is not None:
                acknowledge()  # reported, never to play: the broker must not send it again

    def _off_again(self, change: Change) -> bool:
        """An 'off' that failed, tried once more: True when it went through (a glitch); else
        the chip is lost, and every motor goes off (see ``_cut_playing``)."""
        try:
            self._backend.set_intensity(change.row, change.column, 0.0)
        except Exception:
            log.warning(
                "%sactuator (%d, %d) still not off: its chip is lost",
                self._log_prefix,
                change.row,
                change.column,
            )
            return False
        return True

    def _capped(self, capped: Capped) -> None:
        """A stroke the duty-cycle cap kept from playing: said, and never called played."""
        with self._lock:
            self._pending -= 1
            acknowledge = self._done(capped.tag) if isinstance(capped.tag, PlannedStroke) else None
        self.capped += 1
        refusal = capped.refusal
        row, column = refusal.actuator
        window_s = refusal.window_ms / 1000
        ref = capped.tag.ref if isinstance(capped.tag, PlannedStroke) else NO_STROKE
        self._on_event(
            Safety(
                reason="duty_cycle",
                row=row,
                column=column,
                message=(
                    f"not played: motor row {row}, column {column} would have been driven "
                    f"{refusal.duty_cycle:.0%} of the last {window_s:g} s at full drive, above "
                    f"the layout's max_duty_cycle {refusal.max_duty_cycle:.0%}; it needs a rest"
                ),
                stroke=ref,
                duty_cycle=round(refusal.duty_cycle, 4),
                max_duty_cycle=refusal.max_duty_cycle,
                window_ms=refusal.window_ms,
            )
        )
        if acknowledge is not None:
            acknowledge()  # refused, and said so: the broker must not send it again

    def _started(self, stroke: PlannedStroke, now: float) -> None:
        with self._lock:
            stroke.started = True
            self._pending -= 1
            acknowledge = self._done(stroke)
            self._queue.mark_started(stroke.ref.drawing, stroke.ref.seq)
            drawing = stroke.ref.drawing
            self._started_drawing = drawing if isinstance(drawing, str) else None
        self.played += 1
        self._on_event(played_event(stroke, now))
        if acknowledge is not None:
            acknowledge()


def caught_up(given: Schedule | Outline, duration_ms: float, layout: Layout) -> Outline | None:
    """``given`` planned again to play in ``duration_ms`` (shorter, at or above the floor), on
    the same path: crossings that no longer fit are thinned as for any stroke. None when that
    would not be shorter, or would be slowed (below the floor of ``given``'s own bursts)."""
    min_ms = given.min_command_ms if isinstance(given, Outline) else None
    faster = outline(replace(given.stroke, duration_ms=duration_ms), layout, min_command_ms=min_ms)
    if faster.adjusted is not None or faster.duration_ms >= given.duration_ms:
        return None
    return faster


def played_event(stroke: PlannedStroke, written_at_ms: float) -> Played:
    """The ``played`` event (``adjusted`` when the planner slowed it) of a stroke whose first
    command went out at ``written_at_ms`` (the player's clock, as ``received_at_ms``)."""
    schedule = stroke.planned()
    received_wall_ms = stroke.received_wall_ms
    timing: dict[str, Any] = {
        "stroke": stroke.ref,
        "start_at_ms": received_wall_ms + (stroke.start_ms - stroke.received_at_ms),
        "first_command_at_ms": received_wall_ms + (written_at_ms - stroke.received_at_ms),
        "latency_ms": written_at_ms - stroke.received_at_ms,
        "start_error_ms": written_at_ms - stroke.start_ms,
        "queued_ms": stroke.start_ms - stroke.received_at_ms,
        "duration_ms": schedule.duration_ms,
        "commands": len(schedule.commands),
        "compressed_ms": stroke.compressed_ms,
    }
    if schedule.adjusted:
        return Adjusted(
            **timing,
            reason=schedule.adjusted.reason,
            requested_duration_ms=schedule.adjusted.requested_duration_ms,
        )
    return Played(**timing)


def stalled_ref(stroke: PlannedStroke, now_ms: float) -> StrokeRef:
    """What names a stroke refused at ``now_ms`` (the player's clock) because its whole time
    passed while the player did not run: its ``lag_ms`` is how late it was then, as another
    ``late`` refusal's: the lag it was admitted with (behind its sender's time line; 0 without
    ``sent_at_ms``) plus how long after its planned start it was refused."""
    ref = stroke.ref
    lag_ms = (ref.lag_ms or 0.0) + max(0.0, now_ms - stroke.start_ms)
    return replace(ref, lag_ms=round(lag_ms, 1))


def _both(first: Callable[[], None] | None, second: Callable[[], None]) -> Callable[[], None]:
    if first is None:
        return second

    def both() -> None:
        first()
        second()

    return both


def cancelled(
    stroke: StrokeRef, cancelled_at_ms: float, *, started: bool, by: str | None = None
) -> Cancelled:
    """The event for a stroke that a control message received at ``cancelled_at_ms``
    cancelled (``by="wearer"``: the wearer's stop or pause, at that time)."""
    who = "the wearer" if by == WEARER else "a control message"
    return Cancelled(
        message=f"cut short by {who}" if started else f"dropped by {who} before it played",
        stroke=stroke,
        cancelled_at_ms=cancelled_at_ms,
        started=started,
        by=by,
    )


def _cut_event(request: _CancelRequest, stroke: StrokeRef, *, started: bool) -> Event:
    """What a stroke cut by ``request`` is reported as: ``cancelled``, or, not yet started
    when the wearer paused, refused for the pause."""
    if not started and request.refusal is not None:
        refusal = request.refusal
        return Rejected(reason=refusal.reason, message=refusal.message, stroke=stroke)
    return cancelled(stroke, request.received_wall_ms, started=started, by=request.by)
