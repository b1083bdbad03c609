"""An emulated I2C bus with TCA9548A multiplexers and DRV2605L chips, register by register.

It has the ``smbus2.SMBus`` methods the drivers use, so the hardware backend
runs on it unchanged: in tests, and behind ``--emulate`` without a sleeve.
It is written from the datasheets, independently of the driver (constants are
repeated on purpose), so that a misreading in the driver shows up as a
difference instead of being shared.

What it models:

- a TCA9548A answers at its address; its control register is the channel
  mask (bit n enables channel n) and reading returns it. Like the chip, it
  keeps the last byte of a write, so ``write_byte_data(0x70, r, v)`` stores v.
- a DRV2605L (address 0x5A) hangs on one multiplexer channel and answers only
  while that channel is enabled. Its register file starts at the datasheet's
  reset values (MODE 0x40: standby); STATUS, VBAT and LRA_RESONANCE_PERIOD are
  read-only; MODE bit 7 (DEV_RESET) restores the reset values.
- auto-calibration: GO (0x0C) written 1 in MODE 7, out of standby, with EN high, runs
  it; GO reads 1 for a few reads (the chip is busy), then clears, with DIAG_RESULT
  (STATUS bit 3) 0 and results in A_CAL_COMP, A_CAL_BEMF and FEEDBACK's BEMF_GAIN
  worked out from the motor settings (plausible, not physics); with
  ``fail_calibration`` set (a motor missing), DIAG_RESULT 1 and the results unchanged.
  ``calibrations`` counts the calibrations run.
- nobody answering an address raises ``OSError(121, 'Remote I/O error')`` as
  Linux's i2c-dev does; two devices answering one address (two enabled
  channels with a chip each) is a bus conflict: counted, logged and raised as
  :class:`BusConflictError`.

- an optional enable line (:class:`EmulatedEnableLine`): the GPIO every chip's
  EN pin hangs on, with a pull-down. A chip whose EN is low drives nothing
  (``output`` is 0) whatever its registers say; its registers still take
  writes (as TI found on its own evaluation module, though the datasheet
  discourages I2C with EN low). The line is high only while a living process
  drives it high: the process that drives it is recorded (pid and start
  time), and once that process is gone the line reads low, as the pull-down
  takes a real line low when the process holding it dies.

Faults to inject: ``detach_chip`` (a missing chip), ``connected = False`` (a
broken wire, registers kept), ``device_id`` (a wrong chip, e.g. 4 = DRV2604).
A chip that stops answering records when (``lost_at``: the wall clock in ms and
the bus's transaction count), and so does the enable line when it changes, so
a test can read from the state file how soon after a loss every motor was off.

``on_write``, when set, is called after every write the bus applied, while the
bus is locked: :mod:`feelmysign.backends.emulated_state` uses it to keep the
registers in a file, so that they outlive the process as a real chip's do.
"""

from __future__ import annotations

import errno
import os
import threading
import time
from collections import Counter, deque, namedtuple

# A restarting sleeve on an emulated bus imports this before it switches its motors
# off: no typing, dataclasses or TOML reader at run time. mypy reads this name as True.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Literal, NamedTuple

    from feelmysign.layout import Layout

    Operation = Literal["read_byte", "write_byte", "read_byte_data", "write_byte_data"]

DRV2605L_ADDRESS = 0x5A
DRV2605L_DEVICE_ID = 7
DRV2604_DEVICE_ID = 4

# DRV2605L register file: reset values from the datasheet's register map.
_DRV2605L_RESET_VALUES = (
    0xE0,  # 0x00 STATUS: DEVICE_ID = 7 in bits 7:5 (set from device_id)
    0x40,  # 0x01 MODE: STANDBY, internal trigger
    0x00,  # 0x02 RTP_INPUT
    0x01,  # 0x03 LIBRARY_SEL
    0x01,  # 0x04 WAVEFORM_SEQUENCER_1
    0x00,  # 0x05 WAVEFORM_SEQUENCER_2
    0x00,  # 0x06 WAVEFORM_SEQUENCER_3
    0x00,  # 0x07 WAVEFORM_SEQUENCER_4
    0x00,  # 0x08 WAVEFORM_SEQUENCER_5
    0x00,  # 0x09 WAVEFORM_SEQUENCER_6
    0x00,  # 0x0A WAVEFORM_SEQUENCER_7
    0x00,  # 0x0B WAVEFORM_SEQUENCER_8
    0x00,  # 0x0C GO
    0x00,  # 0x0D OVERDRIVE_TIME_OFFSET
    0x00,  # 0x0E SUSTAIN_TIME_OFFSET_POSITIVE
    0x00,  # 0x0F SUSTAIN_TIME_OFFSET_NEGATIVE
    0x00,  # 0x10 BRAKE_TIME_OFFSET
    0x05,  # 0x11 AUDIO_TO_VIBE_CONTROL
    0x19,  # 0x12 AUDIO_TO_VIBE_MIN_INPUT_LEVEL
    0xFF,  # 0x13 AUDIO_TO_VIBE_MAX_INPUT_LEVEL
    0x19,  # 0x14 AUDIO_TO_VIBE_MIN_OUTPUT_DRIVE
    0xFF,  # 0x15 AUDIO_TO_VIBE_MAX_OUTPUT_DRIVE
    0x3E,  # 0x16 RATED_VOLTAGE
    0x8C,  # 0x17 OVERDRIVE_CLAMP_VOLTAGE
    0x0C,  # 0x18 AUTO_CALIBRATION_COMPENSATION_RESULT
    0x6C,  # 0x19 AUTO_CALIBRATION_BACK_EMF_RESULT
    0x36,  # 0x1A FEEDBACK_CONTROL: N_ERM_LRA = 0 (ERM), FB_BRAKE_FACTOR 3, LOOP_GAIN 1, BEMF_GAIN 2
    0x93,  # 0x1B CONTROL1
    0xF5,  # 0x1C CONTROL2
    0xA0,  # 0x1D CONTROL3: NG_THRESH 2, ERM_OPEN_LOOP 1, DATA_FORMAT_RTP 0 (signed)
    0x20,  # 0x1E CONTROL4
    0x80,  # 0x1F CONTROL5
    0x33,  # 0x20 LRA_OPEN_LOOP_PERIOD
    0x00,  # 0x21 VBAT
    0x00,  # 0x22 LRA_RESONANCE_PERIOD
)
STATUS, MODE, RTP_INPUT, FEEDBACK_CONTROL, CONTROL3 = 0x00, 0x01, 0x02, 0x1A, 0x1D
GO, RATED_VOLTAGE, OD_CLAMP, A_CAL_COMP, A_CAL_BEMF, CONTROL1 = 0x0C, 0x16, 0x17, 0x18, 0x19, 0x1B
_MODE_AUTO_CALIBRATION = 0x07
_STATUS_DIAG_RESULT = 0x08
_CALIBRATION_BUSY_READS = 3  # GO reads 1 this many times before it clears
_READ_ONLY = frozenset({STATUS, 0x21, 0x22})
_MODE_DEV_RESET = 0x80
_MODE_STANDBY = 0x40
_MODE_FIELD = 0x07
_MODE_REAL_TIME_PLAYBACK = 0x05
_FEEDBACK_N_ERM_LRA = 0x80
_CONTROL3_DATA_FORMAT_RTP = 0x08


class BusConflictError(OSError):
    """Two or more devices answered one address at once (e.g. two enabled DRV2605L channels)."""

    def __init__(self, address: int, devices: list[str]) -> None:
        super().__init__(
            errno.EIO,
            f"bus conflict: {len(devices)} devices answer at 0x{address:02X} "
            f"({', '.join(devices)})",
        )
        self.address = address
        self.devices = devices


if TYPE_CHECKING:

    class Transaction(NamedTuple):
        """One bus transaction: ``device`` that answered (None: nobody); ``error`` if it failed."""

        op: Operation
        address: int
        register: int | None
        value: int | None
        device: str | None
        error: str | None = None

else:  # the same tuple, without importing typing
    Transaction = namedtuple(
        "Transaction", "op address register value device error", defaults=(None,)
    )


class EmulatedDRV2605L:
    """A DRV2605L's register file, with what a test wants to know about it."""

    def __init__(self, name: str, *, device_id: int = DRV2605L_DEVICE_ID) -> None:
        self.name = name
        self.address = DRV2605L_ADDRESS
        self.connected = True
        self.registers = bytearray(_DRV2605L_RESET_VALUES)
        self.writes: Counter[int] = Counter()  # register -> writes received
        self.reads: Counter[int] = Counter()
        self._pointer = 0
        self.device_id = device_id
        self.enabled = True  # the EN pin: low is shutdown, the motor driven by nothing
        # When a transaction first found it not answering (ms, bus transaction), since it last did.
        self.lost_at: tuple[float, int] | None = None
        self.fail_calibration = False  # a fault: the next calibrations set DIAG_RESULT
        self.calibrations = 0
        self._busy_reads = 0  # while calibrating: GO reads left before it clears

    @property
    def device_id(self) -> int:
        return self.registers[STATUS] >> 5

    @device_id.setter
    def device_id(self, device_id: int) -> None:
        self.registers[STATUS] = (self.registers[STATUS] & 0x1F) | ((device_id & 0b111) << 5)

    @property
    def standby(self) -> bool:
        return bool(self.registers[MODE] & _MODE_STANDBY)

    @property
    def rtp_mode(self) -> bool:
        return (self.registers[MODE] & _MODE_FIELD) == _MODE_REAL_TIME_PLAYBACK

    @property
    def lra(self) -> bool:
        return bool(self.registers[FEEDBACK_CONTROL] & _FEEDBACK_N_ERM_LRA)

    @property
    def rtp_unsigned(self) -> bool:
        return bool(self.registers[CONTROL3] & _CONTROL3_DATA_FORMAT_RTP)

    @property
    def output(self) -> float:
        """The drive the motor gets, 0..1 (only RTP mode is modelled; other modes give 0)."""
        if not self.enabled or self.standby or not self.rtp_mode:
            return 0.0
        rtp = self.registers[RTP_INPUT]
        if self.rtp_unsigned:
            return rtp / 255
        signed = rtp - 256 if rtp >= 128 else rtp
        return max(0, signed) / 127  # negative values brake: nothing felt

    @property
    def write_count(self) -> int:
        return sum(self.writes.values())

    def reset(self) -> None:
        device_id = self.device_id
        self.registers[:] = bytes(_DRV2605L_RESET_VALUES)
        self.device_id = device_id

    def read(self, register: int) -> int:
        self._check(register)
        self.reads[register] += 1
        self._pointer = register
        if register == GO and self._busy_reads > 0:
            self._busy_reads -= 1
            if self._busy_reads == 0:
                self._finish_calibration()
        return self.registers[register]

    def write(self, register: int, value: int) -> None:
        self._check(register)
        self.writes[register] += 1
        self._pointer = register
        if register == MODE and value & _MODE_DEV_RESET:
            self._busy_reads = 0
            self.reset()  # DEV_RESET clears itself once the reset is done
        elif register not in _READ_ONLY:
            self.registers[register] = value
        if register == GO and value & 1 and self._calibration_mode:
            self._busy_reads = _CALIBRATION_BUSY_READS
        elif (register == GO and not value & 1) or (register == MODE and value & _MODE_STANDBY):
            self._busy_reads = 0  # GO 0 or standby stops a calibration
            self.registers[GO] = 0

    @property
    def _calibration_mode(self) -> bool:
        mode = self.registers[MODE]
        return self.enabled and not self.standby and (mode & _MODE_FIELD) == _MODE_AUTO_CALIBRATION

    def _finish_calibration(self) -> None:
        self.calibrations += 1
        self.registers[GO] = 0
        if self.fail_calibration:
            self.registers[STATUS] |= _STATUS_DIAG_RESULT
            return
        self.registers[STATUS] &= ~_STATUS_DIAG_RESULT & 0xFF
        # Plausible values that depend on the settings, so that a test sees them written.
        rated = self.registers[RATED_VOLTAGE]
        self.registers[A_CAL_COMP] = 0x0D + rated % 4
        self.registers[A_CAL_BEMF] = min(0xFF, 0x40 + rated // 2)
        gain = 3 if self.lra else 1
        self.registers[FEEDBACK_CONTROL] = (self.registers[FEEDBACK_CONTROL] & 0xFC) | gain

    def set_pointer(self, register: int) -> None:
        self._check(register)
        self._pointer = register

    def read_current(self) -> int:
        return self.read(self._pointer)

    def _check(self, register: int) -> None:
        if not 0 <= register < len(self.registers):
            raise ValueError(
                f"register 0x{register:02X} does not exist on the DRV2605L "
                f"(0x00..0x{len(self.registers) - 1:02X})"
            )


class EmulatedTCA9548A:
    def __init__(self, address: int) -> None:
        self.address = address
        self.name = f"TCA9548A 0x{address:02X}"
        self.connected = True
        self.control = 0x00  # power-on: every channel disabled
        self.writes = 0

    @property
    def enabled_channels(self) -> tuple[int, ...]:
        return tuple(channel for channel in range(8) if self.control >> channel & 1)


_Device = EmulatedTCA9548A | EmulatedDRV2605L


def process_identity(pid: int) -> int | None:
    """The start time of process ``pid`` (clock ticks since boot, /proc/PID/stat field 22), so
    that a pid the kernel reused is not taken for the process that drove the line; None when
    the process does not exist or is a zombie (dead, not yet reaped)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as stat:
            text = stat.read()
    except OSError:
        if os.path.isdir("/proc/self"):
            return None
        try:  # no /proc (not Linux): whether the pid exists is all that can be known
            os.kill(pid, 0)
        except ProcessLookupError:
            return None
        except PermissionError:
            pass
        return 0
    fields = text[text.rfind(")") + 2 :].split()  # after "pid (name) "
    if not fields or fields[0] in ("Z", "X"):
        return None
    return int(fields[19])  # field 22 of the whole line


class EmulatedEnableLine:
    """The GPIO line on every chip's EN pin, pulled down: the same methods as the real one.

    ``level`` is what the last process that drove the line drove it to, ``holder``
    that process (pid, start time); the line is high (``effective_high``) only while
    that process lives. ``changed_at`` is when it last changed (ms, bus transaction).
    """

    def __init__(self, chip: str, line: int) -> None:
        self.chip = chip
        self.line = line
        self.level = False
        self.holder: tuple[int, int] | None = None
        self.changed_at: tuple[float, int] | None = None
        self.rises = 0  # how many times it went high, ever: a test sees that it never did
        self._bus: EmulatedI2CBus | None = None

    @property
    def description(self) -> str:
        return f"emulated enable line ({self.chip} line {self.line})"

    @property
    def holder_alive(self) -> bool:
        if self.holder is None:
            return False
        pid, started = self.holder
        return pid == os.getpid() or process_identity(pid) == started

    @property
    def effective_high(self) -> bool:
        """High only while it is driven high by a process that still exists (the pull-down)."""
        return self.level and self.holder_alive

    @property
    def held_here(self) -> bool:
        return self.holder is not None and self.holder[0] == os.getpid()

    @property
    def high(self) -> bool:
        return self.held_here and self.level

    def request(self) -> None:
        if self.held_here:
            return
        if self.holder_alive:
            from feelmysign.errors import HardwareError

            assert self.holder is not None
            raise HardwareError(
                f"the {self.description} is in use by process {self.holder[0]} (another sleeve "
                "on this state file?); stop it, then try again"
            )
        pid = os.getpid()
        self.holder = (pid, process_identity(pid) or 0)
        self._change(False)

    def set_high(self, high: bool) -> None:
        if not self.held_here:
            from feelmysign.errors import HardwareError

            raise HardwareError(f"the {self.description} is not requested; this is a bug")
        self._change(high)

    def release(self) -> None:
        if not self.held_here:
            return
        self._change(False)
        self.holder = None
        self._changed()

    def _change(self, high: bool) -> None:
        bus = self._bus
        transactions = 0 if bus is None else bus.transactions
        if high and not self.level:
            self.rises += 1
        self.level = high
        self.changed_at = (round(time.time() * 1000, 3), transactions)
        self._changed()

    def _changed(self) -> None:
        if self._bus is not None:
            self._bus.enable_changed()


class EmulatedI2CBus:
    """Multiplexers and DRV2605L chips on one emulated bus; smbus2-compatible byte transactions.

    ``log`` keeps the last ``log_size`` transactions (None: all).
    """

    def __init__(self, *, log_size: int | None = 10_000) -> None:
        self._lock = threading.RLock()
        self._multiplexers: dict[int, EmulatedTCA9548A] = {}
        self._chips: dict[tuple[int, int], EmulatedDRV2605L] = {}
        self._main_bus_chips: list[EmulatedDRV2605L] = []
        self.log: deque[Transaction] = deque(maxlen=log_size)
        self.conflicts = 0
        self.write_count = 0
        self.read_count = 0
        self.max_enabled_channels = 0  # the most channels ever enabled at once, all multiplexers
        self.transactions = 0  # every transaction tried, answered or not (kept in a state file)
        self.enable_line: EmulatedEnableLine | None = None
        self.closed = False
        self.on_write: Callable[[EmulatedI2CBus], None] | None = None
        # Called before every transaction, bus locked: a fault injected from outside lands.
        self.before_transaction: Callable[[EmulatedI2CBus], None] | None = None

    @classmethod
    def for_layout(
        cls, layout: Layout, *, device_id: int = DRV2605L_DEVICE_ID, log_size: int | None = 10_000
    ) -> EmulatedI2CBus:
        """A bus wired as ``layout`` says: its multiplexers, one chip per wired actuator."""
        bus = cls(log_size=log_size)
        for address in layout.multiplexers:
            bus.add_multiplexer(address)
        for wire in layout.wiring:
            bus.attach_chip(wire.multiplexer, wire.channel, device_id=device_id)
        if layout.enable is not None:
            bus.add_enable_line(layout.enable.chip, layout.enable.line)
        return bus

    def add_enable_line(self, chip: str, line: int) -> EmulatedEnableLine:
        """Every chip's EN pin on one pulled-down line (low until a process drives it high)."""
        with self._lock:
            if self.enable_line is None:
                self.enable_line = EmulatedEnableLine(chip, line)
            self.enable_line._bus = self
            self._apply_enable()
            return self.enable_line

    def enable_changed(self) -> None:
        """The line changed: every chip's EN follows, and the state is saved (``on_write``)."""
        with self._lock:
            self._apply_enable()
            if self.on_write is not None:
                self.on_write(self)

    def _apply_enable(self) -> None:
        high = self.enable_line is None or self.enable_line.effective_high
        for chip in (*self._chips.values(), *self._main_bus_chips):
            chip.enabled = high

    # -- building and inspecting ------------------------------------------------------------

    def add_multiplexer(self, address: int) -> EmulatedTCA9548A:
        if address not in range(0x70, 0x78):
            raise ValueError(f"a TCA9548A address is 0x70..0x77, not 0x{address:02X}")
        with self._lock:
            multiplexer = self._multiplexers.setdefault(address, EmulatedTCA9548A(address))
        return multiplexer

    def attach_chip(
        self, multiplexer: int, channel: int, *, device_id: int = DRV2605L_DEVICE_ID
    ) -> EmulatedDRV2605L:
        if multiplexer not in self._multiplexers or channel not in range(8):
            raise ValueError(
                f"no multiplexer 0x{multiplexer:02X} with a channel {channel} on this bus"
            )
        chip = EmulatedDRV2605L(f"DRV2605L 0x{multiplexer:02X}/{channel}", device_id=device_id)
        with self._lock:
            self._chips[(multiplexer, channel)] = chip
            chip.enabled = self.enable_line is None or self.enable_line.effective_high
        return chip

    def attach_main_bus_chip(self, *, device_id: int = DRV2605L_DEVICE_ID) -> EmulatedDRV2605L:
        """A DRV2605L wired straight to the bus: it answers whatever channel is enabled."""
        chip = EmulatedDRV2605L("DRV2605L on the main bus", device_id=device_id)
        with self._lock:
            self._main_bus_chips.append(chip)
        return chip

    def detach_chip(self, multiplexer: int, channel: int) -> EmulatedDRV2605L:
        with self._lock:
            return self._chips.pop((multiplexer, channel))

    def chip(self, *, mux: int, channel: int) -> EmulatedDRV2605L:
        return self._chips[(mux, channel)]

    def multiplexer(self, address: int) -> EmulatedTCA9548A:
        return self._multiplexers[address]

    @property
    def multiplexers(self) -> dict[int, EmulatedTCA9548A]:
        """address -> multiplexer."""
        return dict(self._multiplexers)

    @property
    def main_bus_chips(self) -> list[EmulatedDRV2605L]:
        return list(self._main_bus_chips)

    @property
    def chips(self) -> dict[tuple[int, int], EmulatedDRV2605L]:
        """(multiplexer, channel) -> chip."""
        return dict(self._chips)

    def enabled_channels(self) -> list[tuple[int, int]]:
        return [
            (address, channel)
            for address, multiplexer in sorted(self._multiplexers.items())
            for channel in multiplexer.enabled_channels
        ]

    # -- smbus2-compatible transactions ----------------------------------------------------

    def read_byte(self, i2c_addr: int, force: bool | None = None) -> int:
        return self._transact("read_byte", i2c_addr, None, None)

    def write_byte(self, i2c_addr: int, value: int, force: bool | None = None) -> None:
        self._transact("write_byte", i2c_addr, None, value)

    def read_byte_data(self, i2c_addr: int, register: int, force: bool | None = None) -> int:
        return self._transact("read_byte_data", i2c_addr, register, None)

    def write_byte_data(
        self, i2c_addr: int, register: int, value: int, force: bool | None = None
    ) -> None:
        self._transact("write_byte_data", i2c_addr, register, value)

    def close(self) -> None:
        self.closed = True

    # -- the bus itself ----------------------------------------------------------------------

    def _transact(
        self,
        op: Operation,
        address: int,
        register: int | None,
        value: int | None,
    ) -> int:
        if self.closed:
            raise ValueError("I/O on a closed I2C bus")
        for name, byte in (("address", address), ("register", register), ("value", value)):
            limit = 0x7F if name == "address" else 0xFF
            if byte is not None and not 0 <= byte <= limit:
                raise ValueError(f"{name} {byte} is outside the allowed range 0..{limit}")
        with self._lock:
            if self.before_transaction is not None:
                self.before_transaction(self)
            self.transactions += 1
            devices = self._answering(address)
            if len(devices) != 1:
                if not devices:
                    self._note_lost(address)
                error = self._no_answer(address, devices)
                self.log.append(Transaction(op, address, register, value, None, str(error)))
                raise error
            device = devices[0]
            if isinstance(device, EmulatedDRV2605L):
                device.lost_at = None
            result = self._apply(device, op, register, value)
            self.log.append(Transaction(op, address, register, value, device.name))
            if self.on_write is not None and op.startswith("write"):
                self.on_write(self)
            return result

    def _answering(self, address: int) -> list[_Device]:
        devices: list[_Device] = []
        multiplexer = self._multiplexers.get(address)
        if multiplexer is not None and multiplexer.connected:
            devices.append(multiplexer)
        reachable = list(self._main_bus_chips)
        for (mux_address, channel), chip in self._chips.items():
            mux = self._multiplexers[mux_address]
            if mux.connected and mux.control >> channel & 1:
                reachable.append(chip)
        devices.extend(c for c in reachable if c.connected and c.address == address)
        return devices

    def _note_lost(self, address: int) -> None:
        """A chip on an enabled channel whose wire is broken: when it was first found so."""
        for (mux_address, channel), chip in self._chips.items():
            mux = self._multiplexers[mux_address]
            selected = mux.connected and mux.control >> channel & 1
            if selected and not chip.connected and chip.address == address and chip.lost_at is None:
                chip.lost_at = (round(time.time() * 1000, 3), self.transactions)

    def _no_answer(self, address: int, devices: list[_Device]) -> OSError:
        if not devices:
            return OSError(errno.EREMOTEIO, "Remote I/O error")
        self.conflicts += 1
        return BusConflictError(address, [d.name for d in devices])

    def _apply(self, device: _Device, op: str, register: int | None, value: int | None) -> int:
        if op.startswith("write"):
            self.write_count += 1
        else:
            self.read_count += 1
        if isinstance(device, EmulatedTCA9548A):
            return self._apply_multiplexer(device, op, register, value)
        if op == "write_byte":  # sets the register pointer, as an SMBus "send byte" does
            assert value is not None
            device.set_pointer(value)
            return 0
        if op == "read_byte":
            return device.read_current()
        assert register is not None
        if op == "read_byte_data":
            return device.read(register)
        assert value is not None
        device.write(register, value)
        return 0

    def _apply_multiplexer(
        self, multiplexer: EmulatedTCA9548A, op: str, register: int | None, value: int | None
    ) -> int:
        # The TCA9548A has one register and keeps the last byte written to it; the
        # "register" byte of an SMBus data transaction is such a byte too.
        written = value if value is not None else register
        if written is not None:
            multiplexer.control = written
            multiplexer.writes += 1
            self.max_enabled_channels = max(self.max_enabled_channels, len(self.enabled_channels()))
        return multiplexer.control
