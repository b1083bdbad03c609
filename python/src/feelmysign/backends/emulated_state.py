"""The emulated I2C bus kept in a file, so that its registers outlive the process.

A real DRV2605L keeps its registers, and so keeps driving its motor, when the
process that wrote them dies; a TCA9548A keeps its enabled channels. The
emulated bus on its own forgets everything with its process, so it cannot
show what a crash leaves behind. With a state file (``--emulate-state FILE`` on
``sleeve``, ``scan`` and ``buzz``) every register write is written through to
the file, and the next process starts from what the last one left: a test can
``kill -9`` a sleeve mid-stroke, see the motor still on in the file, restart
the sleeve and read back every motor's drive level.

The file is JSON, written whole to a temporary file and renamed over the old
one after every write, so a process killed at any moment leaves either the
state before or the state after its last write, never half a file (a rename
survives the death of the process; like the chips themselves, it is not meant
to survive a power cut)::

    {
      "format": "feelmysign-emulated-i2c/1",
      "multiplexers": {"0x70": {"control": 0, "connected": true}, ...},
      "chips": {
        "0x70/0": {"device_id": 7, "connected": true, "drive": 0.0,
                   "registers": "e04000010100..."},
        ...
      },
      "main_bus_chips": [],
      "transactions": 1234,
      "enable": {"chip": "gpiochip0", "line": 17, "level": 1,
                 "holder": {"pid": 4242, "start": 987654},
                 "effective": 1, "changed_at": {"ms": 1764166000123.5, "transaction": 1201},
                 "rises": 3}
    }

``enable`` is present when the layout wires every chip's EN pin to one GPIO line
(``i2c.enable``), absent or null otherwise (EN tied high). ``level`` is what the
last process that drove the line drove it to and ``holder`` that process (its
pid and its start time in clock ticks since boot, /proc/PID/stat field 22, so a
reused pid does not count). The line models its pull-down: it is high only
while ``level`` is 1 and the holder still runs, so once the sleeve is gone
(``kill -9``, a crash) every reader sees it low and every chip's ``drive`` 0,
though no process was left to write "low". ``effective`` is that level when the
file was written; ``rises`` counts the times it ever went high. A chip whose EN
is low drives nothing whatever its registers say; with EN high (or no line) it
drives what its registers say.

``transactions`` counts the bus transactions tried; a chip that stops answering
gets ``lost_at`` (the wall clock in ms and that count: when the process driving
the bus took the edit that disconnected it, or when a transaction first found it
gone; null while it answers), and the line's ``changed_at`` says when it
last changed: a test reads from these how soon after a chip was lost every
motor was off.

Faults are set in the file: leave a chip out of ``chips`` (or set
``"connected": false``, a broken wire that keeps the registers) for a missing
chip; set ``device_id`` (e.g. 4, a DRV2604) for a wrong chip; set ``"fail_calibration":
true`` for a motor the chip cannot calibrate (DIAG_RESULT set; ``calibrations`` counts the
calibrations a chip ran). ``drive`` is
written for people and tests to read (0..1, what the motor gets when the file
was written; :func:`drive_levels` works it out again at the time it is read, as
the enable line may have fallen since) and ignored when the file is read
back. One process at a time should drive a state file; others may read it.
"""

from __future__ import annotations

import json
import os
import time

from feelmysign.backends.emulated_i2c import (
    EmulatedDRV2605L,
    EmulatedEnableLine,
    EmulatedI2CBus,
)
from feelmysign.errors import FeelMySignError
from feelmysign.input_files import MAX_STATE_BYTES, loads_json, read_text

# A restarting sleeve on an emulated bus opens its state file before anything else:
# no typing, pathlib or TOML reader at run time. mypy reads this name as True.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

    from feelmysign.layout import Layout

STATE_FORMAT = "feelmysign-emulated-i2c/1"


class EmulatedStateError(FeelMySignError):
    """A state file that cannot be used; ``path`` and ``problem`` say which and why."""

    def __init__(self, path: str | os.PathLike[str], problem: str) -> None:
        super().__init__(
            f"{path}: not a usable emulated I2C bus state file ({problem}); fix it, or delete it "
            "to start from a fresh bus wired as the layout says"
        )
        self.path = path
        self.problem = problem


def chip_key(multiplexer: int, channel: int) -> str:
    """How the file names the chip on ``channel`` of ``multiplexer``: ``"0x70/3"``."""
    return f"0x{multiplexer:02X}/{channel}"


def open_state_bus(path: str | os.PathLike[str], layout: Layout | None) -> EmulatedI2CBus:
    """The bus kept in ``path``, written through on every write.

    A file that does not exist yet becomes a fresh bus wired as ``layout``
    says (every chip at its power-on reset values); an existing file is the
    truth, whatever the layout says, as the hardware would be. Without a
    layout (the early all-off, before any TOML is read) the file must exist:
    EmulatedStateError otherwise.
    """
    state_path = os.fspath(path)  # os.path, not pathlib: a restarting sleeve imports this early
    if layout is None or os.path.exists(state_path):
        bus = read_state(state_path)
    else:
        bus = EmulatedI2CBus.for_layout(layout)
        try:
            write_state(bus, state_path)
        except OSError as error:
            raise EmulatedStateError(
                state_path, f"cannot be written: {error.strerror or error}"
            ) from error
    if layout is not None and layout.enable is not None and bus.enable_line is None:
        # A file made before the layout had a line: the boards are wired to it now.
        bus.add_enable_line(layout.enable.chip, layout.enable.line)
    write_through = _WriteThrough(state_path)
    bus.on_write = write_through
    bus.before_transaction = write_through.take_faults
    return bus


class _WriteThrough:
    """Saves the bus after each write that changed it (a write of what a register holds
    changes nothing, and skipping it keeps a burst of writes quick)."""

    def __init__(self, path: str) -> None:
        self._path = path
        self._last = ""
        self._written = _identity(path)

    def __call__(self, bus: EmulatedI2CBus) -> None:
        self.take_faults(bus)  # an edit made since the last write is not overwritten unseen
        text = _as_text(bus)
        if text != self._last:
            self._written = _replace(self._path, text)
            self._last = text

    def take_faults(self, bus: EmulatedI2CBus) -> None:
        """A file someone else changed while this process drives it: its faults land now.

        A chip left out of ``chips``, or ``"connected": false``, stops answering at once,
        as a chip whose wire comes loose mid-drawing would (registers kept: its motor runs on).
        So does a multiplexer set ``"connected": false``, and every chip behind it.
        """
        found = _identity(self._path)
        if found == self._written or found is None:
            return
        self._written = found
        try:
            edited = read_state(self._path)
        except EmulatedStateError:
            return  # half-edited by hand: the next change is looked at again
        saved = dict(edited.chips)
        for key, chip in bus.chips.items():
            connected = key in saved and saved[key].connected
            if chip.connected and not connected:  # the wire comes loose now, for this process
                chip.lost_at = (round(time.time() * 1000, 3), bus.transactions)
            chip.connected = connected
        for address, mux in bus.multiplexers.items():
            kept = edited.multiplexers.get(address)
            mux.connected = kept is not None and kept.connected


def read_state(path: str | os.PathLike[str]) -> EmulatedI2CBus:
    """The bus saved in ``path`` (no write-through: for looking, or for a test to edit)."""
    state_path = os.fspath(path)
    try:
        data = loads_json(read_text(state_path, max_bytes=MAX_STATE_BYTES))
    except OSError as error:
        problem = f"cannot be read: {error.strerror or error}"
        raise EmulatedStateError(state_path, problem) from error
    except (UnicodeDecodeError, ValueError) as error:
        raise EmulatedStateError(state_path, f"not JSON: {error}") from error
    try:
        return bus_from_state(data)
    except (KeyError, TypeError, ValueError) as error:
        raise EmulatedStateError(state_path, f"{type(error).__name__}: {error}") from error


def write_state(bus: EmulatedI2CBus, path: str | os.PathLike[str]) -> None:
    """Save ``bus`` to ``path`` atomically: a reader, or a killed writer, never sees half a file."""
    _replace(os.fspath(path), _as_text(bus))


def _as_text(bus: EmulatedI2CBus) -> str:
    return json.dumps(state_of(bus), indent=1) + "\n"


def _replace(path: str, text: str) -> tuple[int, int, int] | None:
    """Writes ``text`` to ``path`` in one step (readers see the old or the new file); the
    identity of what was written, taken before the rename (which keeps it): an edit renamed
    over the file just after is then never mistaken for this write, and is seen."""
    folder, name = os.path.split(path)
    temporary = os.path.join(folder, f".{name}.{os.getpid()}.tmp")
    with open(temporary, "w", encoding="utf-8") as file:
        file.write(text)
    written = _identity(temporary)
    os.replace(temporary, path)
    return written


def _identity(path: str) -> tuple[int, int, int] | None:
    try:
        info = os.stat(path)
    except OSError:
        return None
    return (info.st_ino, info.st_mtime_ns, info.st_size)


def drive_levels(path: str | os.PathLike[str]) -> dict[str, float]:
    """What each chip saved in ``path`` drives its motor with, 0..1, by :func:`chip_key`."""
    return {
        chip_key(multiplexer, channel): chip.output
        for (multiplexer, channel), chip in read_state(path).chips.items()
    }


def state_of(bus: EmulatedI2CBus) -> dict[str, Any]:
    """The JSON-ready state of every multiplexer and chip on ``bus``."""
    return {
        "format": STATE_FORMAT,
        "multiplexers": {
            f"0x{address:02X}": {"control": mux.control, "connected": mux.connected}
            for address, mux in sorted(bus.multiplexers.items())
        },
        "chips": {
            chip_key(multiplexer, channel): _chip_state(chip)
            for (multiplexer, channel), chip in sorted(bus.chips.items())
        },
        "main_bus_chips": [_chip_state(chip) for chip in bus.main_bus_chips],
        "transactions": bus.transactions,
        "enable": None if bus.enable_line is None else _line_state(bus.enable_line),
    }


def _line_state(line: EmulatedEnableLine) -> dict[str, Any]:
    holder = line.holder
    return {
        "chip": line.chip,
        "line": line.line,
        "level": int(line.level),
        "holder": None if holder is None else {"pid": holder[0], "start": holder[1]},
        "effective": int(line.effective_high),
        "changed_at": _when(line.changed_at),
        "rises": line.rises,
    }


def _when(at: tuple[float, int] | None) -> dict[str, Any] | None:
    return None if at is None else {"ms": at[0], "transaction": at[1]}


def _read_when(saved: Any) -> tuple[float, int] | None:
    if saved is None:
        return None
    return (float(saved["ms"]), int(saved["transaction"]))


def bus_from_state(data: Any) -> EmulatedI2CBus:
    """The bus ``data`` (as :func:`state_of` makes it) describes; ValueError/KeyError if not one."""
    if not isinstance(data, dict) or data.get("format") != STATE_FORMAT:
        raise ValueError(f"format is not {STATE_FORMAT!r}")
    bus = EmulatedI2CBus()
    for name, saved in dict(data["multiplexers"]).items():
        mux = bus.add_multiplexer(int(name, 16))
        mux.control = _byte(saved["control"], f"multiplexer {name} control")
        mux.connected = bool(saved.get("connected", True))
    for name, saved in dict(data["chips"]).items():
        multiplexer, _, channel = str(name).partition("/")
        _restore(bus.attach_chip(int(multiplexer, 16), int(channel)), saved, name)
    for index, saved in enumerate(list(data.get("main_bus_chips", []))):
        _restore(bus.attach_main_bus_chip(), saved, f"main bus chip {index}")
    bus.transactions = int(data.get("transactions", 0))
    line = data.get("enable")
    if line is not None:
        enable = EmulatedEnableLine(str(line["chip"]), int(line["line"]))
        enable.level = bool(line.get("level", 0))
        holder = line.get("holder")
        enable.holder = None if holder is None else (int(holder["pid"]), int(holder["start"]))
        enable.changed_at = _read_when(line.get("changed_at"))
        enable.rises = int(line.get("rises", 0))
        bus.enable_line = enable
        bus.add_enable_line(enable.chip, enable.line)  # links it, and every EN follows it
    return bus


def _chip_state(chip: EmulatedDRV2605L) -> dict[str, Any]:
    return {
        "device_id": chip.device_id,
        "connected": chip.connected,
        "drive": round(chip.output, 4),
        "registers": chip.registers.hex(),
        "lost_at": _when(chip.lost_at),
        "fail_calibration": chip.fail_calibration,
        "calibrations": chip.calibrations,
    }


def _restore(chip: EmulatedDRV2605L, saved: Any, name: str) -> None:
    registers = bytes.fromhex(str(saved["registers"]))
    if len(registers) != len(chip.registers):
        raise ValueError(f"chip {name} has {len(registers)} registers, not {len(chip.registers)}")
    chip.registers[:] = registers
    chip.connected = bool(saved.get("connected", True))
    chip.lost_at = _read_when(saved.get("lost_at"))
    chip.fail_calibration = bool(saved.get("fail_calibration", False))
    chip.calibrations = int(saved.get("calibrations", 0))
    if "device_id" in saved:  # wins over STATUS, so a test can fit a wrong chip by editing one key
        device_id = int(saved["device_id"])
        if not 0 <= device_id <= 7:
            raise ValueError(f"chip {name} device_id {device_id} is outside 0..7")
        chip.device_id = device_id


def _byte(value: Any, name: str) -> int:
    byte = int(value)
    if not 0 <= byte <= 0xFF:
        raise ValueError(f"{name} {byte} is outside 0..255")
    return byte
