"""The DRV2605L datasheet's equations (SLOS854, 8.5.2), the layout's motor keys, the kept results.

The datasheet gives the equations but no worked register values for them, so each
expected value below is derived by hand from the equation in its comment.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from feelmysign.backends.actuator_config import (
    Calibration,
    CalibrationStore,
    chip_settings,
    closed_loop_od_clamp_code,
    erm_open_loop_od_clamp_code,
    erm_rated_voltage_code,
    lra_drive_time_code,
    lra_rated_voltage_code,
    motor_description,
)
from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_i2c import EmulatedI2CBus
from feelmysign.errors import HardwareError, LayoutError
from feelmysign.layout import parse_layout

GRID = "rows = 2\ncolumns = 2\nspacing_cm = 2.0\n"
WIRED = (
    "[i2c]\nmultiplexers = [0x70]\nwiring = [\n"
    "  { row = 0, column = 0, multiplexer = 0x70, channel = 0 },\n"
    "  { row = 0, column = 1, multiplexer = 0x70, channel = 1 },\n"
    "  { row = 1, column = 0, multiplexer = 0x70, channel = 2 },\n"
    "  { row = 1, column = 1, multiplexer = 0x70, channel = 3 },\n]\n"
)


def test_erm_closed_loop_rated_voltage() -> None:
    # V(ERM-CL, AV) = 21.18 mV x RATED_VOLTAGE: 3.0 V / 0.02118 V = 141.64 -> 142 (0x8E);
    # 1.3 V / 0.02118 V = 61.38 -> 61.
    assert erm_rated_voltage_code(3.0) == 0x8E
    assert erm_rated_voltage_code(1.3) == 61


def test_erm_open_loop_full_scale() -> None:
    # V(ERM-OL, AV) = 21.59 mV x OD_CLAMP: 3.0 V / 0.02159 V = 138.95 -> 139 (0x8B).
    assert erm_open_loop_od_clamp_code(3.0) == 0x8B


def test_closed_loop_overdrive_clamp() -> None:
    # V(OD) = 21.96 mV x OD_CLAMP: 3.6 V / 0.02196 V = 163.93 -> 164; 2.5 V -> 113.84 -> 114.
    assert closed_loop_od_clamp_code(3.6) == 164
    assert closed_loop_od_clamp_code(2.5) == 0x72


def test_lra_closed_loop_rated_voltage() -> None:
    # V(LRA-CL, RMS) = 20.58 mV x RATED_VOLTAGE / sqrt(1 - (4 x 300 us + 300 us) x f):
    # at 175 Hz, sqrt(1 - 0.0015 x 175) = sqrt(0.7375) = 0.85878, so
    # 1.8 V rms -> 1.8 x 0.85878 / 0.02058 = 75.11 -> 75 (0x4B);
    # 2.0 V rms -> 83.46 -> 83. At 235 Hz: sqrt(1 - 0.3525) = 0.80467, 2.0 V -> 78.20 -> 78.
    assert lra_rated_voltage_code(1.8, 175.0) == 0x4B
    assert lra_rated_voltage_code(2.0, 175.0) == 83
    assert lra_rated_voltage_code(2.0, 235.0) == 78


def test_lra_drive_time_is_half_the_period() -> None:
    # Half period = 0.1 ms x DRIVE_TIME + 0.5 ms: 175 Hz -> 2.857 ms -> 23.57 -> 24;
    # 235 Hz -> 2.128 ms -> 16.28 -> 16; 170 Hz -> 2.941 ms -> 24.41 -> 24.
    assert lra_drive_time_code(175.0) == 24
    assert lra_drive_time_code(235.0) == 16
    assert lra_drive_time_code(170.0) == 24


def test_voltages_beyond_the_register_are_refused() -> None:
    with pytest.raises(ValueError, match=r"outside 1\.\.255"):
        erm_rated_voltage_code(6.0)  # 283 steps


def test_the_layout_defaults_are_those_of_coin_motors() -> None:
    erm = chip_settings(parse_layout(GRID))
    assert (erm.lra, erm.rated_voltage, erm.od_clamp, erm.drive_time) == (False, 0x8E, 0x8B, 19)
    assert erm.calibration_od_clamp == 164  # the 3.6 V overdrive, for calibration only
    lra = chip_settings(parse_layout(GRID + 'actuator_type = "LRA"\n'))
    # 2.0 V rms at 205 Hz: sqrt(1 - 0.3075) = 0.83217 -> 2.0 x 0.83217 / 0.02058 = 80.87 -> 81;
    # 2.8 V / 0.02196 = 127.5 -> 128 (Python rounds 127.505 up); 500/205 = 2.439 ms -> 19.39 -> 19.
    assert (lra.lra, lra.rated_voltage, lra.od_clamp, lra.drive_time) == (True, 81, 128, 19)


@pytest.mark.parametrize(
    ("keys", "problem"),
    [
        ("rated_voltage_v = 12", "rated_voltage_v: must be a number from 0.5 to 5 V"),
        ('overdrive_voltage_v = "3V"', "overdrive_voltage_v: must be a number from 0.5 to 5.5"),
        ("rated_voltage_v = 3.0\noverdrive_voltage_v = 2.0", "below the rated voltage 3 V"),
        ("resonant_frequency_hz = 175", 'is for an LRA only (actuator_type = "LRA")'),
        (
            'actuator_type = "LRA"\nresonant_frequency_hz = 60',
            "resonant_frequency_hz: must be a number from 140 to 400 Hz",
        ),
    ],
)
def test_bad_motor_values_are_named_with_their_range(keys: str, problem: str) -> None:
    with pytest.raises(LayoutError) as caught:
        parse_layout(GRID + keys + "\n")
    assert any(problem in p for p in caught.value.problems), caught.value.problems


def test_a_kept_calibration_is_used_only_for_the_same_motor(tmp_path: Path) -> None:
    store = CalibrationStore(str(tmp_path / "state" / "calibration.json"))
    layout = parse_layout(GRID + 'actuator_type = "LRA"\n')
    motor = motor_description(layout)
    store.put({"0x70/0": Calibration(14, 104, 3)}, motor)
    assert store.get("0x70/0", motor) == Calibration(14, 104, 3)
    other = motor_description(parse_layout(GRID + 'actuator_type = "LRA"\nrated_voltage_v = 1.5\n'))
    assert store.get("0x70/0", other) is None  # another motor: calibrate again
    assert store.get("0x70/1", motor) is None


def test_a_calibration_that_never_ends_is_stopped_and_named(tmp_path: Path) -> None:
    layout = parse_layout(GRID + WIRED)
    bus = EmulatedI2CBus.for_layout(layout)
    chip = bus.chips[(0x70, 2)]
    original = chip.read

    def stuck(register: int) -> int:
        value = original(register)
        return value | 1 if register == 0x0C and chip.registers[0x01] & 0x07 == 7 else value

    chip.read = stuck  # type: ignore[method-assign]
    store = CalibrationStore(str(tmp_path / "calibration.json"))
    backend = Drv2605Backend(layout, bus=bus, calibration=store)
    with pytest.raises(HardwareError, match=r"channel 2 .*GO did not clear"):
        backend.open()
    assert chip.standby and chip.registers[0x0C] == 0  # stopped, and in standby
    assert all(c.output == 0 for c in bus.chips.values())
    # The chips calibrated before it keep their results.
    assert set(store.results(motor_description(layout))) == {"0x70/0", "0x70/1"}


def test_a_layout_built_in_code_past_the_checks_is_refused_after_the_off() -> None:
    layout = dataclasses.replace(parse_layout(GRID + WIRED), rated_voltage_v=9.0)
    bus = EmulatedI2CBus.for_layout(layout)
    bus.chips[(0x70, 1)].registers[0x01] = 0x05  # left in RTP mode at full drive by a crash
    bus.chips[(0x70, 1)].registers[0x02] = 0xFF
    bus.chips[(0x70, 1)].registers[0x1D] |= 0x08
    assert bus.chips[(0x70, 1)].output == 1.0
    with pytest.raises(LayoutError, match="rated voltage 9 V needs register value 425"):
        Drv2605Backend(layout, bus=bus).open()
    assert all(c.output == 0 for c in bus.chips.values())
