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
from collections.abc import Callable
from dataclasses import dataclass
from typing import ParamSpec, TypeVar

from feelmysign.backends.all_off import DRV2605_ADDRESS as DRV2605_ADDRESS  # re-exported
from feelmysign.backends.all_off import MODE_STANDBY, REG_MODE, REG_RTP_INPUT
from feelmysign.backends.base import GridBackend
from feelmysign.backends.i2c import I2CBus, is_no_answer, open_smbus
from feelmysign.backends.tca9548a import CHANNELS, MULTIPLEXER_ADDRESSES, Multiplexers
from feelmysign.backends.telemetry import ActuatorTelemetry
from feelmysign.errors import HardwareError, LayoutError, ParameterError
from feelmysign.layout import ActuatorType, Layout, Wire

# Register map (datasheet names); the ones the all-off writes come from all_off.
_REG_STATUS = 0x00
_REG_MODE = REG_MODE
_REG_RTP_INPUT = REG_RTP_INPUT
_REG_FEEDBACK_CONTROL = 0x1A
_REG_CONTROL3 = 0x1D

_STATUS_DEVICE_ID_SHIFT = 5  # STATUS[7:5] = DEVICE_ID
_MODE_INTERNAL_TRIGGER = 0x00  # active (STANDBY = 0), plays nothing until GO
_MODE_REAL_TIME_PLAYBACK = 0x05  # active, output amplitude = RTP_INPUT
_MODE_STANDBY = MODE_STANDBY
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

    def start_rtp(self, actuator_type: ActuatorType) -> None:
        """Leave standby, set the motor type and unsigned RTP data, then play RTP at 0 (silent)."""
        self._i2c.write_byte_data(self.address, _REG_MODE, _MODE_INTERNAL_TRIGGER)
        # Zero before entering RTP mode, so a value left by an earlier run never buzzes.
        self._i2c.write_byte_data(self.address, _REG_RTP_INPUT, 0)
        lra = actuator_type == "LRA"
        self._update_bits(_REG_FEEDBACK_CONTROL, _FEEDBACK_N_ERM_LRA, lra)
        self._update_bits(_REG_CONTROL3, _CONTROL3_DATA_FORMAT_RTP, True)
        self.play_rtp()

    def play_rtp(self) -> None:
        self._i2c.write_byte_data(self.address, _REG_MODE, _MODE_REAL_TIME_PLAYBACK)

    def set_rtp(self, level: int) -> None:
        if not 0 <= level <= RTP_FULL_SCALE:
            raise ParameterError("RTP level", level, f"an integer in 0..{RTP_FULL_SCALE}")
        self._i2c.write_byte_data(self.address, _REG_RTP_INPUT, level)

    def standby(self) -> None:
        self._i2c.write_byte_data(self.address, _REG_MODE, _MODE_STANDBY)

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
        leave_out_missing: bool = False,
    ) -> None:
        super().__init__(layout, telemetry=telemetry)
        self._leave_out_missing = leave_out_missing
        self.missing: dict[tuple[int, int], str] = {}  # left out at open: actuator -> where
        self._bus = bus
        self._owned_bus: I2CBus | None = None
        self._multiplexers: Multiplexers | None = None
        self._actuators: dict[tuple[int, int], _Actuator] = {}
        self._rtp_levels: dict[tuple[int, int], int] = {}  # what each chip holds, when known
        self._configured: set[tuple[int, int]] = set()  # chips set up for RTP by start_rtp
        self._playing: set[tuple[int, int]] = set()  # of those, the ones out of standby

    def switch_off_unchecked(self) -> list[str]:
        """Before (or instead of) ``open``: every chip that answers off, none checked; what failed.

        For the very start of a process, when a crash may have left motors on:
        it never raises, and leaves the backend as it found it (not open).
        """
        with self._lock:
            if self.is_open:
                return []
            try:
                self._connect()
                return self._off_problems()
            except (HardwareError, LayoutError) as error:
                return [str(error)]
            finally:
                self._multiplexers = None
                self._release()

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
        try:
            # Off first, before any check can raise: after a crash a chip may still drive
            # its motor, and a missing or wrong chip elsewhere must not keep it running.
            off_problems = self._off_problems()
            self._check_chips()
            if off_problems and self.missing:  # expected of the chips left out: the rest again
                off_problems = self._off_problems()
            if off_problems:  # every chip passed the check, yet one could not be switched off
                raise HardwareError(_off_failed_message(off_problems))
            for key, actuator in self._actuators.items():
                self._guard(
                    actuator,
                    "while being set up",
                    actuator.chip.start_rtp,
                    self._layout.actuator_type,
                )
                self._rtp_levels[key] = 0
                self._configured.add(key)
                self._playing.add(key)
        except BaseException:
            # Leave no channel enabled, so 'feelmysign scan' starts from a clean bus.
            with contextlib.suppress(HardwareError):
                multiplexers.deselect_all()
            self._release()
            raise

    def _check_chips(self) -> None:
        problems = []
        for actuator in self._actuators.values():
            try:
                device_id = actuator.chip.device_id()
            except OSError as error:
                if is_no_answer(error) and self._leave_out_missing:
                    self.missing[(actuator.wire.row, actuator.wire.column)] = actuator.where
                elif is_no_answer(error):
                    problems.append(f"No DRV2605L answered on {actuator.where}; {_CHECK_HINT}")
                else:
                    problems.append(
                        f"I2C error ({error}) reading the DRV2605L on {actuator.where}; "
                        f"{_CHECK_HINT}"
                    )
                continue
            if device_id not in SUPPORTED_DEVICE_IDS:
                problems.append(
                    f"The chip at 0x{DRV2605_ADDRESS:02X} on {actuator.where} is a "
                    f"{device_name(device_id)}, not a DRV2605L (device id 7) or DRV2605 (id 3); "
                    f"fit a DRV2605L there or {_CHECK_HINT}"
                )
        for key in self.missing:
            del self._actuators[key]
        if len(problems) == 1:
            raise HardwareError(f"{problems[0]} {_OTHERS_OFF}")
        if problems:
            total = len(self._actuators)
            listed = "\n".join(f"  - {p}" for p in problems)
            raise HardwareError(
                f"{len(problems)} of {total} DRV2605L chips failed the check ({_OTHERS_OFF}):"
                f"\n{listed}"
            )

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
            self._guard(actuator, "", actuator.chip.start_rtp, self._layout.actuator_type)
            self._configured.add(key)
            self._playing.add(key)
        elif key not in self._playing:  # in standby since all_off
            self._guard(actuator, "", actuator.chip.play_rtp)
            self._playing.add(key)
        self._guard(actuator, "", actuator.chip.set_rtp, level)
        self._rtp_levels[key] = level

    def _all_off(self) -> None:
        problems = self._off_problems()
        if problems:
            raise HardwareError(_off_failed_message(problems))

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
        except OSError as error:
            # The chip's and the multiplexers' state are unknown now: rewrite them next time.
            self._rtp_levels.pop(key, None)
            self._configured.discard(key)
            self._playing.discard(key)
            if self._multiplexers is not None:
                self._multiplexers.invalidate()
            when = f" {doing}" if doing else ""
            raise HardwareError(
                f"The DRV2605L on {actuator.where} stopped answering{when} ({error}); {_CHECK_HINT}"
            ) from error
