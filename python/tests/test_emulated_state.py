"""The emulated bus kept in a file: registers outlive the process, faults are set in the file."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_state import (
    EmulatedStateError,
    chip_key,
    drive_levels,
    open_state_bus,
    read_state,
    state_of,
    write_state,
)
from feelmysign.cli import main
from feelmysign.errors import HardwareError
from feelmysign.layout import Layout, load_layout

REPO = Path(__file__).resolve().parents[2]
PAPER = str(REPO / "deploy" / "layouts" / "paper-sleeve.toml")
WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly


def wait_until(condition: Callable[[], bool], timeout_s: float = WAIT_S) -> bool:
    """Poll ``condition`` (a file another process writes) until it holds or time runs out."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.005)
    return True


@pytest.fixture
def paper() -> Layout:
    return load_layout(PAPER)


def test_a_new_state_file_holds_every_wired_chip_at_its_reset_values(
    tmp_path: Path, paper: Layout
) -> None:
    path = tmp_path / "bus.json"
    open_state_bus(path, paper)
    saved = json.loads(path.read_text())
    assert saved["format"] == "feelmysign-emulated-i2c/1"
    wired = sorted(chip_key(w.multiplexer, w.channel) for w in paper.wiring)
    assert sorted(saved["chips"]) == wired
    assert all(chip["registers"][2:4] == "40" for chip in saved["chips"].values())  # standby
    assert set(drive_levels(path).values()) == {0.0}


def test_every_register_write_reaches_the_file_and_a_new_bus_starts_from_it(
    tmp_path: Path, paper: Layout
) -> None:
    path = tmp_path / "bus.json"
    backend = Drv2605Backend(paper, bus=open_state_bus(path, paper))
    backend.open()
    backend.set_intensity(1, 2, 0.6)  # row 1, column 2: multiplexer 0x70 channel 6
    levels = drive_levels(path)
    assert levels.pop("0x70/6") == pytest.approx(round(0.6 * 255) / 255)
    assert set(levels.values()) == {0.0}
    # The process "dies" here: nothing closes the backend. The next bus is what it left.
    again = read_state(path)
    assert again.chip(mux=0x70, channel=6).output > 0.5
    assert again.multiplexer(0x70).enabled_channels == (6,)
    assert state_of(again) == state_of(open_state_bus(path, paper))


def test_a_chip_left_out_of_the_file_is_missing_and_the_others_are_switched_off(
    tmp_path: Path, paper: Layout
) -> None:
    path = tmp_path / "bus.json"
    bus = open_state_bus(path, paper)
    backend = Drv2605Backend(paper, bus=bus)
    backend.open()
    for wire in paper.wiring:
        backend.set_intensity(wire.row, wire.column, 1.0)
    saved = json.loads(path.read_text())
    del saved["chips"]["0x71/1"]
    saved["chips"]["0x70/2"]["device_id"] = 4  # and a DRV2604 where a DRV2605L should be
    path.write_text(json.dumps(saved))
    assert sum(level > 0 for level in drive_levels(path).values()) == 11

    with pytest.raises(HardwareError) as error:
        Drv2605Backend(paper, bus=open_state_bus(path, paper)).open()
    assert "2 of 12 DRV2605L chips failed the check" in str(error.value)
    assert "multiplexer 0x71 channel 1" in str(error.value)
    assert "is a DRV2604" in str(error.value)
    assert set(drive_levels(path).values()) == {0.0}


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        ("{", "not JSON"),
        ('{"format": "something else"}', "format is not 'feelmysign-emulated-i2c/1'"),
        (
            '{"format": "feelmysign-emulated-i2c/1", "multiplexers": {"0x70": {"control": 300}},'
            ' "chips": {}}',
            "control 300 is outside 0..255",
        ),
    ],
)
def test_a_bad_state_file_is_an_error_that_says_how_to_start_afresh(
    tmp_path: Path, paper: Layout, content: str, problem: str
) -> None:
    path = tmp_path / "bus.json"
    path.write_text(content)
    with pytest.raises(EmulatedStateError) as error:
        open_state_bus(path, paper)
    assert problem in str(error.value)
    assert str(error.value).endswith("delete it to start from a fresh bus wired as the layout says")


def test_scan_and_buzz_read_the_faults_in_the_file(
    tmp_path: Path, paper: Layout, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bus.json"
    bus = open_state_bus(path, paper)
    bus.detach_chip(0x70, 3)
    write_state(bus, path)
    assert main(["scan", "--layout", PAPER, "--emulate-state", str(path), "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["emulated"] is True
    assert [c["status"] for c in report["channels"] if c["status"] not in ("ok", "free")] == [
        "MISSING"
    ]
    # The missing chip's own motor cannot buzz; another one can, and the missing one is named.
    assert main(["buzz", "0", "3", "--layout", PAPER, "--emulate-state", str(path)]) == 1
    error = capsys.readouterr().err
    assert (
        "Error: Cannot buzz row 0, column 3: its DRV2605L, on multiplexer 0x70 channel 3" in error
    )
    buzz = ["buzz", "0", "0", "--duration-ms", "50", "--layout", PAPER]
    assert main([*buzz, "--emulate-state", str(path)]) == 0
    assert "no DRV2605L answered on multiplexer 0x70 channel 3" in capsys.readouterr().err
    assert main(["scan", "--emulate-state", str(tmp_path), "--layout", PAPER]) == 1
    assert "not a usable emulated I2C bus state file" in capsys.readouterr().err


def test_a_buzz_killed_with_sigkill_leaves_its_motor_on_until_the_next_start(
    tmp_path: Path,
) -> None:
    path = tmp_path / "bus.json"
    command = [sys.executable, "-m", "feelmysign", "buzz", "--layout", PAPER]
    command += ["--emulate-state", str(path)]
    buzz = subprocess.Popen(
        [*command, "2", "1", "--duration-ms", "15000"], stdout=subprocess.PIPE, text=True
    )
    try:
        assert buzz.stdout is not None
        assert buzz.stdout.readline().startswith("Buzzing row 2, column 1")
        assert wait_until(lambda: drive_levels(path)["0x71/1"] > 0)
        buzz.send_signal(signal.SIGKILL)
        buzz.wait(WAIT_S)
    finally:
        buzz.kill()
    # No handler ran: the chip still drives its motor, as a real one would.
    assert drive_levels(path)["0x71/1"] > 0
    # The next command that opens the bus switches it off first, whatever it then does.
    started = time.monotonic()
    done = subprocess.run(
        [*command, "0", "0", "--duration-ms", "1"], capture_output=True, text=True, timeout=WAIT_S
    )
    assert done.returncode == 0, done.stderr
    assert set(drive_levels(path).values()) == {0.0}
    assert time.monotonic() - started < WAIT_S


def test_off_after_a_sigkill_switches_every_reachable_motor_off_and_names_the_missing(
    tmp_path: Path,
) -> None:
    path = tmp_path / "bus.json"
    state = ["--emulate-state", str(path)]
    buzz = subprocess.Popen(
        [sys.executable, "-m", "feelmysign", "buzz", "1", "1", "--layout", PAPER, *state],
        stdout=subprocess.DEVNULL,
    )
    try:
        assert wait_until(lambda: path.exists() and drive_levels(path)["0x70/5"] > 0)
        buzz.send_signal(signal.SIGKILL)
        buzz.wait(WAIT_S)
    finally:
        buzz.kill()
    bus = read_state(path)
    bus.detach_chip(0x71, 3)
    write_state(bus, path)
    assert drive_levels(path)["0x70/5"] > 0
    off = [sys.executable, "-m", "feelmysign", "off", "--layout", PAPER, *state]
    done = subprocess.run(off, capture_output=True, text=True, timeout=WAIT_S)
    assert set(drive_levels(path).values()) == {0.0}
    assert done.returncode == 1 and done.stderr.startswith("Error: Not every motor")
    assert "multiplexer 0x71 channel 3" in done.stderr and "Traceback" not in done.stderr
    bus = read_state(path)
    bus.attach_chip(0x71, 3)
    write_state(bus, path)
    done = subprocess.run(off, capture_output=True, text=True, timeout=WAIT_S)
    assert (done.returncode, done.stdout) == (
        0,
        f"Every motor is off (12 DRV2605L on the emulated bus in {path}).\n",
    )


def test_the_service_switches_every_motor_off_whenever_the_sleeve_ends() -> None:
    service = (REPO / "deploy" / "feelmysign-sleeve.service").read_text()
    start = next(line for line in service.splitlines() if line.startswith("ExecStart="))
    stop_post = next(line for line in service.splitlines() if line.startswith("ExecStopPost="))
    layout = start.split("--layout ", 1)[1].split()[0]
    assert stop_post == f"ExecStopPost=/opt/feelmysign/bin/feelmysign off --layout {layout}"
