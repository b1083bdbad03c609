"""The player, in its real thread, on the simulator: order, continuity, refusals, all off."""

from __future__ import annotations

import itertools
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import Any

import pytest

from feelmysign.backends.sim import SimBackend
from feelmysign.backends.telemetry import ActuatorTelemetry
from feelmysign.clock import monotonic_ms, wall_ms
from feelmysign.events import Event, StrokeRef
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.player import PlannedStroke, Player
from feelmysign.sleeve.queue import SeenSeqs
from feelmysign.stroke import Stroke

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)


class Events:
    def __init__(self) -> None:
        self.items: list[dict[str, Any]] = []
        self.changed = threading.Condition()

    def __call__(self, event: Event) -> None:
        with self.changed:
            self.items.append(event.to_json())
            self.changed.notify_all()

    def wait_for(self, count: int, timeout_s: float = 10.0) -> list[dict[str, Any]]:
        with self.changed:
            assert self.changed.wait_for(lambda: len(self.items) >= count, timeout_s), self.items
            return list(self.items)


def _planned(
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    duration_ms: float,
    received: tuple[float, float] | None = None,
    **info: Any,
) -> PlannedStroke:
    """The stroke, planned, received now or at ``received`` (monotonic ms, wall-clock ms)."""
    schedule = plan(Stroke((x0, y0), (x1, y1), duration_ms), PAPER)
    received_at_ms, received_wall_ms = received or (monotonic_ms(), wall_ms())
    return PlannedStroke(
        schedule, received_at_ms, StrokeRef(**info, received_at_ms=received_wall_ms)
    )


def new_player() -> tuple[Player, SimBackend, Events]:
    """A player on the paper sleeve's simulator, recording its events; not started yet."""
    backend = SimBackend(PAPER)
    events = Events()
    return Player(backend, PAPER, on_event=events), backend, events


@contextmanager
def started_player() -> Iterator[tuple[Player, SimBackend, Events]]:
    """A :func:`new_player`, started; stopped and its simulator closed after."""
    player, backend, events = new_player()
    player.start()
    try:
        yield player, backend, events
    finally:
        player.stop()
        backend.close()


@pytest.fixture
def running() -> Iterator[tuple[Player, SimBackend, Events]]:
    with started_player() as started:
        yield started


def test_strokes_of_a_drawing_play_back_to_back(running: Any) -> None:
    player, backend, events = running
    square = [(0, 0, 3, 0), (3, 0, 3, 2), (3, 2, 0, 2), (0, 2, 0, 0)]
    # All four received at one time, so each is due when the one before ends however long
    # a busy machine takes to submit them (a stroke received after the one before ended is
    # due at once). How late the player's thread writes the first commands is a figure of
    # `make bench`, not something a test can hold a loaded machine to.
    received = (monotonic_ms(), wall_ms())
    for seq, (x0, y0, x1, y1) in enumerate(square):
        stroke = _planned(x0, y0, x1, y1, 150, received, drawing="d", seq=seq)
        assert player.submit(stroke) is None
    played = events.wait_for(4)
    assert [e["seq"] for e in played] == [0, 1, 2, 3]
    assert played[0]["queued_ms"] == 0
    for before, after in itertools.pairwise(played):
        # Back to back: due as the one before ends, and never started before it is due.
        # (To a microsecond: a wall-clock time in ms near 1.8e12 is a float 2.4e-4 ms apart.)
        due_ms = before["start_at_ms"] + before["duration_ms"]
        assert after["start_at_ms"] == pytest.approx(due_ms, abs=1e-3)
        assert after["start_error_ms"] >= 0
        # Behind their drawing, so played faster to catch up, by what the event says.
        assert after["duration_ms"] + after["compressed_ms"] == pytest.approx(150.0)
    _wait_idle(player)
    assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]
    assert {(c.row, c.column) for c in backend.changes} >= {(0, 0), (0, 3), (2, 3), (2, 0)}


def test_copies_are_refused_gaps_never_wait_and_a_stroke_after_later_ones_still_plays(
    running: Any,
) -> None:
    player, _, events = running
    assert player.submit(_planned(0, 0, 1, 0, 100, drawing="d", seq=0)) is None
    assert player.submit(_planned(1, 0, 2, 0, 100, drawing="d", seq=2)) is None  # 1 not yet
    assert player.submit(_planned(2, 0, 3, 0, 100, drawing="d", seq=3)) is None
    duplicate = player.submit(_planned(1, 0, 2, 0, 100, drawing="d", seq=2))
    assert duplicate is not None and duplicate.reason == "duplicate"
    assert player.seen("d", 0) and not player.seen("d", 1)
    # Stroke 1 comes after 2 and 3 (a broker that failed over delivers it again): it was
    # delivered as far as its sender knows, so it plays, once.
    assert player.submit(_planned(0, 0, 1, 0, 100, drawing="d", seq=1)) is None
    again = player.submit(_planned(0, 0, 1, 0, 100, drawing="d", seq=1))
    assert again is not None and again.reason == "duplicate"
    assert [e["seq"] for e in events.wait_for(4)] == [0, 2, 3, 1]


def test_a_stroke_settled_without_playing_is_a_duplicate_when_it_comes_again(
    running: Any,
) -> None:
    player, _, _ = running
    player.remember("d", 7)
    refusal = player.submit(_planned(0, 0, 1, 0, 100, drawing="d", seq=7))
    assert refusal is not None and refusal.reason == "duplicate"
    assert "already played or refused" in refusal.message
    assert not player.seen("d", 6) and not player.seen("e", 7)


def test_the_seqs_seen_are_kept_as_ranges() -> None:
    seqs = SeenSeqs()
    order = [5, 0, 1, 3, 2, 9, 4, 7, 8]
    for seq in order:
        assert seq not in seqs
        seqs.add(seq)
        assert seq in seqs
    assert {s for s in range(12) if s in seqs} == set(order)
    assert seqs.ranges == 2  # 0..5 and 7..9
    seqs.add(6)
    assert seqs.ranges == 1 and 6 in seqs and 10 not in seqs and -1 not in seqs


def test_a_full_queue_refuses_with_the_limits_in_the_message() -> None:
    backend = SimBackend(PAPER)
    player = Player(backend, PAPER, max_pending=2, max_backlog_ms=60_000)
    player.start()
    try:
        results = [player.submit(_planned(0, 0, 3, 0, 2000)) for _ in range(4)]
        assert results[0] is None and results[1] is None
        refusals = [r for r in results if r is not None]
        assert refusals and all(r.reason == "queue_full" for r in refusals)
        assert "at most 2 strokes" in refusals[0].message
    finally:
        player.stop()
        backend.close()


def test_stop_mid_stroke_leaves_every_motor_off(running: Any) -> None:
    player, backend, events = running
    player.submit(_planned(0, 0, 3, 2, 5000))
    events.wait_for(1)
    assert any(any(row) for row in backend.snapshot())
    player.stop()
    assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]


def test_adjusted_strokes_say_so(running: Any) -> None:
    player, _, events = running
    player.submit(_planned(0, 0, 3, 2, 50))
    (event,) = events.wait_for(1)
    assert event["type"] == "adjusted" and event["reason"] == "too_fast"
    assert event["duration_ms"] > event["requested_duration_ms"] == 50


def _wait_idle(player: Player, timeout_s: float = 10.0) -> None:
    deadline = monotonic_ms() + timeout_s * 1000
    while not player.idle:
        assert monotonic_ms() < deadline, "player never went idle"
        threading.Event().wait(0.01)


def test_a_player_that_crashes_mid_stroke_switches_every_motor_off_first(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from feelmysign.timeline import Timeline

    player, backend, events = new_player()
    real_pop_due = Timeline.pop_due

    def pop_due_then_crash(self: Timeline, now_ms: float) -> Any:
        if any(any(row) for row in backend.snapshot()):  # a motor is on: now crash
            raise RuntimeError("a bug in the player")
        return real_pop_due(self, now_ms)

    monkeypatch.setattr(Timeline, "pop_due", pop_due_then_crash)
    player.start()
    try:
        assert player.submit(_planned(0, 0, 3, 0, 2000, drawing="crash", seq=0)) is None
        told = events.wait_for(2)
    finally:
        player.stop()
    assert [e["type"] for e in told] == ["played", "error"]
    assert told[1]["reason"] == "player_crashed"
    assert any(change.intensity > 0 for change in backend.changes)  # it did play
    assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]  # and ended all off
    assert backend.changes[-1].intensity == 0.0
    backend.close()


class _WaitsSeen(threading.Event):
    """An Event that keeps every timeout the player's loop waits with."""

    def __init__(self) -> None:
        super().__init__()
        self.timeouts: list[float | None] = []

    def wait(self, timeout: float | None = None) -> bool:
        self.timeouts.append(timeout)
        return super().wait(timeout)


def test_the_loop_goes_round_at_least_once_an_idle_wait_during_a_long_command() -> None:
    """systemd's watchdog hears from the sleeve only while the player's loop goes round."""
    from feelmysign.player import IDLE_WAIT_S

    backend = SimBackend(PAPER)
    player = Player(backend, PAPER)
    waits = _WaitsSeen()
    player._wake = waits
    player.start()
    try:
        # One motor, on for 4 s: its off is the only thing due for seconds.
        assert player.submit(_planned(0, 0, 0, 0, 4000.0)) is None
        event = threading.Event()
        for _ in range(2000):  # 100 s at most; a few seconds on any machine
            if len([t for t in waits.timeouts if t is not None and t > 0.2]) >= 3:
                break
            event.wait(0.05)
        assert player.alive(max_age_s=60.0)
    finally:
        player.stop()
        backend.close()
    assert max(t for t in waits.timeouts if t is not None) <= IDLE_WAIT_S


class _ThreadsSeen(SimBackend):
    """The simulator, keeping which thread wrote each command."""

    def __init__(self, layout: Layout) -> None:
        super().__init__(layout)
        self.writers: list[int] = []

    def set_intensity(self, row: int, column: int, intensity: float) -> None:
        self.writers.append(threading.get_ident())
        super().set_intensity(row, column, intensity)


def test_a_stroke_for_an_idle_player_starts_on_the_thread_that_submits_it() -> None:
    """No thread switch between a stroke's receipt and its first motor; the player's thread
    plays the rest, and the stroke plays as it would have."""
    backend = _ThreadsSeen(PAPER)
    events = Events()
    player = Player(backend, PAPER, on_event=events)
    player.start()
    try:
        _wait_idle(player)
        threading.Event().wait(0.05)  # the player's thread is asleep, between rounds
        assert player.submit(_planned(0, 0, 3, 0, 300, drawing="here", seq=0)) is None
        first_writer = backend.writers[0] if backend.writers else None
        (event,) = events.wait_for(1)
        _wait_idle(player)
        last_writer = backend.writers[-1]  # its last off
    finally:
        player.stop()
    assert first_writer == threading.get_ident()
    assert event["type"] == "played" and event["seq"] == 0
    assert last_writer != threading.get_ident()  # written by the player's thread
    assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]
    reference = SimBackend(PAPER)  # the same stroke, played by the player's thread alone
    alone = Player(reference, PAPER)
    alone._play_lock.acquire()  # as when the player's thread is in a round
    alone.start()
    try:
        assert alone.submit(_planned(0, 0, 3, 0, 300, drawing="there", seq=0)) is None
        alone._play_lock.release()
        _wait_idle(alone)
    finally:
        alone.stop()
    written = [(c.row, c.column, c.intensity) for c in backend.changes]
    assert written == [(c.row, c.column, c.intensity) for c in reference.changes]
    backend.close()
    reference.close()


def test_a_crash_on_the_submitting_thread_switches_every_motor_off_and_stops_the_player(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from feelmysign.timeline import Timeline

    player, backend, events = new_player()
    real_complete = Timeline.complete

    def complete_then_crash(self: Timeline) -> None:
        if any(any(row) for row in backend.snapshot()):  # a motor is on: now crash
            raise RuntimeError("a bug in the player")
        real_complete(self)

    monkeypatch.setattr(Timeline, "complete", complete_then_crash)
    player.start()
    try:
        _wait_idle(player)
        assert player.submit(_planned(0, 0, 3, 0, 2000, drawing="crash", seq=0)) is None
        (told,) = events.wait_for(1)
        assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]  # off before submit returned
        refusal = player.submit(_planned(0, 0, 3, 0, 2000, drawing="crash", seq=1))
    finally:
        player.stop()
    assert told["type"] == "error" and told["reason"] == "player_crashed"
    assert any(change.intensity > 0 for change in backend.changes)  # it did start
    assert refusal is not None and refusal.reason == "player_stopped"
    backend.close()


class _HungBus(SimBackend):
    """The simulator whose first motor write hangs until ``release`` (a bus that stopped
    answering mid-write), counting the all-offs asked of it."""

    def __init__(self, layout: Layout) -> None:
        super().__init__(layout)
        self.hanging = threading.Event()
        self.release = threading.Event()
        self.all_offs = 0

    def set_intensity(self, row: int, column: int, intensity: float) -> None:
        if intensity > 0 and not self.release.is_set():
            self.hanging.set()
            self.release.wait()
        super().set_intensity(row, column, intensity)

    def all_off(self) -> None:
        self.all_offs += 1
        super().all_off()


def test_stop_switches_every_motor_off_while_a_write_on_the_submitting_thread_hangs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The submitting thread holds the player's lock while it writes a stroke's first
    command; a write that never returns must not keep stop from switching every motor off."""
    monkeypatch.setattr("feelmysign.player.STOP_WAIT_S", 0.1)
    backend = _HungBus(PAPER)
    player = Player(backend, PAPER)
    player.start()
    _wait_idle(player)
    opened_offs = backend.all_offs
    submitter = threading.Thread(
        target=player.submit, args=(_planned(0, 0, 3, 0, 300, drawing="hung", seq=0),)
    )
    submitter.start()
    try:
        assert backend.hanging.wait(10.0), "the first write never started"
        player.stop()
        offs_while_hung = backend.all_offs - opened_offs
    finally:
        backend.release.set()
        submitter.join(10.0)
    assert offs_while_hung >= 1
    assert not submitter.is_alive()
    backend.close()


class _Grids(ActuatorTelemetry):
    """Telemetry that keeps every grid it is told of (its publisher is never called here)."""

    def __init__(self) -> None:
        super().__init__(lambda frame: None)
        self.grids: list[list[list[float]]] = []

    def update(self, grid: Sequence[Sequence[float]]) -> None:
        self.grids.append([list(row) for row in grid])
        super().update(grid)


def test_the_telemetry_hears_of_a_burst_once_all_its_motors_are_on() -> None:
    """Inside a cell, a stroke's first burst drives the cell's four corners: they are written
    one after the other, and the telemetry (whose update wakes its thread) is told after the
    fourth, once, with all four on: never a grid with the burst half written."""
    telemetry = _Grids()
    backend = SimBackend(PAPER, telemetry=telemetry)
    player = Player(backend, PAPER)
    player.start()
    try:
        assert player.submit(_planned(0.5, 0.5, 1.5, 1.5, 300.0, drawing="d", seq=0)) is None
        first = backend.changes[:4]
    finally:
        player.stop()
        backend.close()
    assert {(c.row, c.column) for c in first} == {(0, 0), (0, 1), (1, 0), (1, 1)}
    assert all(c.intensity > 0 for c in first)
    driven = [sum(1 for row in grid for value in row if value > 0) for grid in telemetry.grids]
    assert driven[0] == 4, driven
    # Every change reached the telemetry: its last grid is the final all-off.
    assert all(value == 0.0 for row in telemetry.grids[-1] for value in row)
