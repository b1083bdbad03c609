"""What a sleeve builder tries on the emulated bus, with real processes: ``buzz`` with a chip
missing, a multiplexer unplugged under a running sleeve, and the sleeve's journal line per
drawing (a real Mosquitto, a real ``feelmysign sleeve``, ``feelmysign send``)."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import time
from pathlib import Path

from builder_sleeve import start_sleeve, two_by_six_layout
from sleeve_watch import SleeveWatch, online

from feelmysign.backends.emulated_state import drive_levels, read_state
from feelmysign.bench.restart_off import feelmysign_command
from feelmysign.broker import Broker
from feelmysign.stroke import Stroke

WAIT_S = 120.0
LOST = "0x71/2"  # row 1, column 2 of the 2 x 6 sleeve


def run(*argv: str, timeout_s: float = WAIT_S) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    return subprocess.run(
        [*feelmysign_command(), *argv],
        capture_output=True,
        text=True,
        timeout=timeout_s,
        env=env,
        check=False,
    )


def edit_state(state: Path, change: object) -> None:
    """Change the file as a person would, replacing it whole (as the sleeve writes it)."""
    saved = json.loads(state.read_text())
    change(saved)  # type: ignore[operator]
    edited = state.with_name("edit.json")
    edited.write_text(json.dumps(saved))
    edited.replace(state)


def wait_until(condition: object, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():  # type: ignore[operator]
        assert time.monotonic() < deadline, what
        time.sleep(0.01)


def fresh_bus(tmp_path: Path) -> tuple[Path, Path]:
    """The 2 x 6 layout and its emulated bus's state file, every chip at reset."""
    layout = two_by_six_layout(tmp_path / "maker.toml")
    state = tmp_path / "bus.json"
    made = run("scan", "--layout", str(layout), "--emulate-state", str(state))
    assert made.returncode == 0, made.stdout + made.stderr
    return layout, state


def test_buzz_tries_the_motors_that_answer_and_names_the_missing_chip(tmp_path: Path) -> None:
    layout, state = fresh_bus(tmp_path)
    edit_state(state, lambda s: s["chips"][LOST].update(connected=False))
    buzz = [*feelmysign_command(), "buzz", "--layout", str(layout), "--emulate-state", str(state)]
    buzzing = subprocess.Popen(
        [*buzz, "0", "0", "--duration-ms", "3000"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        wait_until(lambda: drive_levels(state)["0x70/0"] > 0, "row 0, column 0 never buzzed")
        out, errors = buzzing.communicate(timeout=WAIT_S)
    finally:
        buzzing.kill()
    assert buzzing.returncode == 0, out + errors
    assert "no DRV2605L answered on multiplexer 0x71 channel 2 (actuator row 1, column 2)" in errors
    assert "Buzzing row 0, column 0" in out and "Every motor is off." in out
    assert set(drive_levels(state).values()) == {0.0}

    missing = run("buzz", "1", "2", "--layout", str(layout), "--emulate-state", str(state))
    assert missing.returncode == 1, missing.stdout + missing.stderr
    assert "Error: Cannot buzz row 1, column 2: its DRV2605L, on multiplexer 0x71 channel 2" in (
        missing.stderr
    )
    assert "Traceback" not in missing.stderr
    assert set(drive_levels(state).values()) == {0.0}


def test_a_running_sleeve_keeps_a_multiplexer_unplugged_in_the_state_file(
    broker: Broker, tmp_path: Path
) -> None:
    layout, state = fresh_bus(tmp_path)
    with SleeveWatch(broker.credentials, "status", "events") as watcher:
        sleeve = start_sleeve(broker.credentials_path, layout, state)
        try:
            watcher.next(online, "the sleeve online")
            edit_state(state, lambda s: s["multiplexers"]["0x71"].update(connected=False))
            # A stroke on row 0 (multiplexer 0x70): it plays, and the sleeve writes the file.
            watcher.send(Stroke((0.0, 0.0), (3.0, 0.0), 400.0, 0.8, "row0", 0))
            watcher.next(lambda n, b: b.get("drawing") == "row0", "the row 0 stroke's event")
            wait_until(lambda: set(drive_levels(state).values()) == {0.0}, "row 0 stayed on")
            assert read_state(state).multiplexers[0x71].connected is False
            # A stroke on row 1, behind the unplugged multiplexer, is never called played.
            watcher.send(Stroke((0.0, 1.0), (3.0, 1.0), 400.0, 0.8, "row1", 0))
            answer = watcher.next(lambda n, b: b.get("drawing") == "row1", "the row 1 answer")
            assert answer["type"] not in ("played", "adjusted"), answer
            assert read_state(state).multiplexers[0x71].connected is False
        finally:
            sleeve.kill()
            sleeve.wait(WAIT_S)


def test_the_sleeve_logs_one_line_per_drawing(broker: Broker, tmp_path: Path) -> None:
    layout = two_by_six_layout(tmp_path / "maker.toml")
    with SleeveWatch(broker.credentials, "status") as watcher:
        sleeve = start_sleeve(broker.credentials_path, layout, tmp_path / "bus.json")
        try:
            watcher.next(online, "the sleeve online")
            credentials = ("--credentials", str(broker.credentials_path))
            sent = run("send", *credentials, "--shape", "square", "--duration-ms", "1200")
            assert sent.returncode == 0, sent.stdout + sent.stderr
            drawing = sent.stdout.split('"drawing":"', 1)[1][:8]
            # Checked against a wider grid than the sleeve's: its second stroke is refused.
            wider = ("--rows", "2", "--columns", "10", "--wait")
            refused = run("send", *credentials, "0,0,5,1,300", "5,1,9,1,300", *wider)
            assert refused.returncode == 1, refused.stdout + refused.stderr
            second = refused.stdout.split('"drawing":"', 1)[1][:8]
        finally:
            sleeve.send_signal(signal.SIGTERM)
            _, log = sleeve.communicate(timeout=WAIT_S)
    lines = [line for line in log.splitlines() if f"Drawing {drawing}" in line]
    assert len(lines) == 1, log
    # (strokes that queued on a loaded machine are said in brackets: played faster)
    said = rf"sleeve sleeve1: Drawing {drawing}: 4 strokes played( \([^)]*\))?; start delay median "
    assert re.search(said, lines[0]) is not None, lines
    assert lines[0].rsplit("start delay median ", 1)[1].endswith(" ms"), lines
    lines = [line for line in log.splitlines() if f"Drawing {second}" in line]
    assert len(lines) == 1, log
    assert f"Drawing {second}: 1 stroke played, 1 rejected (outside_grid)" in lines[0], lines
