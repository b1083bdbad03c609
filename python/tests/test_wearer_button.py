"""The wearer's buttons on real sleeve processes: pause mid-drawing, resume, restarts.

A real ``feelmysign sleeve`` against a real Mosquitto, on the paper's layout with a
``[controls]`` table; its chips and its buttons emulated in a state file. The test
presses a button through the pipe next to that file, as a finger would; the emulated
button records when the sleeve saw the press, and the bus when every motor was last
found off (``silent_since``), on one clock: the test reads from that record how soon
after the press every motor was off, and by which transactions.

- a press mid-drawing: every motor at 0 by the player's next pass (the first bus writes
  after the press are the offs of the motors then driven; the milliseconds are a figure of
  ``make bench``, group ``wearer_pause``), the stroke playing cut
  (``cancelled`` by the wearer), the rest refused ``paused``, every stroke sent with
  exactly one fate; a status that says so; a second press resumes and strokes play;
- ``kill -9`` while paused, restart: still paused, refusing, every motor off; a ceiling set
  with the turn-down button holds after a restart, on every motor.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lost_chip import saved, wait_until
from sleeve_watch import SleeveWatch, exit_code_after, online, reaped

from feelmysign.backends.emulated_button import press_in, release_in
from feelmysign.backends.emulated_state import drive_levels
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.events import event_from_json
from feelmysign.fates import DrawingFates
from feelmysign.stroke import Stroke

CHIP, PAUSE_LINE, TURN_DOWN_LINE = "gpiochip0", 27, 22
CONTROLS = (
    "\n[controls]\n"
    f'pause_button = {{ chip = "{CHIP}", line = {PAUSE_LINE} }}\n'
    f'turn_down_button = {{ chip = "{CHIP}", line = {TURN_DOWN_LINE} }}\n'
)
HOLD_S = 0.1  # a finger's short press
# One RTP step of the DRV2605L (signed: 127 is full drive): how far a level is rounded.
RTP_STEP = 1 / 127


def paper_with_buttons(folder: Path) -> Path:
    path = folder / "paper-buttons.toml"
    path.write_text(restart_off.PAPER.read_text() + CONTROLS)
    return path


def start(broker: Broker, state: Path, layout: Path, home: Path) -> subprocess.Popen[str]:
    command = restart_off.sleeve_command(broker.credentials_path, state)
    command[command.index("--layout") + 1] = str(layout)
    # A state directory of its own: the wearer's controls of this sleeve id stay in this test.
    env = {**os.environ, "XDG_STATE_HOME": str(home)}
    with open(home.parent / "sleeve.log", "a") as log:  # its log, to read when a test fails
        return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=log, text=True, env=env)


def press(state: Path, line: int) -> None:
    """Down and up again, as a short press: the sleeve acts on the way down."""
    count = _presses(state, line)
    press_in(state, CHIP, line)
    wait_until(lambda: _presses(state, line) == count + 1, "the press taken")
    time.sleep(HOLD_S)
    release_in(state, CHIP, line)
    wait_until(lambda: not _button(state, line)["pressed"], "the button let go")


def _button(state: Path, line: int) -> dict[str, Any]:
    found: list[dict[str, Any]] = [b for b in saved(state).get("buttons", []) if b["line"] == line]
    assert len(found) == 1, f"no button on line {line} in {state}"
    return found[0]


def _presses(state: Path, line: int) -> int:
    return int(_button(state, line)["presses"])


def controls_said(**expected: Any) -> Callable[[str, dict[str, Any]], bool]:
    def check(name: str, body: dict[str, Any]) -> bool:
        controls = body.get("controls") or {}
        return name == "status" and all(controls.get(k) == v for k, v in expected.items())

    return check


def test_a_press_mid_drawing_stops_every_motor_at_once_and_the_rest_is_refused_paused(
    broker: Broker, tmp_path: Path
) -> None:
    state, layout, home = tmp_path / "bus.json", paper_with_buttons(tmp_path), tmp_path / "s"
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout, home)) as sleeve,
    ):
        status = watcher.next(online, "the sleeve online")
        assert status["controls"] == {
            "paused": False,
            "paused_by": None,
            "ceiling": None,
            "do_not_disturb_until_ms": None,
        }
        # Four long strokes back to back: a motor is on whenever the press comes.
        for seq in range(4):
            watcher.send(Stroke((0.0, 1.0), (3.0, 1.0), 1500.0, 0.9, "d", seq))
        watcher.next(lambda n, b: b.get("type") == "played", "the first stroke playing")
        wait_until(lambda: any(drive_levels(state).values()), "a motor on")
        press(state, PAUSE_LINE)
        watcher.next(controls_said(paused=True, paused_by="button"), "a status saying paused")

        after = saved(state)
        pressed_at, silent_since = _button(state, PAUSE_LINE)["pressed_at"], after["silent_since"]
        print("the press:", _button(state, PAUSE_LINE), "every motor off since:", silent_since)
        assert _button(state, PAUSE_LINE)["driven_at_press"] > 0  # it came mid-drawing
        assert silent_since is not None and set(drive_levels(state).values()) == {0.0}
        assert silent_since["transaction"] >= pressed_at["transaction"]
        # One pass of the player, nothing else first: each motor driven at the press needs at
        # most three transactions to go off (the other multiplexer deselected, its channel
        # selected, its level written).
        driven = _button(state, PAUSE_LINE)["driven_at_press"]
        assert silent_since["transaction"] - pressed_at["transaction"] <= 3 * driven
        # How soon, in ms, is a figure of `make bench` (wearer_pause: within 20 ms there, on
        # a machine not shared by a dozen test runs); printed here, not held to.
        off_ms = silent_since["ms"] - pressed_at["ms"]
        print(f"every motor off {off_ms:.3f} ms after the sleeve saw the press")

        # Sent while paused: refused too. Then every stroke has exactly one fate.
        watcher.send(Stroke((0.0, 1.0), (3.0, 1.0), 300.0, 0.9, "d", 4))
        fates = DrawingFates()

        def every_stroke_answered() -> bool:
            for _, body in watcher.history[len(fates_seen) :]:
                fates_seen.append(body)
                if body.get("drawing") == "d":
                    fates.add(event_from_json(body))
            return set(fates.fates()) == set(range(5)) and "cut" in fates.fates().values()

        fates_seen: list[dict[str, Any]] = []
        watcher.wait_until(every_stroke_answered, "a fate for every stroke")
        found = fates.fates()
        print("fates:", found)
        cut = [seq for seq, fate in found.items() if fate == "cut"]
        assert len(cut) == 1, found
        assert all(found[seq] == "played" for seq in range(cut[0])), found
        assert all(found[seq] == "refused" for seq in range(cut[0] + 1, 5)), found
        assert set(fates.refusals()) == {"paused"}, fates.refusals()
        cancels = [b for _, b in watcher.history if b.get("type") == "cancelled"]
        assert [(c["seq"], c["started"], c["by"]) for c in cancels] == [(cut[0], True, "wearer")]
        refused = [b for _, b in watcher.history if b.get("reason") == "paused"]
        assert all("wearer paused" in r["message"] for r in refused), refused
        # Nothing came on while paused: the bus has been silent since the press.
        assert saved(state)["silent_since"] == silent_since

        # A second press resumes: strokes play again.
        press(state, PAUSE_LINE)
        watcher.next(controls_said(paused=False), "a status saying resumed")
        watcher.send(Stroke((0.0, 1.0), (3.0, 1.0), 300.0, 0.9, "e", 0))
        played = watcher.next(lambda n, b: b.get("drawing") == "e", "the stroke after resuming")
        assert played["type"] == "played", played
        assert exit_code_after(sleeve, signal.SIGTERM) == 0


def test_kill_9_while_paused_restarts_paused_and_a_ceiling_holds(
    broker: Broker, tmp_path: Path
) -> None:
    state, layout, home = tmp_path / "bus.json", paper_with_buttons(tmp_path), tmp_path / "s"
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout, home)) as sleeve,
    ):
        watcher.next(online, "the sleeve online")
        for _ in range(3):  # 1.0 -> 0.7, the layout's max_intensity being 1.0
            press(state, TURN_DOWN_LINE)
        watcher.next(controls_said(ceiling=0.7, paused=False), "a status with the ceiling")
        press(state, PAUSE_LINE)
        paused = watcher.next(controls_said(paused=True), "a status saying paused")
        assert exit_code_after(sleeve, signal.SIGKILL) == -signal.SIGKILL

    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout, home)) as sleeve,
    ):
        # The retained status is the dead sleeve's until the new one says it is online.
        status = watcher.next(
            lambda n, b: online(n, b) and b["at_ms"] > paused["at_ms"],
            "the restarted sleeve online",
        )
        assert status["controls"] == {
            "paused": True,
            "paused_by": "button",
            "ceiling": 0.7,
            "do_not_disturb_until_ms": None,
        }
        for seq in range(3):
            watcher.send(Stroke((0.0, 1.0), (3.0, 1.0), 300.0, 1.0, "while-paused", seq))
            refused = watcher.next(lambda n, b: b.get("drawing") == "while-paused", "a refusal")
            assert (refused["type"], refused["reason"]) == ("rejected", "paused"), refused
        assert set(drive_levels(state).values()) == {0.0}
        # The log: the state kept said once at start, the presses in words, and one line for
        # the drawing refused while paused, not one a stroke.
        log = (tmp_path / "sleeve.log").read_text()
        restarted = log[log.rindex("connecting to") :]
        print(restarted)
        assert "the wearer's controls at start: paused (by button), ceiling 0.7" in log
        assert "press press" not in log and f"line {PAUSE_LINE}): pressed" in log
        assert restarted.count("drawing while-paused") == 1, restarted
        assert "until None" not in log

        press(state, PAUSE_LINE)  # resume: the ceiling still holds, on every motor
        watcher.next(controls_said(paused=False, ceiling=0.7), "a status saying resumed")
        watcher.send(Stroke((0.0, 0.5), (3.0, 1.5), 1200.0, 1.0, "full", 0))
        played = watcher.next(lambda n, b: b.get("drawing") == "full", "the stroke played")
        assert played["type"] == "played", played
        peak = loudest_until_quiet(state)
        print(f"the loudest motor of a stroke asking 1.0: {peak:.4f}")
        assert 0 < peak <= 0.7 + RTP_STEP
        assert exit_code_after(sleeve, signal.SIGTERM) == 0


def loudest_until_quiet(state: Path) -> float:
    """The highest drive any motor is seen at, read from the bus until every motor is off."""
    peak = 0.0

    def quiet() -> bool:
        nonlocal peak
        levels = drive_levels(state).values()
        peak = max(peak, *levels)
        return peak > 0 and not any(levels)

    wait_until(quiet, "the stroke over")
    return peak


def test_a_button_line_that_cannot_be_had_stops_the_sleeve_at_start_saying_what_to_check(
    tmp_path: Path,
) -> None:
    """The wearer's control is never silently absent: on a machine without that GPIO chip
    (this one, the sim backend reading the real lines), a clear error and exit 1."""
    layout = tmp_path / "paper-button.toml"
    missing = 'pause_button = { chip = "gpiochip99", line = 27 }'
    layout.write_text(restart_off.PAPER.read_text() + f"\n[controls]\n{missing}\n")
    command = [*restart_off.feelmysign_command(), "sleeve", "--layout", str(layout)]
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "s")}
    done = subprocess.run(command, capture_output=True, text=True, timeout=60, env=env)
    print(done.stderr)
    assert done.returncode == 1
    assert "Traceback" not in done.stderr
    assert "pause button" in done.stderr and "controls.pause_button.chip" in done.stderr
    assert "/dev/gpiochip99" in done.stderr and "gpiodetect" in done.stderr
