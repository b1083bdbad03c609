"""``feelmysign scan``: what answers on every multiplexer channel, against the sleeve layout.

    feelmysign scan --layout /etc/feelmysign/layout.toml
    feelmysign scan --layout deploy/layouts/paper-sleeve.toml --emulate   # no hardware needed
    feelmysign scan --layout deploy/layouts/paper-sleeve.toml --emulate-state bus.json

One line per channel of every multiplexer the layout lists: the actuator the
layout expects there, what answered, and the verdict. With an enable line in the
layout (``i2c.enable``), who holds it and, when nobody does, that it reads low
(the pull-down): one that reads high with nobody driving it is a problem. Exit 0 when every wired
actuator's DRV2605L answers and nothing answers where none is wired, 1
otherwise (also when the layout wires nothing, as then nothing was checked).
Only reads: no motor is switched on, and every channel is disabled afterwards.

Below the table, each chip's motor settings (RATED_VOLTAGE, OD_CLAMP, DRIVE_TIME) against
what the layout's motor asks for, its auto-calibration results (A_CAL_COMP, A_CAL_BEMF,
BEMF_GAIN) and whether they are kept for the next start. ``--calibrate`` first runs the
chips' auto-calibration again (each motor buzzes for about a second, one after another)
and keeps the results: do it after changing a motor; the sleeve calibrates by itself a
chip that has no result kept.

While a sleeve runs on the same bus (or a buzz), scan refuses before any I2C
traffic, naming that process (PID, command), exit 1: two processes must not
drive one bus. Stop the sleeve first (``sudo systemctl stop feelmysign-sleeve``
for the service, Ctrl-C where it runs otherwise).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
from dataclasses import dataclass
from typing import Any

from feelmysign.backends.actuator_config import (
    BEMF_GAIN_MASK,
    CalibrationStore,
    ChipSettings,
    chip_settings,
    motor_description,
)
from feelmysign.backends.bus_lock import lock_for
from feelmysign.backends.drv2605 import (
    DRV2605_ADDRESS,
    SUPPORTED_DEVICE_IDS,
    Drv2605Backend,
    device_name,
)
from feelmysign.backends.emulated_i2c import EmulatedI2CBus
from feelmysign.backends.emulated_state import open_state_bus
from feelmysign.backends.enable import read_free_line
from feelmysign.backends.factory import calibration_store_for, check_wired, enable_line_for
from feelmysign.backends.i2c import I2CBus, open_smbus
from feelmysign.backends.scan import (
    LayoutReport,
    ScanResult,
    compare_with_layout,
    read_motor_registers,
    scan,
)
from feelmysign.backends.tca9548a import CHANNELS, MULTIPLEXER_ADDRESSES
from feelmysign.cli.options.emulation import add_emulate_state_option
from feelmysign.cli.options.layout import LAYOUT_ENV
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.cli.options.values import MAX_LAYOUT_BYTES, check_input_file, not_empty
from feelmysign.errors import HardwareError, ParameterError
from feelmysign.layout import MAX_I2C_BUS, PAPER_SLEEVE, Layout, Wire, load_layout

EMULATED_NOTE = (
    "Emulated bus: nothing real was probed. Every chip the layout wires is simulated as "
    "present, so this shows the output format, not your sleeve."
)
STATE_NOTE = (
    "Emulated bus kept in {path}: nothing real was probed; the chips are those the file holds, "
    "with the faults set in it."
)
_TABLE_HEADER = ("multiplexer", "channel", "expected", "found", "status")


@dataclass(frozen=True)
class ChannelRow:
    """One line of the table: a multiplexer channel, expected against found."""

    multiplexer: int
    channel: int
    expected: Wire | None
    found: str
    status: str

    def as_dict(self) -> dict[str, Any]:
        return {
            "multiplexer": f"0x{self.multiplexer:02X}",
            "channel": self.channel,
            "expected": None
            if self.expected is None
            else {"row": self.expected.row, "column": self.expected.column},
            "found": self.found,
            "status": self.status,
        }


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "scan",
        help="check which DRV2605L answers on each multiplexer channel, against the layout",
        description=__doc__,
    )
    parser.add_argument(
        "--layout",
        metavar="FILE",
        type=not_empty("layout file"),
        help=f"sleeve layout TOML file with an [i2c] table, e.g. deploy/layouts/paper-sleeve.toml "
        f"(default: ${LAYOUT_ENV}; without a wired layout every address 0x70..0x77 is probed "
        "and nothing is compared)",
    )
    parser.add_argument(
        "--bus",
        type=int,
        metavar="N",
        help="I2C bus number, /dev/i2c-N (default: the layout's i2c.bus, 1 on a Raspberry Pi)",
    )
    parser.add_argument(
        "--emulate",
        action="store_true",
        help="scan an emulated bus wired as the layout says, instead of /dev/i2c-N",
    )
    add_emulate_state_option(parser)
    parser.add_argument(
        "--calibrate",
        action="store_true",
        help="first run every chip's auto-calibration again and keep the results (each motor "
        "buzzes for about a second); after changing a motor, with the sleeve stopped",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object, for programs")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    layout = _layout(args.layout)
    bus_number = layout.i2c_bus if args.bus is None else args.bus
    if not 0 <= bus_number <= MAX_I2C_BUS:
        raise ParameterError("--bus", bus_number, f"a bus number from 0 to {MAX_I2C_BUS}")
    # Without wiring there is nothing to expect: probe every address a TCA9548A can have.
    addresses = layout.multiplexers or tuple(MULTIPLEXER_ADDRESSES)
    # An emulated bus without a file is this process's own; any other one may be shared.
    with contextlib.ExitStack() as held:
        if args.emulate_state or not args.emulate:
            lock = held.enter_context(lock_for(bus_number, args.emulate_state or None))
            lock.acquire("scan", refused="Nothing was scanned.")
        return _scan(args, layout, bus_number, addresses)


def _scan(
    args: argparse.Namespace, layout: Layout, bus_number: int, addresses: tuple[int, ...]
) -> int:
    bus: I2CBus
    if args.emulate_state:
        bus = open_state_bus(args.emulate_state, layout)
    elif args.emulate:
        bus = EmulatedI2CBus.for_layout(layout)
    else:
        bus = _open_bus(bus_number)
    # An emulated bus without a file keeps nothing: its calibration is not kept either.
    store = None if args.emulate and not args.emulate_state else _store(layout, args)
    calibration_problem = None
    try:
        if args.calibrate:
            calibration_problem = _calibrate(layout, bus, store)
        result = scan(bus, addresses)
        line = _enable_line(layout, bus)
        report = compare_with_layout(result, layout)
        registers = read_motor_registers(bus, layout, result, report) if layout.wiring else {}
    finally:
        bus.close()
    motors = _motor_rows(layout, registers, store)
    scanned = _Scanned(
        layout,
        bus_number,
        result,
        report,
        channel_rows(result, layout),
        line,
        motors,
        calibration_problem,
    )
    if args.json:
        print(json.dumps(_as_json(args, scanned)))
    else:
        print(_describe(args, scanned), flush=True)
    return 0 if scanned.ok else 1


@dataclass(frozen=True)
class _Scanned:
    """A scan and what it means for the layout: what the text and the JSON both report."""

    layout: Layout
    bus_number: int
    result: ScanResult
    report: LayoutReport
    rows: list[ChannelRow]
    enable: EnableReport | None = None
    motors: list[MotorRow] | None = None
    calibration_problem: str | None = None  # --calibrate, when it failed

    @property
    def ok(self) -> bool:
        """Every wired actuator answers, the layout wires some, and its enable line is sound."""
        line_ok = self.enable is None or self.enable.problem is None
        calibrated = self.calibration_problem is None
        return self.report.ok and bool(self.layout.wiring) and line_ok and calibrated


@dataclass(frozen=True)
class EnableReport:
    """The enable line: who holds it, its level when it could be read, what is wrong."""

    name: str
    holder: str
    level: bool | None
    problem: str | None

    def as_dict(self) -> dict[str, Any]:
        return {
            "line": self.name,
            "holder": self.holder,
            "level": None if self.level is None else "high" if self.level else "low",
            "problem": self.problem,
        }

    def describe(self) -> str:
        level = "" if self.level is None else f", reads {'high' if self.level else 'low'}"
        verdict = f": {self.problem}" if self.problem else ": ok"
        return f"Enable line {self.name}: {self.holder}{level}{verdict}."


@dataclass(frozen=True)
class MotorRow:
    """One chip's motor registers as read, against the layout's motor."""

    wire: Wire
    registers: dict[str, int]
    stored: bool  # its calibration results are kept for the next start
    settings: ChipSettings

    @property
    def drive_time(self) -> int:
        return self.registers["control1"] & 0x1F

    @property
    def bemf_gain(self) -> int:
        return self.registers["feedback_control"] & BEMF_GAIN_MASK

    @property
    def as_layout(self) -> bool:
        """RATED_VOLTAGE, OD_CLAMP and DRIVE_TIME hold what the layout's motor asks for."""
        return (
            self.registers["rated_voltage"] == self.settings.rated_voltage
            and self.registers["od_clamp"] == self.settings.od_clamp
            and self.drive_time == self.settings.drive_time
        )

    def as_dict(self) -> dict[str, Any]:
        return {
            "multiplexer": f"0x{self.wire.multiplexer:02X}",
            "channel": self.wire.channel,
            "row": self.wire.row,
            "column": self.wire.column,
            "rated_voltage": self.registers["rated_voltage"],
            "od_clamp": self.registers["od_clamp"],
            "drive_time": self.drive_time,
            "a_cal_comp": self.registers["a_cal_comp"],
            "a_cal_bemf": self.registers["a_cal_bemf"],
            "bemf_gain": self.bemf_gain,
            "as_layout": self.as_layout,
            "calibration_stored": self.stored,
        }


def _store(layout: Layout, args: argparse.Namespace) -> CalibrationStore:
    return calibration_store_for(layout, args.emulate_state)


def _calibrate(layout: Layout, bus: I2CBus, store: CalibrationStore | None) -> str | None:
    """Every chip switched off, set up and auto-calibrated again, the results kept in ``store``;
    what went wrong (every motor off then too), or None. The scan runs after it either way."""
    check_wired(layout)
    backend = Drv2605Backend(
        layout, bus=bus, enable=enable_line_for(layout, bus), calibration=store, calibrate=True
    )
    try:
        with backend:
            pass  # open() calibrates; leaving switches every motor off
    except HardwareError as error:  # open() switched every motor off before it raised
        return str(error)
    return None


def _motor_rows(
    layout: Layout,
    registers: dict[tuple[int, int], dict[str, int]],
    store: CalibrationStore | None,
) -> list[MotorRow]:
    if not layout.wiring:
        return []
    settings = chip_settings(layout)
    stored = {} if store is None else store.results(motor_description(layout))
    return [
        MotorRow(
            w,
            registers[(w.multiplexer, w.channel)],
            f"0x{w.multiplexer:02X}/{w.channel}" in stored,
            settings,
        )
        for w in layout.wiring
        if (w.multiplexer, w.channel) in registers
    ]


def _motor_lines(layout: Layout, motors: list[MotorRow]) -> list[str]:
    settings = chip_settings(layout)
    kind = layout.actuator_type
    motor = (
        f"{kind}, rated {layout.rated_voltage:g} V {'rms' if kind == 'LRA' else 'average'}, "
        f"overdrive {layout.overdrive_voltage:g} V peak"
        + (f", {layout.resonance_hz:g} Hz" if kind == "LRA" else "")
    )
    lines = [
        f"Motor ({motor}): RATED_VOLTAGE 0x{settings.rated_voltage:02X}, OD_CLAMP "
        f"0x{settings.od_clamp:02X}, DRIVE_TIME {settings.drive_time} by the DRV2605L datasheet.",
        "",
    ]
    header = (
        "actuator",
        "RATED_VOLTAGE",
        "OD_CLAMP",
        "DRIVE_TIME",
        "A_CAL_COMP",
        "A_CAL_BEMF",
        "BEMF_GAIN",
        "settings",
        "calibration",
    )
    cells = [header] + [
        (
            f"row {m.wire.row}, column {m.wire.column}",
            f"0x{m.registers['rated_voltage']:02X}",
            f"0x{m.registers['od_clamp']:02X}",
            str(m.drive_time),
            f"0x{m.registers['a_cal_comp']:02X}",
            f"0x{m.registers['a_cal_bemf']:02X}",
            str(m.bemf_gain),
            "as layout" if m.as_layout else "not yet (set when the sleeve starts)",
            "kept" if m.stored else "none kept (the sleeve calibrates it at its next start)",
        )
        for m in motors
    ]
    widths = [max(len(line[i]) for line in cells) for i in range(len(header))]
    lines += [
        "  ".join(c.ljust(w) for c, w in zip(line, widths, strict=True)).rstrip() for line in cells
    ]
    return lines


def _enable_line(layout: Layout, bus: I2CBus) -> EnableReport | None:
    """The layout's enable line as it is now (read without driving it); None without one."""
    enable = layout.enable
    if enable is None:
        return None
    if isinstance(bus, EmulatedI2CBus):
        line = bus.enable_line
        if line is None or line.holder is None or not line.holder_alive:
            holder, level = "free (nobody drives it; the pull-down holds it)", False
        else:
            holder, level = f"held by process {line.holder[0]}", line.effective_high
        return EnableReport(enable.name, holder, level, None)
    try:
        holder, read = read_free_line(enable)
    except HardwareError as error:
        return EnableReport(enable.name, "not readable", None, str(error))
    problem = None
    if read:
        problem = (
            "it reads HIGH with nobody driving it, so a crash would leave the motors enabled: "
            "fit the pull-down (10 kOhm from the line to GND) and check that no driver board "
            "ties EN high (docs/sleeve-hardware.md)"
        )
    return EnableReport(enable.name, holder, read, problem)


def _open_bus(bus_number: int) -> I2CBus:
    try:
        return open_smbus(bus_number)
    except HardwareError as error:
        raise HardwareError(
            f"{error} To see what scan prints without hardware, add --emulate."
        ) from error


def _layout(path: str | None) -> Layout:
    chosen = path or os.environ.get(LAYOUT_ENV, "")
    if not chosen:
        return PAPER_SLEEVE
    check_input_file(chosen, what="layout file", max_bytes=MAX_LAYOUT_BYTES)
    return load_layout(chosen)


def channel_rows(result: ScanResult, layout: Layout) -> list[ChannelRow]:
    """Every channel of every multiplexer scanned or expected, in address and channel order."""
    wires = {(w.multiplexer, w.channel): w for w in layout.wiring}
    present = {c.multiplexer for c in result.channels}
    rows = []
    for multiplexer in sorted(present | set(layout.multiplexers)):
        for channel in CHANNELS:
            expected = wires.get((multiplexer, channel))
            if multiplexer in result.missing_multiplexers:
                if expected is not None:
                    rows.append(
                        ChannelRow(multiplexer, channel, expected, "-", "multiplexer missing")
                    )
                continue
            found, status = _found_and_status(result, multiplexer, channel, expected)
            rows.append(ChannelRow(multiplexer, channel, expected, found, status))
    return rows


def _found_and_status(
    result: ScanResult, multiplexer: int, channel: int, expected: Wire | None
) -> tuple[str, str]:
    scanned = result.channel(multiplexer, channel)
    addresses = scanned.addresses if scanned is not None else ()
    names = []
    for address in addresses:
        if address == DRV2605_ADDRESS and scanned is not None and scanned.device_id is not None:
            names.append(f"0x{address:02X} {device_name(scanned.device_id)}")
        else:
            names.append(f"0x{address:02X}")
    found = ", ".join(names) or "nothing"
    has_driver = DRV2605_ADDRESS in addresses
    right_chip = scanned is not None and scanned.device_id in SUPPORTED_DEVICE_IDS
    if expected is None:
        return found, "UNEXPECTED" if has_driver else "free"
    if not has_driver:
        return found, "MISSING"
    if not right_chip:
        return found, "WRONG CHIP"
    return found, "DRIVING" if scanned is not None and scanned.driving else "ok"


def _describe(args: argparse.Namespace, scanned: _Scanned) -> str:
    layout, result, report, rows = scanned.layout, scanned.result, scanned.report, scanned.rows
    where = f"/dev/i2c-{scanned.bus_number}"
    if args.emulate_state:
        where = f"the emulated bus in {args.emulate_state}"
    elif args.emulate:
        where = "an emulated bus"
    lines = [f"Scanning {where} against layout {layout.name!r}."]
    if args.emulate_state:
        lines.append(STATE_NOTE.format(path=args.emulate_state))
    elif args.emulate:
        lines.append(EMULATED_NOTE)
    if rows:
        lines += ["", *_table(rows), ""]
    else:
        listed = ", ".join(f"0x{m:02X}" for m in result.missing_multiplexers)
        lines += [
            "",
            f"No multiplexer answered (probed {listed}): check the TCA9548A's power (VIN, GND), "
            "its SDA/SCL wires to the Pi (pins 3 and 5) and its address pins A0-A2.",
            "",
        ]
    lines.append(_main_bus_line(result, layout))
    if scanned.enable is not None:
        lines.append(scanned.enable.describe())
    if not layout.wiring:
        lines.append(
            f"The layout {layout.name!r} wires no actuator, so nothing was checked: give "
            "--layout FILE with an [i2c] table (e.g. deploy/layouts/paper-sleeve.toml)."
        )
        return "\n".join(lines)
    if scanned.motors:
        lines += ["", *_motor_lines(layout, scanned.motors), ""]
    if scanned.calibration_problem is not None:
        lines += [f"Calibration failed: {scanned.calibration_problem}", ""]
    wired = len(report.wires)
    answering = sum(1 for check in report.wires if check.status in ("ok", "driving"))
    if report.ok:
        lines.append(f"All {wired} actuators answer as the layout says.")
    else:
        lines.append(f"{answering} of {wired} actuators answer as the layout says. Problems:")
        lines += [f"  - {problem}" for problem in report.problems()]
        lines.append("See 'Troubleshooting' in docs/sleeve-hardware.md.")
    return "\n".join(lines)


def _table(rows: list[ChannelRow]) -> list[str]:
    cells = [_TABLE_HEADER] + [
        (
            f"0x{row.multiplexer:02X}",
            str(row.channel),
            "-"
            if row.expected is None
            else f"row {row.expected.row}, column {row.expected.column}",
            row.found,
            row.status,
        )
        for row in rows
    ]
    widths = [max(len(line[i]) for line in cells) for i in range(len(_TABLE_HEADER))]
    return [
        "  ".join(c.ljust(w) for c, w in zip(line, widths, strict=True)).rstrip() for line in cells
    ]


def _main_bus_line(result: ScanResult, layout: Layout) -> str:
    answering = (
        ", ".join(
            f"0x{a:02X}" + (" (TCA9548A)" if a in layout.multiplexers else "")
            for a in result.main_bus
        )
        or "nothing"
    )
    line = f"On the main bus (every channel disabled): {answering}."
    strangers = [
        a for a in result.main_bus if a in MULTIPLEXER_ADDRESSES and a not in layout.multiplexers
    ]
    if strangers and layout.wiring:
        line += (
            f" Also answering where the layout lists no multiplexer: "
            f"{', '.join(f'0x{a:02X}' for a in strangers)}."
        )
    return line


def _as_json(args: argparse.Namespace, scanned: _Scanned) -> dict[str, Any]:
    layout, result, report = scanned.layout, scanned.result, scanned.report
    return {
        "ok": scanned.ok,
        "emulated": bool(args.emulate or args.emulate_state),
        "bus": None if args.emulate or args.emulate_state else scanned.bus_number,
        "layout": layout.name,
        "main_bus": [f"0x{a:02X}" for a in result.main_bus],
        "missing_multiplexers": [f"0x{a:02X}" for a in result.missing_multiplexers],
        "channels": [row.as_dict() for row in scanned.rows],
        "problems": (report.problems() if layout.wiring else ["the layout wires no actuator"])
        + (
            [] if scanned.enable is None or not scanned.enable.problem else [scanned.enable.problem]
        ),
        "enable": None if scanned.enable is None else scanned.enable.as_dict(),
        "motors": [row.as_dict() for row in scanned.motors or []],
        "calibration_problem": scanned.calibration_problem,
    }
