"""The hardware backend: DRV2605L haptic drivers in RTP mode behind TCA9548A multiplexers.

Texas Instruments, "DRV2605L 2- to 5.2-V Haptic Driver for LRA and ERM With
Effect Library and Smart-Loop Architecture" (SLOS854), register map section.
Every DRV2605L answers at 0x5A, so each sits alone on a multiplexer channel::

    Raspberry Pi, I2C bus 1
     ├── TCA9548A 0x70 ── channel 0 ── DRV2605L 0x5A ── motor row 0, column 0
     │                    ...
     │                    channel 7 ── DRV2605L 0x5A ── motor row 1, column 3
     └── TCA9548A 0x71 ── channel 0 ── DRV2605L 0x5A ── motor row 2, column 0
                          ...

In RTP mode a chip drives its motor at the amplitude held in RTP_INPUT until
the register changes, so the backend writes one register per intensity change
and nothing while an intensity holds.
"""

from __future__ import annotations

import contextlib
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import ParamSpec, TypeVar

from feelmysign.backends.actuator_config import (
    BEMF_GAIN_MASK,
    Calibration,
    CalibrationStore,
    ChipSettings,
    chip_settings,
    motor_description,
)
from feelmysign.backends.all_off import DRV2605_ADDRESS as DRV2605_ADDRESS  # re-exported
from feelmysign.backends.all_off import MODE_STANDBY, REG_MODE, REG_RTP_INPUT
from feelmysign.backends.base import GridBackend
from feelmysign.backends.bus_lock import BusLock
from feelmysign.backends.enable import Line
from feelmysign.backends.i2c import I2CBus, is_no_answer, open_smbus
from feelmysign.backends.tca9548a import CHANNELS, MULTIPLEXER_ADDRESSES, Multiplexers
from feelmysign.backends.telemetry import ActuatorTelemetry
from feelmysign.errors import HardwareError, LayoutError, ParameterError
from feelmysign.guard import Guardian
from feelmysign.layout import Layout, Wire

# Register map (datasheet names); the ones the all-off writes come from all_off.
_REG_STATUS = 0x00
_REG_MODE = REG_MODE
_REG_RTP_INPUT = REG_RTP_INPUT
_REG_GO = 0x0C
_REG_RATED_VOLTAGE = 0x16
_REG_OD_CLAMP = 0x17
_REG_A_CAL_COMP = 0x18
_REG_A_CAL_BEMF = 0x19
_REG_FEEDBACK_CONTROL = 0x1A
_REG_CONTROL1 = 0x1B
_REG_CONTROL3 = 0x1D

_STATUS_DEVICE_ID_SHIFT = 5  # STATUS[7:5] = DEVICE_ID
_MODE_INTERNAL_TRIGGER = 0x00  # active (STANDBY = 0), plays nothing until GO
_MODE_REAL_TIME_PLAYBACK = 0x05  # active, output amplitude = RTP_INPUT
_MODE_AUTO_CALIBRATION = 0x07  # active, runs auto-calibration on GO
_MODE_STANDBY = MODE_STANDBY
_STATUS_DIAG_RESULT = 0x08  # STATUS bit 3: 1 = the last calibration (or diagnostic) failed
_CONTROL1_DRIVE_TIME = 0x1F  # CONTROL1[4:0]
# Auto-calibration takes 500 to 700 ms at CONTROL4's reset AUTO_CAL_TIME (plus the LRA's
# settling): far more than that and GO that never clears is a chip or motor problem.
CALIBRATION_TIMEOUT_S = 2.0
_CALIBRATION_POLL_S = 0.02
_FEEDBACK_N_ERM_LRA = 0x80  # N_ERM_LRA (bit 7): 1 = LRA, 0 = ERM
_CONTROL3_DATA_FORMAT_RTP = 0x08  # DATA_FORMAT_RTP (bit 3): 1 = unsigned, 0x00 off .. 0xFF full

RTP_FULL_SCALE = 0xFF
DEVICE_NAMES = {3: "DRV2605", 4: "DRV2604", 6: "DRV2604L", 7: "DRV2605L"}
SUPPORTED_DEVICE_IDS = (
    7,
    3,
)  # DRV2605L, DRV2605: both have the RTP mode and register map used here

_T = TypeVar("_T")
_P = ParamSpec("_P")

log = logging.getLogger(__name__)


def device_id_from_status(status: int) -> int:
    return (status >> _STATUS_DEVICE_ID_SHIFT) & 0b111


def device_name(device_id: int) -> str:
    return DEVICE_NAMES.get(device_id, f"unknown chip (device id {device_id})")


def rtp_level(intensity: float) -> int:
    """The unsigned RTP_INPUT value for ``intensity`` in [0, 1]: 0 is off, 255 full scale.

    Python's round (halves to even): only exact halves differ from rounding up, by 1/255.
    """
    return round(intensity * RTP_FULL_SCALE)


class DRV2605L:
    """One DRV2605L on ``i2c``: a bus, or a multiplexer channel that looks like one."""

    def __init__(self, i2c: I2CBus, address: int = DRV2605_ADDRESS) -> None:
        self._i2c = i2c
        self.address = address

    def device_id(self) -> int:
        return device_id_from_status(self._i2c.read_byte_data(self.address, _REG_STATUS))

    def start_rtp(self, settings: ChipSettings, calibration: Calibration | None = None) -> None:
        """Leave standby, set the motor (type, voltages, drive time, ``calibration`` when known)
        and unsigned RTP data, then play RTP at 0 (silent)."""
        self._i2c.write_byte_data(self.address, _REG_MODE, _MODE_INTERNAL_TRIGGER)
        # Zero before entering RTP mode, so a value left by an earlier run never buzzes.
        self._i2c.write_byte_data(self.address, _REG_RTP_INPUT, 0)
        self._configure(settings, settings.od_clamp, calibration)
        self._update_bits(_REG_CONTROL3, _CONTROL3_DATA_FORMAT_RTP, True)
        self.play_rtp()

    def _configure(
        self, settings: ChipSettings, od_clamp: int, calibration: Calibration | None
    ) -> None:
        write = self._i2c.write_byte_data
        write(self.address, _REG_RATED_VOLTAGE, settings.rated_voltage)
        write(self.address, _REG_OD_CLAMP, od_clamp)
        feedback = self._i2c.read_byte_data(self.address, _REG_FEEDBACK_CONTROL)
        wanted = feedback | _FEEDBACK_N_ERM_LRA if settings.lra else feedback & ~_FEEDBACK_N_ERM_LRA
        if calibration is not None:
            write(self.address, _REG_A_CAL_COMP, calibration.a_cal_comp)
            write(self.address, _REG_A_CAL_BEMF, calibration.a_cal_bemf)
            wanted = (wanted & ~BEMF_GAIN_MASK) | calibration.bemf_gain
        if wanted & 0xFF != feedback:
            write(self.address, _REG_FEEDBACK_CONTROL, wanted & 0xFF)
        control1 = self._i2c.read_byte_data(self.address, _REG_CONTROL1)
        wanted = (control1 & ~_CONTROL1_DRIVE_TIME & 0xFF) | settings.drive_time
        if wanted != control1:
            write(self.address, _REG_CONTROL1, wanted)

    def calibrate(
        self,
        settings: ChipSettings,
        *,
        timeout_s: float = CALIBRATION_TIMEOUT_S,
        sleep: Callable[[float], None] = time.sleep,
    ) -> Calibration | str:
        """Run the chip's auto-calibration (SLOS854 8.5.6): its results, or what went wrong.

        The chip is left in standby whatever happens, so that a calibration cut short never
        leaves its motor driven; ``start_rtp`` sets it up again."""
        write, read = self._i2c.write_byte_data, self._i2c.read_byte_data
        try:
            write(self.address, _REG_MODE, _MODE_AUTO_CALIBRATION)
            self._configure(settings, settings.calibration_od_clamp, None)
            write(self.address, _REG_GO, 1)
            deadline = time.monotonic() + timeout_s
            while read(self.address, _REG_GO) & 1:
                if time.monotonic() > deadline:
                    write(self.address, _REG_GO, 0)  # stops it
                    return f"GO did not clear within {timeout_s:g} s"
                sleep(_CALIBRATION_POLL_S)
            if read(self.address, _REG_STATUS) & _STATUS_DIAG_RESULT:
                return "DIAG_RESULT set in STATUS: the chip found no motor it could calibrate"
            return Calibration(
                a_cal_comp=read(self.address, _REG_A_CAL_COMP),
                a_cal_bemf=read(self.address, _REG_A_CAL_BEMF),
                bemf_gain=read(self.address, _REG_FEEDBACK_CONTROL) & BEMF_GAIN_MASK,
            )
        finally:
            write(self.address, _REG_MODE, _MODE_STANDBY)

    def play_rtp(self) -> None:
        self._i2c.write_byte_data(self.address, _REG_MODE, _MODE_REAL_TIME_PLAYBACK)

    def set_rtp(self, level: int) -> None:
        if not 0 <= level <= RTP_FULL_SCALE:
            raise ParameterError("RTP level", level, f"an integer in 0..{RTP_FULL_SCALE}")
        self._i2c.write_byte_data(self.address, _REG_RTP_INPUT, level)

    def standby(self) -> None:
        self._i2c.write_byte_data(self.address, _REG_MODE, _MODE_STANDBY)

    def reads_off(self) -> str | None:
        """None when the registers read back silent (standby, RTP 0); else what they hold.

        With the enable line low the datasheet says the chip may not take writes: before
        the line goes high, each chip must show that it took its "off"."""
        mode = self._i2c.read_byte_data(self.address, _REG_MODE)
        rtp = self._i2c.read_byte_data(self.address, _REG_RTP_INPUT)
        if mode & _MODE_STANDBY and rtp == 0:
            return None
        return f"MODE 0x{mode:02X}, RTP_INPUT 0x{rtp:02X}"

    def _update_bits(self, register: int, mask: int, on: bool) -> None:
        # Read-modify-write: the other bits hold calibration and loop settings.
        value = self._i2c.read_byte_data(self.address, register)
        wanted = value | mask if on else value & ~mask & 0xFF
        if wanted != value:
            self._i2c.write_byte_data(self.address, register, wanted)


def check_wiring(layout: Layout) -> list[str]:
    """Every problem that keeps ``layout`` from driving hardware (empty when it can)."""
    problems: list[str] = []
    if not layout.multiplexers:
        problems.append("multiplexers is empty: list the TCA9548A addresses (0x70..0x77)")
    for address in layout.multiplexers:
        if address not in MULTIPLEXER_ADDRESSES:
            problems.append(f"multiplexer 0x{address:02X} is outside the TCA9548A range 0x70..0x77")
    if len(set(layout.multiplexers)) != len(layout.multiplexers):
        problems.append("multiplexers lists an address twice")
    if layout.actuator_type not in ("ERM", "LRA"):
        problems.append(f"actuator_type {layout.actuator_type!r} must be 'ERM' or 'LRA'")
    wired: dict[tuple[int, int], Wire] = {}
    channels: dict[tuple[int, int], Wire] = {}
    for wire in layout.wiring:
        problems.extend(_wire_problems(layout, wire, wired, channels))
    unwired = [
        f"row {row}, column {column}"
        for row in range(layout.rows)
        for column in range(layout.columns)
        if (row, column) not in wired
    ]
    if unwired:
        problems.append(f"no wiring for actuator(s) {'; '.join(unwired)}")
    return problems


def _wire_problems(
    layout: Layout,
    wire: Wire,
    wired: dict[tuple[int, int], Wire],
    channels: dict[tuple[int, int], Wire],
) -> list[str]:
    name = f"wire for row {wire.row}, column {wire.column}"
    problems = []
    if not (0 <= wire.row < layout.rows and 0 <= wire.column < layout.columns):
        problems.append(
            f"{name} is outside the {layout.rows} x {layout.columns} grid "
            f"(row 0..{layout.rows - 1}, column 0..{layout.columns - 1})"
        )
    if wire.multiplexer not in layout.multiplexers:
        problems.append(f"{name} uses multiplexer 0x{wire.multiplexer:02X}, not in multiplexers")
    if wire.channel not in CHANNELS:
        problems.append(f"{name} uses channel {wire.channel}, outside the range 0..7")
    if (wire.row, wire.column) in wired:
        problems.append(f"{name} appears twice")
    other = channels.get((wire.multiplexer, wire.channel))
    if other is not None:
        problems.append(
            f"{name} shares multiplexer 0x{wire.multiplexer:02X} channel {wire.channel} with "
            f"row {other.row}, column {other.column}: one DRV2605L per channel"
        )
    wired[(wire.row, wire.column)] = wire
    channels[(wire.multiplexer, wire.channel)] = wire
    return problems


@dataclass(frozen=True)
class _Actuator:
    wire: Wire
    chip: DRV2605L

    @property
    def where(self) -> str:
        w = self.wire
        return (
            f"multiplexer 0x{w.multiplexer:02X} channel {w.channel} "
            f"(actuator row {w.row}, column {w.column})"
        )


_CHECK_HINT = "check the wiring or run 'feelmysign scan'"


# Said with every failed chip check: the off went out before the check.
_OTHERS_OFF = "(every chip that answered was switched off first)"


def _off_failed_message(problems: list[str]) -> str:
    listed = "\n".join(f"  - {p}" for p in problems)
    return (
        "Could not switch off every actuator; if a motor keeps vibrating, cut the "
        f"sleeve's power:\n{listed}"
    )


class Drv2605Backend(GridBackend):
    """Drives one DRV2605L per actuator, wired as ``layout.wiring`` says.

    ``bus`` is any :class:`~feelmysign.backends.i2c.I2CBus` (the emulated bus in
    tests); without it ``/dev/i2c-<layout.i2c_bus>`` is opened on ``open()`` and
    closed on ``close()``. An injected bus is left open: its owner closes it.

    ``leave_out_missing`` (for ``feelmysign buzz``, to try the motors that are there):
    a chip that does not answer at ``open`` is left out, named in ``missing``, instead of
    failing the open; a wrong chip still fails it. Driving a left-out actuator is an error.
    """

    def __init__(
        self,
        layout: Layout,
        *,
        bus: I2CBus | None = None,
        telemetry: ActuatorTelemetry | None = None,
        enable: Line | None = None,
        calibration: CalibrationStore | None = None,
        calibrate: bool = False,
        leave_out_missing: bool = False,
        bus_lock: BusLock | None = None,
    ) -> None:
        super().__init__(layout, telemetry=telemetry)
        self._leave_out_missing = leave_out_missing
        # The bus's lock (feelmysign.backends.bus_lock), taken by the opener: let go on close,
        # after every motor is off.
        self._bus_lock = bus_lock
        self._guardian: Guardian | None = None
        self.missing: dict[tuple[int, int], str] = {}  # left out at open: actuator -> where
        self._bus = bus
        # Auto-calibration results: restored from ``calibration`` at every open; a chip without
        # one there is calibrated on open and its result kept. ``calibrate``: every chip is
        # calibrated again on open (feelmysign scan --calibrate). With neither, the chips keep
        # whatever calibration they hold.
        self._store = calibration
        self._calibrate_all = calibrate
        self._settings: ChipSettings | None = None  # worked out on open, after the off
        self._calibrations: dict[tuple[int, int], Calibration] = {}
        # Every chip's EN pin (layout.enable): low until every chip is off and checked, and
        # dropped before any I2C "off". None: EN tied high, only I2C switches a motor off.
        self._enable = enable
        self._closing = False
        # Chips that stopped answering and have not taken an "off" since: their motor may be
        # on (without an enable line). ``retry_lost`` tries them again. key -> what failed.
        self._lost: dict[tuple[int, int], str] = {}
        self._owned_bus: I2CBus | None = None
        self._multiplexers: Multiplexers | None = None
        self._actuators: dict[tuple[int, int], _Actuator] = {}
        self._rtp_levels: dict[tuple[int, int], int] = {}  # what each chip holds, when known
        self._configured: set[tuple[int, int]] = set()  # chips set up for RTP by start_rtp
        self._playing: set[tuple[int, int]] = set()  # of those, the ones out of standby

    @property
    def enable(self) -> Line | None:
        return self._enable

    @property
    def lost(self) -> dict[tuple[int, int], str]:
        """(row, column) -> why, for every chip that stopped answering and was not switched
        off since."""
        with self._lock:
            return dict(self._lost)

    @property
    def silenced(self) -> bool:
        """Open, with an enable line held low for a chip that does not answer (or failed its
        check): every motor is off whatever is written to it, until that chip answers."""
        # No lock: read on the path of every stroke's receipt, and each name is read whole.
        enable = self._enable
        return enable is not None and self.is_open and bool(self._lost) and not enable.high

    def describe(self, key: tuple[int, int]) -> str:
        """Where the chip of actuator ``key`` (row, column) hangs, in words."""
        actuator = self._actuators.get(key)
        if actuator is None:
            return f"actuator row {key[0]}, column {key[1]}"
        return actuator.where

    @property
    def calibrations(self) -> dict[tuple[int, int], Calibration]:
        """(row, column) -> the calibration results the chip was given (restored or measured)."""
        with self._lock:
            return dict(self._calibrations)

    def wire(self, key: tuple[int, int]) -> Wire | None:
        actuator = self._actuators.get(key)
        return None if actuator is None else actuator.wire

    def switch_off_unchecked(self) -> list[str]:
        """Before (or instead of) ``open``: every chip that answers off, none checked; what failed.

        For the very start of a process, when a crash may have left motors on:
        it never raises, and leaves the backend as it found it (not open).
        """
        with self._lock:
            if self.is_open:
                return []
            problems = []
            if self._enable is not None:
                try:  # first, before any I2C: every motor off at once, the lost ones included
                    self._enable.request()
                except HardwareError as error:
                    problems.append(str(error))
            try:
                self._connect()
                return problems + self._off_problems()
            except (HardwareError, LayoutError) as error:
                return [*problems, str(error)]
            finally:
                self._multiplexers = None
                self._release()

    @property
    def bus(self) -> I2CBus | None:
        """The bus given at construction (an emulated one), None for the Pi's own."""
        return self._bus

    def _connect(self) -> Multiplexers:
        problems = check_wiring(self._layout)
        if problems:  # before any I2C traffic
            raise LayoutError(self._layout.name, problems)
        bus = self._bus
        if bus is None:
            bus = self._owned_bus = open_smbus(self._layout.i2c_bus)
        multiplexers = self._multiplexers = Multiplexers(bus, self._layout.multiplexers)
        self._actuators = {
            (w.row, w.column): _Actuator(
                w, DRV2605L(multiplexers.channel(w.multiplexer, w.channel))
            )
            for w in self._layout.wiring
        }
        return multiplexers

    def _open(self) -> None:
        multiplexers = self._connect()
        line_problem: HardwareError | None = None
        try:
            if self._enable is not None:
                try:  # low (shutdown) until every chip is off and checked
                    self._enable.request()
                except HardwareError as error:
                    line_problem = error  # the I2C "off" below goes out all the same
            # Off first, before any check can raise: after a crash a chip may still drive
            # its motor, and a missing or wrong chip elsewhere must not keep it running.
            off_problems = self._off_problems()
            self._check_chips(readback=self._enable is not None)
            if off_problems and self.missing:  # expected of the chips left out: the rest again
                off_problems = self._off_problems()
            if off_problems:  # every chip passed the check, yet one could not be switched off
                raise HardwareError(_off_failed_message(off_problems))
            if line_problem is not None:
                raise line_problem
            # Configuration comes after every motor is off and checked: nothing above waits
            # for the calibration file, and nothing here can delay an "off".
            self._settings = self._chip_settings()
            self._calibrations = self._stored_calibrations()
            for key, actuator in self._actuators.items():
                self._guard(actuator, "while being set up", self._start_rtp, key, actuator)
                self._rtp_levels[key] = 0
                self._configured.add(key)
                self._playing.add(key)
            if self._enable is not None and self.missing:
                # One line for every chip: raised, it would wake a missing chip that may
                # still hold a level. It stays low, and nothing is driven.
                listed = "; ".join(self.missing.values())
                raise HardwareError(
                    f"No DRV2605L answered on {listed}, and the {self._enable.description} "
                    "switches every chip: it stays low, so no motor can run until that chip "
                    f"answers; {_CHECK_HINT}"
                )
            if self._enable is not None:
                self._enable.set_high(True)  # every chip off, checked and set up: motors may run
            self._calibrate_missing()
        except BaseException:
            self._drop(release=True)  # low first, whatever failed
            # Leave no channel enabled, so 'feelmysign scan' starts from a clean bus.
            with contextlib.suppress(HardwareError):
                multiplexers.deselect_all()
            self._release()
            raise

    def _chip_settings(self) -> ChipSettings:
        try:
            return chip_settings(self._layout)
        except ValueError as error:  # a Layout built in code, past the file's checks
            raise LayoutError(
                self._layout.name,
                [f"{error}; set the motor's values from its datasheet (docs/sleeve-hardware.md)"],
            ) from None

    def _start_rtp(self, key: tuple[int, int], actuator: _Actuator) -> None:
        assert self._settings is not None  # opened: the layout is wired
        actuator.chip.start_rtp(self._settings, self._calibrations.get(key))

    def _chip_name(self, key: tuple[int, int]) -> str:
        wire = self._actuators[key].wire
        return f"0x{wire.multiplexer:02X}/{wire.channel}"

    def _stored_calibrations(self) -> dict[tuple[int, int], Calibration]:
        if self._store is None:
            return {}
        stored = self._store.results(motor_description(self._layout))
        found = {key: stored.get(self._chip_name(key)) for key in self._actuators}
        return {key: calibration for key, calibration in found.items() if calibration is not None}

    def _calibrate_missing(self) -> None:
        """Auto-calibrate every chip without a stored result (all, with ``calibrate``), one at
        a time (a calibration drives its motor for about a second), and keep the results."""
        if self._store is None and not self._calibrate_all:
            return
        settings = self._settings
        assert settings is not None
        todo = [k for k in self._actuators if self._calibrate_all or k not in self._calibrations]
        measured: dict[str, Calibration] = {}
        try:
            for key in todo:
                actuator = self._actuators[key]
                self._playing.discard(key)  # in standby once calibrate returns
                outcome = self._guard(
                    actuator, "while calibrating", actuator.chip.calibrate, settings
                )
                if isinstance(outcome, str):
                    raise HardwareError(
                        f"Auto-calibration of the DRV2605L on {actuator.where} failed ({outcome}). "
                        "Check that its motor is fitted and wired to OUT+ and OUT-, that "
                        f'actuator_type = "{self._layout.actuator_type}" is the motor\'s kind, and '
                        "that rated_voltage_v, overdrive_voltage_v (and, for an LRA, "
                        "resonant_frequency_hz) in the layout match the motor's datasheet; then "
                        "run 'feelmysign scan --layout FILE --calibrate'"
                    )
                self._calibrations[key] = outcome
                measured[self._chip_name(key)] = outcome
                self._guard(actuator, "after calibrating", self._start_rtp, key, actuator)
                self._playing.add(key)
                log.info(
                    "calibrated the DRV2605L on %s: its results are %s", actuator.where, outcome
                )
        finally:
            if measured and self._store is not None:
                try:
                    self._store.put(measured, motor_description(self._layout))
                except OSError as error:
                    log.warning(
                        "could not keep the calibration results in %s (%s): the chips "
                        "calibrate again at the next start",
                        self._store.path,
                        error.strerror or error,
                    )

    def _check_chips(self, *, readback: bool = False) -> None:
        """Every chip answers and is a DRV2605L (with ``readback``, also reads back "off":
        before an enable line goes high); HardwareError listing every one that is not."""
        try:
            problems = list(self._chip_problems(readback=readback).values())
        except HardwareError as error:  # a multiplexer did not answer: no chip can be checked
            problems = [str(error)]
        for key in self.missing:  # left out (leave_out_missing): the rest are driven
            self._actuators.pop(key, None)
        others_off = _OTHERS_OFF
        if self._enable is None:
            # A chip that does not answer cannot be switched off: its motor may still run.
            others_off = (
                f"{_OTHERS_OFF[:-1]}; a motor on a chip that did not answer may still run: if "
                "one keeps vibrating, cut the sleeve's power)"
            )
        else:
            others_off = f"{_OTHERS_OFF[:-1]}; the {self._enable.description} stays low)"
        if len(problems) == 1:
            raise HardwareError(f"{problems[0]} {others_off}")
        if problems:
            total = len(self._actuators)
            listed = "\n".join(f"  - {p}" for p in problems)
            raise HardwareError(
                f"{len(problems)} of {total} DRV2605L chips failed the check ({others_off[1:-1]}):"
                f"\n{listed}"
            )

    def _chip_problems(self, *, readback: bool) -> dict[tuple[int, int], str]:
        """(row, column) -> what is wrong, for every chip that fails the check."""
        problems: dict[tuple[int, int], str] = {}
        for key, actuator in self._actuators.items():
            try:
                device_id = actuator.chip.device_id()
                held = actuator.chip.reads_off() if readback else None
            except OSError as error:
                if is_no_answer(error) and self._leave_out_missing:
                    self.missing[key] = actuator.where
                elif is_no_answer(error):
                    problems[key] = f"No DRV2605L answered on {actuator.where}; {_CHECK_HINT}"
                else:
                    problems[key] = (
                        f"I2C error ({error}) reading the DRV2605L on {actuator.where}; "
                        f"{_CHECK_HINT}"
                    )
                continue
            if device_id not in SUPPORTED_DEVICE_IDS:
                problems[key] = (
                    f"The chip at 0x{DRV2605_ADDRESS:02X} on {actuator.where} is a "
                    f"{device_name(device_id)}, not a DRV2605L (device id 7) or DRV2605 (id 3); "
                    f"fit a DRV2605L there or {_CHECK_HINT}"
                )
            elif held is not None:
                problems[key] = (
                    f'The DRV2605L on {actuator.where} did not take its "off" ({held} read '
                    "back), so the enable line stays low; power the driver boards off and on"
                )
        return problems

    def _write(self, row: int, column: int, intensity: float) -> None:
        key = (row, column)
        level = rtp_level(intensity)
        if self._rtp_levels.get(key) == level:
            return  # a different intensity, the same register value
        if key in self.missing:
            raise HardwareError(
                f"No DRV2605L answered on {self.missing[key]} when the sleeve was opened; "
                f"{_CHECK_HINT}"
            )
        actuator = self._actuators[key]
        if key not in self._configured:  # after an I2C error the chip may have reset
            self._guard(actuator, "", self._start_rtp, key, actuator)
            self._configured.add(key)
            self._playing.add(key)
        elif key not in self._playing:  # in standby since all_off
            self._guard(actuator, "", actuator.chip.play_rtp)
            self._playing.add(key)
        self._guard(actuator, "", actuator.chip.set_rtp, level)
        self._rtp_levels[key] = level

    def _all_off(self) -> None:
        self._drop()  # first: every motor stops at once, a chip that does not answer included
        problems = self._off_problems()
        if self._enable is None:
            if problems:
                raise HardwareError(_off_failed_message(problems))
            return
        if problems:
            # Not an error: the line holds every motor off. It stays low until they answer.
            log.warning(
                "enable line held low: not every chip took the off:\n%s",
                "\n".join(f"  - {p}" for p in problems),
            )
            return
        self._raise_if_safe()

    def close(self) -> None:
        self.hold_low()
        switched_off = False
        try:
            super().close()
            switched_off = True
        finally:
            guardian, self._guardian = self._guardian, None
            if guardian is not None:  # before the bus is let go: then another may drive it
                guardian.dismiss(switched_off=switched_off and not self._lost)
            if self._bus_lock is not None:
                self._bus_lock.release()

    def guard(self, guardian: Guardian) -> None:
        """``guardian`` switches every motor off should this process die or be stopped
        (:mod:`feelmysign.guard`); dismissed on ``close``, once every motor is off."""
        self._guardian = guardian
        guardian.start()

    def hold_low(self) -> None:
        """The sleeve is stopping: the enable line low now, and it stays low through the
        all-offs on the way out. Takes no lock, so a write stuck on the bus cannot delay it."""
        self._closing = True  # read by _raise_if_safe: no all-off raises the line again
        self._drop()

    def check_driven(self) -> tuple[tuple[int, int], str] | None:
        """With an enable line: read STATUS from every chip whose motor is on; the first one
        that does not answer, and why (the line is low by then). None when all answer.

        A wire that comes loose while its motor runs is otherwise found only at the next
        write to that chip, which may be seconds later in a slow stroke: the player calls
        this every few milliseconds while motors run, so the line drops within them. Without
        a line nothing is gained in time (the motor cannot be stopped), so no bus traffic is
        spent on it."""
        with self._lock:
            if self._enable is None or not self.is_open or not self._enable.high:
                return None
            for key, level in self._rtp_levels.items():
                if level == 0:
                    continue
                actuator = self._actuators[key]
                try:
                    self._guard(actuator, "while its motor ran", actuator.chip.device_id)
                except HardwareError as error:
                    return key, str(error)
            return None

    def retry_lost(self) -> list[tuple[int, int]]:
        """Try "off" again on every chip that stopped answering; the ones that took it.

        A chip that answers again is switched off (RTP 0, standby) at once, so that a motor
        left on when its wire came loose does not run on when the wire comes back; the next
        stroke sets it up again. With an enable line held low for a lost chip, the line goes
        high again only once every chip answers and reads back off."""
        with self._lock:
            if not self.is_open or not self._lost or self._multiplexers is None:
                return []
            back = []
            with self._multiplexers.best_effort():
                for key in list(self._lost):
                    actuator = self._actuators[key]
                    try:
                        self._rtp_zero(key, actuator)
                        self._standby(key, actuator)
                    except HardwareError as error:
                        self._lost[key] = str(error)
                        continue
                    self._configured.discard(key)  # it may have reset: set it up again
                    del self._lost[key]
                    back.append(key)
            if back and not self._lost and self._enable is not None:
                self._all_off()  # every chip off again and checked, then the line goes high
            return back

    def _drop(self, *, release: bool = False) -> None:
        """The enable line low (and let go, with ``release``); never raises."""
        line = self._enable
        if line is None:
            return
        try:
            if release:
                line.release()
            elif line.high:
                line.set_high(False)
        except HardwareError as error:
            log.error("could not drive the enable line low: %s", error)

    def _raise_if_safe(self) -> None:
        """The enable line high again, once every chip answers and reads back off."""
        if self._enable is None or self._closing or not self.is_open or self._lost:
            return
        try:
            problems = self._chip_problems(readback=True)
        finally:
            with contextlib.suppress(HardwareError):
                if self._multiplexers is not None:
                    self._multiplexers.deselect_all()
        if problems:  # tried again with the lost chips (retry_lost)
            self._lost.update(problems)
            log.warning("enable line held low:\n%s", "\n".join(problems.values()))
            return
        self._enable.set_high(True)

    def _off_problems(self) -> list[str]:
        """Switch every chip that answers off (RTP 0, standby), then deselect every channel.

        Never raises for a chip or multiplexer that fails: it tries all of them
        and returns what failed, so that one broken part cannot keep the others on.
        """
        multiplexers = self._multiplexers
        if multiplexers is None:  # never opened: nothing was switched on
            return []
        problems: dict[tuple[int, int], str] = {}
        with multiplexers.best_effort():
            # RTP 0 on every chip first (the quickest way to silence them all), then
            # standby: either alone silences a motor, so both are tried on every chip.
            for step in (self._rtp_zero, self._standby):
                for key, actuator in self._actuators.items():
                    try:
                        step(key, actuator)
                    except HardwareError as error:
                        problems.setdefault(key, str(error))
        for key in self._actuators:
            if key in problems:
                self._lost[key] = problems[key]
            else:
                self._lost.pop(key, None)  # it took the off: its motor is off
        listed = list(problems.values())
        try:
            multiplexers.deselect_all()
        except HardwareError as error:
            listed.append(str(error))
        return listed

    def _rtp_zero(self, key: tuple[int, int], actuator: _Actuator) -> None:
        self._guard(actuator, "", actuator.chip.set_rtp, 0)
        self._rtp_levels[key] = 0

    def _standby(self, key: tuple[int, int], actuator: _Actuator) -> None:
        self._playing.discard(key)
        self._guard(actuator, "", actuator.chip.standby)

    def _release(self) -> None:
        self._drop(release=True)  # low, then let go: the pull-down keeps it low
        bus, self._owned_bus = self._owned_bus, None
        if bus is not None:
            bus.close()

    def _guard(
        self,
        actuator: _Actuator,
        doing: str,
        action: Callable[_P, _T],
        *args: _P.args,
        **kwargs: _P.kwargs,
    ) -> _T:
        """Run one chip access; an I2C error becomes a HardwareError naming the chip."""
        key = (actuator.wire.row, actuator.wire.column)
        try:
            return action(*args, **kwargs)
        except HardwareError as error:  # its multiplexer did not answer
            self._lose(key, str(error))
            raise
        except OSError as error:
            # First, before anything else: with an enable line, every motor stops now.
            self._drop()
            # The chip's and the multiplexers' state are unknown now: rewrite them next time.
            self._rtp_levels.pop(key, None)
            self._configured.discard(key)
            self._playing.discard(key)
            if self._multiplexers is not None:
                self._multiplexers.invalidate()
            when = f" {doing}" if doing else ""
            message = (
                f"The DRV2605L on {actuator.where} stopped answering{when} ({error}); {_CHECK_HINT}"
            )
            self._lost[key] = message
            raise HardwareError(message) from error

    def _lose(self, key: tuple[int, int], message: str) -> None:
        self._drop()
        self._rtp_levels.pop(key, None)
        self._configured.discard(key)
        self._playing.discard(key)
        self._lost[key] = message
