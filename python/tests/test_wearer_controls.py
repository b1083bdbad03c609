"""The wearer's controls: pause, stop, ceiling and "do not disturb", kept across restarts.

The player cuts what plays at a pause (one pass, the cancel-everything path) and refuses
the rest; ``WearerControls`` keeps its state in a file, checks what it is given, and
starts paused from a file it cannot read; a sleeve on a thread, through a real Mosquitto,
says it all in its events and its retained status.
"""

from __future__ import annotations

import json
import os
import threading
import time
import uuid
from pathlib import Path
from typing import Any

import pytest
from test_daemon import Running, _sender
from test_player import _planned, started_player

from feelmysign.backends.button import ButtonWatcher
from feelmysign.backends.emulated_button import EmulatedButton
from feelmysign.broker import Broker
from feelmysign.clock import wall_ms
from feelmysign.events import Status
from feelmysign.player import Refusal
from feelmysign.protocol import format_json
from feelmysign.sleeve.controls import (
    MIN_CEILING,
    ControlsError,
    ControlsState,
    WearerControls,
)
from feelmysign.sleeve.presses import DEBOUNCE_MS
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic

WAIT_S = 10.0
PAUSED = Refusal("paused", "the wearer paused the sleeve")


def _wait(condition: Any, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < deadline, what
        time.sleep(0.005)


# --- the player -----------------------------------------------------------------------------


def test_a_pause_cuts_the_stroke_playing_and_refuses_the_rest_until_resumed() -> None:
    with started_player() as (player, backend, events):
        for seq in range(3):
            assert player.submit(_planned(0, 0, 3, 2, 3000, drawing="d", seq=seq)) is None
        events.wait_for(1)  # stroke 0 plays
        _wait(lambda: any(any(row) for row in backend.snapshot()), "no motor came on")
        player.refuse(PAUSED, 1234.5)
        reported = events.wait_for(4)[1:]
        assert [(e["type"], e["seq"]) for e in reported] == [
            ("cancelled", 0),
            ("rejected", 1),
            ("rejected", 2),
        ]
        assert (reported[0]["started"], reported[0]["by"]) == (True, "wearer")
        assert all(e["reason"] == "paused" for e in reported[1:])
        _wait(lambda: player.idle, "the player still has work after the pause")
        assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]
        # Paused: a stroke that comes is refused, and nothing is queued.
        assert player.submit(_planned(0, 0, 1, 0, 100, drawing="d", seq=3)) == PAUSED
        player.refuse(None, 1300.0)
        assert player.submit(_planned(0, 0, 1, 0, 100, drawing="d", seq=4)) is None
        assert events.wait_for(5)[4]["type"] == "played"


def test_the_wearers_ceiling_caps_every_motor() -> None:
    with started_player() as (player, backend, events):
        player.set_ceiling(0.3)
        assert player.submit(_planned(0, 1, 3, 1, 600, drawing="d", seq=0)) is None
        peak = 0.0
        deadline = time.monotonic() + WAIT_S
        while not events.items and time.monotonic() < deadline:
            time.sleep(0.002)
        while not player.idle and time.monotonic() < deadline:
            peak = max(peak, *(max(row) for row in backend.snapshot()))
            time.sleep(0.002)
        assert 0 < peak <= 0.3


# --- the controls and their file -------------------------------------------------------------


class Applied:
    """What the controls asked the sleeve to do."""

    def __init__(self) -> None:
        self.states: list[ControlsState] = []
        self.stops = 0

    def apply(self, state: ControlsState) -> None:
        self.states.append(state)

    def stop(self) -> None:
        self.stops += 1


def controls(path: Path, applied: Applied | None = None) -> WearerControls:
    applied = applied or Applied()
    return WearerControls(str(path), max_intensity=0.9, apply=applied.apply, stop=applied.stop)


def test_a_pause_and_a_ceiling_survive_a_restart(tmp_path: Path) -> None:
    path = tmp_path / "controls.json"
    first = controls(path)
    assert first.state() == ControlsState(paused=False)
    first.pause("button")
    first.pause("page")  # idempotent: paused by the first
    first.set_ceiling(0.6, "page")
    applied = Applied()
    again = controls(path, applied)
    expected = ControlsState(paused=True, paused_by="button", ceiling=0.6)
    assert again.state() == expected
    assert applied.states == [expected]  # in force from the start
    again.resume("button")
    assert controls(path).state() == ControlsState(paused=False, ceiling=0.6)


def test_a_controls_file_unreadable_falls_back_to_its_last_good_copy(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "controls.json"
    controls(path).set_ceiling(0.6, "page")
    path.write_text('{"format": "feelmysign-controls/1", "paused": "maybe"')  # a disk's damage
    state = controls(path).state()
    assert state == ControlsState(paused=False, ceiling=0.6)  # the wearer's choice, whole
    (line,) = [r.getMessage() for r in caplog.records if "last good copy" in r.getMessage()]
    assert str(path) in line and "ceiling 0.6" in line


@pytest.mark.parametrize("last_good", ["missing", "damaged"])
def test_no_readable_controls_start_the_sleeve_paused_with_the_least_ceiling(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, last_good: str
) -> None:
    """Never stronger than the wearer chose: the chosen ceiling is unknown, so the least."""
    path = tmp_path / "controls.json"
    controls(path).set_ceiling(0.6, "page")
    path.write_text('{"format": "feelmysign-controls/1", "paused": "maybe"')
    backup = Path(f"{path}.last-good")
    if last_good == "missing":
        backup.unlink()
    else:
        backup.write_bytes(b"\xff\xfe")
    state = controls(path).state()
    assert state == ControlsState(paused=True, paused_by="sleeve", ceiling=MIN_CEILING)
    (line,) = [r.getMessage() for r in caplog.records if "cannot be read" in r.getMessage()]
    assert str(path) in line and "starting paused" in line and "least ceiling" in line
    assert "sets the ceiling again" in line
    # Resuming writes both files anew, with the ceiling still the least until set again.
    controls(path).resume("page")
    assert controls(path).state() == ControlsState(paused=False, ceiling=MIN_CEILING)
    assert json.loads(backup.read_text())["paused"] is False


@pytest.mark.parametrize("ceiling", [0.0, 0.04, 0.95, float("nan"), True, "0.5"])
def test_a_ceiling_outside_its_range_is_refused_with_the_range(
    tmp_path: Path, ceiling: Any
) -> None:
    wearer = controls(tmp_path / "c.json")
    with pytest.raises(ControlsError, match=f"from {MIN_CEILING:g} to 0.9"):
        wearer.set_ceiling(ceiling, "page")
    assert wearer.state().ceiling is None


@pytest.mark.parametrize(
    ("ahead_ms", "instead"),
    [(-1000, "a later time"), (-1, "a later time"), (25 * 3600 * 1000, "an earlier time")],
)
def test_do_not_disturb_must_end_within_a_day(tmp_path: Path, ahead_ms: int, instead: str) -> None:
    wearer = controls(tmp_path / "c.json")
    with pytest.raises(ControlsError, match=f"within the next 24 hours.*give {instead}"):
        wearer.set_do_not_disturb(round(wall_ms()) + ahead_ms, "page")


def test_do_not_disturb_ends_by_itself_and_says_so(tmp_path: Path) -> None:
    applied = Applied()
    wearer = controls(tmp_path / "c.json", applied)
    told: list[ControlsState] = []
    ended = threading.Event()

    def tell(state: ControlsState) -> None:
        told.append(state)
        ended.set()

    wearer.subscribe(tell)
    until_ms = round(wall_ms()) + 300
    assert wearer.set_do_not_disturb(until_ms, "page").do_not_disturb_until_ms == until_ms
    refusal = wearer.refusal()
    assert refusal is not None and refusal.reason == "do_not_disturb"
    ended.clear()
    assert ended.wait(WAIT_S), "do not disturb never ended"
    assert told[-1].do_not_disturb_until_ms is None and wearer.refusal() is None
    assert controls(tmp_path / "c.json").state().do_not_disturb_until_ms is None


def test_who_changes_the_controls_is_checked(tmp_path: Path) -> None:
    with pytest.raises(ControlsError, match="button, page, cli"):
        controls(tmp_path / "c.json").pause("sender")


def test_the_file_is_written_before_the_call_returns(tmp_path: Path) -> None:
    path = tmp_path / "deep" / "controls.json"
    controls(path).pause("cli")
    saved = json.loads(path.read_text())
    assert (saved["paused"], saved["paused_by"]) == (True, "cli")
    assert oct(os.stat(path.parent).st_mode & 0o777) == "0o700"


# --- the sleeve, through a real Mosquitto --------------------------------------------------


def test_the_sleeve_says_its_controls_in_its_status_and_refuses_while_paused(
    broker: Broker, tmp_path: Path
) -> None:
    running = Running(broker.credentials, controls_path=str(tmp_path / "controls.json"))
    sender = _sender(broker.credentials)
    sid = broker.credentials.sleeve_id
    try:
        drawing = str(uuid.uuid4())

        def send(seq: int, duration_ms: float = 3000.0) -> None:
            stroke = Stroke((0.0, 0.0), (3.0, 2.0), duration_ms, 0.8, drawing, seq)
            sender.publish(strokes_topic(sid), format_json(stroke), qos=1).wait_for_publish(5)

        for seq in range(2):
            send(seq)
        running.wait_events(1)  # stroke 0 plays
        running.sleeve.controls.pause("page")
        send(2)
        events = running.wait_events(4)[1:]
        fates = sorted((e["seq"], e["type"], e.get("reason"), e.get("by")) for e in events)
        assert fates == [
            (0, "cancelled", "cancelled", "wearer"),
            (1, "rejected", "paused", None),
            (2, "rejected", "paused", None),
        ]
        assert "wearer paused" in events[-1]["message"]

        def last_controls() -> dict[str, Any] | None:
            status = Status.from_json(json.dumps(running.status[-1])) if running.status else None
            return None if status is None or status.controls is None else status.controls.to_json()

        _wait(lambda: (last_controls() or {}).get("paused"), "no status said paused")
        assert last_controls() == {
            "paused": True,
            "paused_by": "page",
            "ceiling": None,
            "do_not_disturb_until_ms": None,
        }
        running.sleeve.controls.resume("page")
        _wait(lambda: (last_controls() or {}).get("paused") is False, "no status said resumed")
        send(3, 200.0)
        assert running.wait_events(5)[4]["type"] == "played"
        # The wearer's stop: what plays is cut, by the wearer; the sleeve stays unpaused.
        send(4)
        running.wait_events(6)
        running.sleeve.controls.stop("page")
        cut = running.wait_events(7)[6]
        assert (cut["type"], cut["seq"], cut["by"]) == ("cancelled", 4, "wearer")
        assert running.sleeve.controls.state().paused is False
        drawing = str(uuid.uuid4())  # the stop stopped the drawing: a new one plays
        # "Do not disturb": refused with the time it ends, until it is ended.
        until_ms = round(wall_ms()) + 60_000
        running.sleeve.controls.set_do_not_disturb(until_ms, "page")
        _wait(
            lambda: (last_controls() or {}).get("do_not_disturb_until_ms") == until_ms,
            "no status said do not disturb",
        )
        send(5, 200.0)
        refused = running.wait_events(8)[7]
        assert (refused["seq"], refused["reason"]) == (5, "do_not_disturb")
        assert time.strftime("%H:%M:%S UTC", time.gmtime(until_ms / 1000)) in refused["message"]
        running.sleeve.controls.set_do_not_disturb(None, "page")
        send(6, 200.0)
        assert running.wait_events(9)[8]["type"] == "played"
    finally:
        sender.loop_stop()
        running.stop()


# --- the buttons, on their emulated lines ---------------------------------------------------


def tap(button: EmulatedButton) -> None:
    """A finger's short press, let go long enough for the next one to count (presses closer
    than the debounce window are the bouncing of one)."""
    button.press()
    time.sleep(0.05)
    button.let_go()
    time.sleep(2 * DEBOUNCE_MS / 1000)


def watched(role: str, wearer: WearerControls) -> tuple[EmulatedButton, ButtonWatcher]:
    button = EmulatedButton("gpiochip0", 27)
    watcher = ButtonWatcher(button, role, wearer)
    watcher.start()
    return button, watcher


def test_a_long_press_stops_the_drawing_and_leaves_the_pause_as_it_was(tmp_path: Path) -> None:
    applied = Applied()
    wearer = controls(tmp_path / "c.json", applied)
    button, watcher = watched("pause", wearer)
    try:
        for paused_before in (False, True):
            stops = applied.stops
            if paused_before:
                wearer.pause("page")
            button.press()
            _wait(lambda s=stops: applied.stops == s + 1, "no stop after a long press")
            button.let_go()
            time.sleep(2 * DEBOUNCE_MS / 1000)  # the let-go taken: it must change nothing
            assert wearer.state().paused is paused_before
        # A short press while paused resumes.
        tap(button)
        _wait(lambda: not wearer.state().paused, "a short press did not resume")
    finally:
        watcher.stop()


def test_the_turn_down_button_lowers_the_ceiling_a_step_a_press_never_below_the_least(
    tmp_path: Path,
) -> None:
    wearer = controls(tmp_path / "c.json")  # max_intensity 0.9
    button, watcher = watched("turn_down", wearer)
    try:
        seen = []
        for _ in range(10):
            before = wearer.state().ceiling
            tap(button)
            if before != MIN_CEILING:
                _wait(lambda b=before: wearer.state().ceiling != b, "the ceiling did not move")
            seen.append(wearer.state().ceiling)
        assert seen[:3] == [0.8, 0.7, 0.6]
        assert seen[-2:] == [MIN_CEILING, MIN_CEILING]
    finally:
        watcher.stop()
