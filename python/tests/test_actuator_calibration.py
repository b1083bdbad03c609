"""Motors set up from their datasheet values and auto-calibrated once, on a real sleeve.

A real ``feelmysign sleeve --backend drv2605 --emulate-state FILE`` against a real
Mosquitto: the state file holds every chip's registers, so the test reads what the
sleeve programmed (RATED_VOLTAGE, OD_CLAMP, DRIVE_TIME and the calibration results),
cuts the chips' power (their registers back to reset values, as a power cycle does) and
sees a restarted sleeve restore the calibration it kept without running it again. The
expected register values are worked out by hand in test_actuator_config.py.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
from pathlib import Path
from typing import Any

import pytest
from sleeve_watch import SleeveWatch, exit_code_after, online, reaped

from feelmysign.backends.emulated_i2c import EmulatedI2CBus
from feelmysign.backends.emulated_state import drive_levels, write_state
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.layout import load_layout

WAIT_S = 60.0

# Hand-derived in test_actuator_config.py: the paper's ERMs at the defaults (3.0 V rated,
# open loop), and LRAs of 1.8 V rms, 2.5 V peak, 175 Hz.
ERM = {"rated_voltage": 0x8E, "od_clamp": 0x8B, "drive_time": 19, "bemf_gain": 1}
LRA = {"rated_voltage": 0x4B, "od_clamp": 0x72, "drive_time": 24, "bemf_gain": 3}
LRA_KEYS = (
    'actuator_type = "LRA"\nrated_voltage_v = 1.8\noverdrive_voltage_v = 2.5\n'
    "resonant_frequency_hz = 175\n"
)
RESET = {0x16: 0x3E, 0x17: 0x8C, 0x18: 0x0C, 0x19: 0x6C}


def layout_file(folder: Path, kind: str) -> Path:
    text = restart_off.PAPER.read_text()
    if kind == "LRA":
        start = text.index('actuator_type = "ERM"')
        end = text.index("\n", start) + 1
        text = text[:start] + LRA_KEYS + text[end:]
    path = folder / f"{kind}.toml"
    path.write_text(text)
    return path


def command(broker: Broker, state: Path, layout: Path, *extra: str) -> list[str]:
    return [
        *restart_off.feelmysign_command(),
        "sleeve",
        "--backend",
        "drv2605",
        "--emulate-state",
        str(state),
        "--layout",
        str(layout),
        "--credentials",
        str(broker.credentials_path),
        "--no-legacy",
        *extra,
    ]


def chips(state: Path) -> dict[str, dict[str, Any]]:
    saved: dict[str, dict[str, Any]] = json.loads(state.read_text())["chips"]
    return saved


def motor_registers(saved: dict[str, Any]) -> dict[str, int]:
    registers = bytes.fromhex(saved["registers"])
    return {
        "rated_voltage": registers[0x16],
        "od_clamp": registers[0x17],
        "a_cal_comp": registers[0x18],
        "a_cal_bemf": registers[0x19],
        "bemf_gain": registers[0x1A] & 0x03,
        "drive_time": registers[0x1B] & 0x1F,
    }


def power_cycle(state: Path) -> None:
    """Every chip's registers back to their reset values, as when the boards lose power."""
    data = json.loads(state.read_text())
    for saved in data["chips"].values():
        registers = bytearray(bytes.fromhex(saved["registers"]))
        for register, value in RESET.items():
            registers[register] = value
        registers[0x1A] = 0x36
        registers[0x1B] = 0x93
        saved["registers"] = registers.hex()
    temporary = state.with_suffix(".tmp")
    temporary.write_text(json.dumps(data))
    os.replace(temporary, state)


def log_file(folder: Path) -> Any:
    """The sleeve's log, to read when a test fails: a pipe never read would fill with its
    lines and block the sleeve before it could exit."""
    return (folder / "sleeve.log").open("a")


@pytest.fixture
def watcher(broker: Broker) -> Any:
    with SleeveWatch(broker.credentials, "status", "events") as watching:
        yield watching


@pytest.mark.parametrize(("kind", "expected"), [("ERM", ERM), ("LRA", LRA)])
def test_a_sleeve_programs_its_motors_calibrates_once_and_restores_it_after_a_power_cycle(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path, kind: str, expected: dict[str, int]
) -> None:
    state, layout = tmp_path / "bus.json", layout_file(tmp_path, kind)
    with reaped(
        subprocess.Popen(command(broker, state, layout), stderr=log_file(tmp_path), text=True)
    ) as first:
        watcher.next(online, "the sleeve online")
        assert exit_code_after(first, signal.SIGTERM) == 0
    # The log says each chip's results in a sentence, the registers as scan shows them.
    logged = (tmp_path / "sleeve.log").read_text()
    assert "Calibration(" not in logged
    said = re.findall(
        r"calibrated the DRV2605L on (multiplexer 0x7[01] channel \d).*?: its results "
        r"are A_CAL_COMP 0x[0-9A-F]{2}, A_CAL_BEMF 0x[0-9A-F]{2} and BEMF_GAIN (\d)$",
        logged,
        flags=re.MULTILINE,
    )
    assert len(said) == len(load_layout(layout).wiring), logged
    assert {gain for _, gain in said} == {str(expected["bemf_gain"])}
    calibrated = chips(state)
    assert len(calibrated) == len(load_layout(layout).wiring)
    results = {}
    for name, saved in calibrated.items():
        registers = motor_registers(saved)
        assert saved["calibrations"] == 1, name  # calibrated once, at the first start
        assert {key: registers[key] for key in expected} == expected, name
        # The emulated chip's results, not the reset values.
        assert (registers["a_cal_comp"], registers["a_cal_bemf"]) != (0x0C, 0x6C), name
        results[name] = registers
    assert set(drive_levels(state).values()) == {0.0}

    power_cycle(state)
    assert motor_registers(chips(state)["0x70/0"])["rated_voltage"] == 0x3E
    with reaped(
        subprocess.Popen(command(broker, state, layout), stderr=log_file(tmp_path), text=True)
    ) as again:
        watcher.next(online, "the restarted sleeve online")
        assert exit_code_after(again, signal.SIGTERM) == 0
    for name, saved in chips(state).items():
        assert saved["calibrations"] == 1, name  # restored, not run again
        assert motor_registers(saved) == results[name], name


def test_a_failed_calibration_names_the_chip_and_leaves_every_motor_off(
    broker: Broker, tmp_path: Path
) -> None:
    state, layout = tmp_path / "bus.json", layout_file(tmp_path, "LRA")
    bus = EmulatedI2CBus.for_layout(load_layout(layout))
    bus.chips[(0x70, 5)].fail_calibration = True  # row 1, column 1: a motor not connected
    write_state(bus, state)

    run = subprocess.run(
        command(broker, state, layout), capture_output=True, text=True, timeout=WAIT_S
    )
    assert run.returncode != 0
    assert "Traceback" not in run.stderr
    assert "Auto-calibration of the DRV2605L on multiplexer 0x70 channel 5" in run.stderr
    assert "DIAG_RESULT" in run.stderr and "OUT+ and OUT-" in run.stderr
    assert "--calibrate" in run.stderr
    assert set(drive_levels(state).values()) == {0.0}
    saved = chips(state)
    assert saved["0x70/5"]["calibrations"] == 1
    assert bytes.fromhex(saved["0x70/5"]["registers"])[0] & 0x08  # DIAG_RESULT

    # scan --calibrate says the same, and still shows every chip.
    failed = scan_calibrate(state, layout)
    assert failed.returncode == 1
    assert "Calibration failed: Auto-calibration of the DRV2605L on multiplexer 0x70 channel 5" in (
        failed.stdout
    )
    assert "row 2, column 3" in failed.stdout  # the scan's table is there
    assert set(drive_levels(state).values()) == {0.0}

    # Fixed (the motor wired again): scan --calibrate calibrates and keeps every result.
    data = json.loads(state.read_text())
    data["chips"]["0x70/5"]["fail_calibration"] = False
    state.write_text(json.dumps(data))
    scan = scan_calibrate(state, layout, "--json")
    assert scan.returncode == 0, scan.stderr
    motors = json.loads(scan.stdout)["motors"]
    assert len(motors) == 12
    assert all(m["calibration_stored"] and m["as_layout"] for m in motors), motors
    assert {m["rated_voltage"] for m in motors} == {LRA["rated_voltage"]}
    counts = {name: saved["calibrations"] for name, saved in chips(state).items()}
    assert counts["0x70/5"] == 3
    assert set(drive_levels(state).values()) == {0.0}


def scan_calibrate(state: Path, layout: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [
            *restart_off.feelmysign_command(),
            "scan",
            "--layout",
            str(layout),
            "--emulate-state",
            str(state),
            "--calibrate",
            *extra,
        ],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
