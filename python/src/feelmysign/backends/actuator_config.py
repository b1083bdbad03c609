"""A motor's datasheet values as DRV2605L register values, and the auto-calibration results kept.

Texas Instruments, "DRV2605L 2- to 5.2-V Haptic Driver for LRA and ERM With Effect
Library and Smart-Loop Architecture" (SLOS854), section 8.5.2 "Programming":

- 8.5.2.1 Rated Voltage Programming (RATED_VOLTAGE, register 0x16), the full-scale
  drive in closed loop:

  - ERM, closed loop (average voltage)::

        V(ERM-CL, AV) = 21.18 mV x RATED_VOLTAGE[7:0]

  - LRA, closed loop (RMS voltage; t_SAMPLE_TIME is CONTROL2's SAMPLE_TIME, 300 us
    at reset, which the sleeve keeps)::

        V(LRA-CL, RMS) = 20.58 mV x RATED_VOLTAGE[7:0]
                         / sqrt(1 - (4 x t_SAMPLE_TIME + 300 us) x f_LRA)

- 8.5.2.2 Overdrive Voltage-Clamp Programming (OD_CLAMP, register 0x17):

  - closed loop, ERM and LRA (peak voltage the automatic overdrive may reach)::

        V(OD) = 21.96 mV x OD_CLAMP[7:0]

  - ERM, open loop, where OD_CLAMP is the full-scale drive (average voltage)::

        V(ERM-OL, AV) = 21.59 mV x OD_CLAMP[7:0]

- 8.5.2.3 Drive-Time Programming (CONTROL1[4:0] DRIVE_TIME): for an LRA the
  initial guess of half its period, ``0.1 ms x DRIVE_TIME + 0.5 ms``; for an ERM
  the back-EMF sampling rate, ``0.2 ms x DRIVE_TIME + 1 ms``, where the reset value
  19 (4.8 ms) is the datasheet's choice for ERMs and is kept.

The sleeve drives an LRA in closed loop (CONTROL3 LRA_OPEN_LOOP = 0, the reset
value) and an ERM in open loop (ERM_OPEN_LOOP = 1, the reset value). In open loop an
RTP value of 255 holds OD_CLAMP for as long as a stroke lasts, with no overdrive
phase the chip could time, so an ERM's OD_CLAMP is its *rated* voltage by the
open-loop equation: its overdrive voltage is set only while it auto-calibrates
(closed loop, as the datasheet's calibration runs), so that no stroke holds a motor
above its rating.
"""

from __future__ import annotations

import json
import math
import os
import zlib
from dataclasses import asdict, dataclass
from typing import Any

from feelmysign.layout import Layout
from feelmysign.state_home import state_path

ERM_CL_RATED_V_PER_STEP = 21.18e-3
LRA_CL_RATED_V_PER_STEP = 20.58e-3
CL_OD_CLAMP_V_PER_STEP = 21.96e-3
ERM_OL_OD_CLAMP_V_PER_STEP = 21.59e-3
SAMPLE_TIME_S = 300e-6  # CONTROL2 SAMPLE_TIME at reset (0b11), kept by the sleeve
LRA_CL_DEAD_TIME_S = 300e-6
LRA_DRIVE_TIME_STEP_MS, LRA_DRIVE_TIME_OFFSET_MS = 0.1, 0.5
ERM_DRIVE_TIME = 19  # the reset value: 4.8 ms, the datasheet's choice for ERMs
DRIVE_TIME_MAX = 31  # five bits
BEMF_GAIN_MASK = 0x03  # FEEDBACK_CONTROL[1:0]

CALIBRATION_FORMAT = "feelmysign-calibration/1"


def _code(voltage_v: float, volts_per_step: float, what: str) -> int:
    code = round(voltage_v / volts_per_step)
    if not 1 <= code <= 0xFF:
        raise ValueError(
            f"{what} {voltage_v:g} V needs register value {code}, outside 1..255 "
            f"(at most {0xFF * volts_per_step:.2f} V)"
        )
    return code


def erm_rated_voltage_code(rated_v: float) -> int:
    """RATED_VOLTAGE for an ERM's average rated voltage (closed loop, 8.5.2.1)."""
    return _code(rated_v, ERM_CL_RATED_V_PER_STEP, "rated voltage")


def lra_rated_voltage_code(rated_rms_v: float, resonance_hz: float) -> int:
    """RATED_VOLTAGE for an LRA's RMS rated voltage at its resonance (closed loop, 8.5.2.1)."""
    factor = 1 - (4 * SAMPLE_TIME_S + LRA_CL_DEAD_TIME_S) * resonance_hz
    if factor <= 0:
        raise ValueError(f"resonant frequency {resonance_hz:g} Hz is too high for closed loop")
    return _code(rated_rms_v * math.sqrt(factor), LRA_CL_RATED_V_PER_STEP, "rated voltage")


def closed_loop_od_clamp_code(overdrive_peak_v: float) -> int:
    """OD_CLAMP for a peak overdrive voltage in closed loop, ERM or LRA (8.5.2.2)."""
    return _code(overdrive_peak_v, CL_OD_CLAMP_V_PER_STEP, "overdrive voltage")


def erm_open_loop_od_clamp_code(full_scale_v: float) -> int:
    """OD_CLAMP for an ERM's full-scale average voltage in open loop (8.5.2.2)."""
    return _code(full_scale_v, ERM_OL_OD_CLAMP_V_PER_STEP, "open-loop full scale")


def lra_drive_time_code(resonance_hz: float) -> int:
    """DRIVE_TIME for an LRA: half its period, 0.1 ms steps above 0.5 ms (8.5.2.3)."""
    half_period_ms = 500.0 / resonance_hz
    code = round((half_period_ms - LRA_DRIVE_TIME_OFFSET_MS) / LRA_DRIVE_TIME_STEP_MS)
    return min(DRIVE_TIME_MAX, max(0, code))


@dataclass(frozen=True)
class ChipSettings:
    """What the sleeve writes to every chip: for driving (``od_clamp``) and for calibrating
    (``calibration_od_clamp``: the overdrive clamp in closed loop)."""

    lra: bool
    rated_voltage: int
    od_clamp: int
    calibration_od_clamp: int
    drive_time: int


def chip_settings(layout: Layout) -> ChipSettings:
    """The register values for ``layout``'s motors (validated by the layout: they fit)."""
    rated, overdrive = layout.rated_voltage, layout.overdrive_voltage
    if layout.actuator_type == "LRA":
        od = closed_loop_od_clamp_code(overdrive)
        return ChipSettings(
            lra=True,
            rated_voltage=lra_rated_voltage_code(rated, layout.resonance_hz),
            od_clamp=od,
            calibration_od_clamp=od,
            drive_time=lra_drive_time_code(layout.resonance_hz),
        )
    return ChipSettings(
        lra=False,
        rated_voltage=erm_rated_voltage_code(rated),
        od_clamp=erm_open_loop_od_clamp_code(rated),
        calibration_od_clamp=closed_loop_od_clamp_code(overdrive),
        drive_time=ERM_DRIVE_TIME,
    )


def motor_description(layout: Layout) -> dict[str, Any]:
    """The motor a calibration was made for: a stored result fits only the same motor."""
    motor: dict[str, Any] = {
        "actuator_type": layout.actuator_type,
        "rated_voltage_v": layout.rated_voltage,
        "overdrive_voltage_v": layout.overdrive_voltage,
    }
    if layout.actuator_type == "LRA":
        motor["resonant_frequency_hz"] = layout.resonance_hz
    return motor


@dataclass(frozen=True)
class Calibration:
    """One chip's auto-calibration results (A_CAL_COMP, A_CAL_BEMF, FEEDBACK's BEMF_GAIN)."""

    a_cal_comp: int
    a_cal_bemf: int
    bemf_gain: int

    def __str__(self) -> str:
        """The results as a log or a person reads them, the registers as scan shows them."""
        return (
            f"A_CAL_COMP 0x{self.a_cal_comp:02X}, A_CAL_BEMF 0x{self.a_cal_bemf:02X} and "
            f"BEMF_GAIN {self.bemf_gain}"
        )


def calibration_path(name: str) -> str:
    """``$XDG_STATE_HOME/feelmysign/calibration/NAME.json`` (``/var/lib/...`` under systemd)."""
    return state_path("calibration", f"{name}.json")


def store_name_for_bus(bus_number: int) -> str:
    return f"i2c-{bus_number}"


def store_name_for_state_file(path: str | os.PathLike[str]) -> str:
    """An emulated bus kept in a file has its own results, as another sleeve would."""
    absolute = os.path.abspath(os.fspath(path))
    return f"emulated-{zlib.crc32(os.fsencode(absolute)):08x}"


class CalibrationStore:
    """The calibration results of every chip on one bus, in one JSON file.

    By chip (``"0x70/3"``), each with the motor it was made for: a result made for
    another motor (the layout's actuator keys changed) is not used, and that chip
    calibrates again.
    """

    def __init__(self, path: str) -> None:
        self.path = path

    def load(self) -> dict[str, Any]:
        try:
            with open(self.path, encoding="utf-8") as file:
                data = json.load(file)
        except (OSError, ValueError):
            return {}
        if not isinstance(data, dict) or data.get("format") != CALIBRATION_FORMAT:
            return {}
        chips = data.get("chips")
        return chips if isinstance(chips, dict) else {}

    def results(self, motor: dict[str, Any]) -> dict[str, Calibration]:
        """Chip -> its stored results, for the chips calibrated with ``motor``."""
        found = {chip: _calibration(saved, motor) for chip, saved in self.load().items()}
        return {chip: result for chip, result in found.items() if result is not None}

    def get(self, chip: str, motor: dict[str, Any]) -> Calibration | None:
        return _calibration(self.load().get(chip), motor)

    def put(self, results: dict[str, Calibration], motor: dict[str, Any]) -> None:
        """Keep ``results`` (chip -> calibration); OSError when the file cannot be written."""
        chips = self.load()
        for chip, calibration in results.items():
            chips[chip] = {"motor": motor, **asdict(calibration)}
        text = json.dumps({"format": CALIBRATION_FORMAT, "chips": chips}, indent=1) + "\n"
        os.makedirs(os.path.dirname(self.path), mode=0o700, exist_ok=True)
        temporary = f"{self.path}.{os.getpid()}.tmp"
        with open(temporary, "w", encoding="utf-8") as file:
            file.write(text)
        os.replace(temporary, self.path)  # whole or not at all


def _calibration(saved: Any, motor: dict[str, Any]) -> Calibration | None:
    if not isinstance(saved, dict) or saved.get("motor") != motor:
        return None
    try:
        values = [int(saved[key]) for key in ("a_cal_comp", "a_cal_bemf", "bemf_gain")]
    except (KeyError, TypeError, ValueError):
        return None
    if not all(0 <= v <= 0xFF for v in values) or values[2] > BEMF_GAIN_MASK:
        return None
    return Calibration(*values)
