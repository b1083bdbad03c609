"""Which I2C devices answer behind each multiplexer channel, and how that compares with a layout.

For ``feelmysign scan``: the builder of a sleeve sees at once which motor
driver is missing, on which multiplexer channel, and what answers instead.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal

from feelmysign.backends.drv2605 import (
    DRV2605_ADDRESS,
    SUPPORTED_DEVICE_IDS,
    device_id_from_status,
    device_name,
)
from feelmysign.backends.i2c import I2CBus
from feelmysign.backends.tca9548a import CHANNELS, Multiplexers
from feelmysign.errors import HardwareError
from feelmysign.layout import Layout, Wire

# i2cdetect's default range: 0x00-0x07 and 0x78-0x7F are reserved addresses.
DEFAULT_ADDRESSES = range(0x08, 0x78)
_STATUS = 0x00  # DRV2605L STATUS register, holds DEVICE_ID
_MODE = 0x01  # bit 6: standby
_RTP_INPUT = 0x02
_MODE_STANDBY = 0x40


@dataclass(frozen=True)
class ChannelScan:
    """The addresses answering on one channel (those on the main bus left out)."""

    multiplexer: int
    channel: int
    addresses: tuple[int, ...]
    device_id: int | None  # of the chip at 0x5A, when one answered
    # What a DRV2605L there holds that drives its motor (out of standby with a non-zero RTP
    # level), as "MODE 0x05, RTP_INPUT 0x66"; None when silent or not read.
    driving: str | None = None


@dataclass(frozen=True)
class ScanResult:
    main_bus: tuple[int, ...]  # answering with every channel disabled, multiplexers included
    missing_multiplexers: tuple[int, ...]
    channels: tuple[ChannelScan, ...]

    def channel(self, multiplexer: int, channel: int) -> ChannelScan | None:
        for found in self.channels:
            if (found.multiplexer, found.channel) == (multiplexer, channel):
                return found
        return None


def _answers(bus: I2CBus, address: int) -> bool:
    try:
        bus.read_byte(address)  # a read, unlike a quick write, cannot change a device's state
    except OSError:
        return False
    return True


def _read_device_id(bus: I2CBus) -> int | None:
    try:
        return device_id_from_status(bus.read_byte_data(DRV2605_ADDRESS, _STATUS))
    except OSError:
        return None


def _read_driving(bus: I2CBus) -> str | None:
    try:
        mode = bus.read_byte_data(DRV2605_ADDRESS, _MODE)
        rtp = bus.read_byte_data(DRV2605_ADDRESS, _RTP_INPUT)
    except OSError:
        return None
    if mode & _MODE_STANDBY or rtp == 0:
        return None
    return f"MODE 0x{mode:02X}, RTP_INPUT 0x{rtp:02X}"


def scan(
    bus: I2CBus, multiplexers: Iterable[int], *, addresses: Iterable[int] = DEFAULT_ADDRESSES
) -> ScanResult:
    """Probe ``addresses`` on the main bus, then behind every channel of every multiplexer.

    A device behind a channel at the same address as one on the main bus
    cannot be told apart from it, so it is not listed for the channel.
    Every channel is disabled afterwards.
    """
    probe = tuple(addresses)
    present, missing = [], []
    for address in multiplexers:
        try:
            bus.write_byte(address, 0x00)  # deselects it too
            present.append(address)
        except OSError:
            missing.append(address)
    muxes = Multiplexers(bus, present)
    main_bus = tuple(a for a in probe if _answers(bus, a))
    channels = []
    try:
        for multiplexer in present:
            for channel in CHANNELS:
                muxes.select(multiplexer, channel)
                found = tuple(a for a in probe if a not in main_bus and _answers(bus, a))
                device_id = _read_device_id(bus) if DRV2605_ADDRESS in found else None
                driving = _read_driving(bus) if device_id in SUPPORTED_DEVICE_IDS else None
                channels.append(ChannelScan(multiplexer, channel, found, device_id, driving))
    finally:
        muxes.deselect_all()
    return ScanResult(main_bus, tuple(missing), tuple(channels))


WireStatus = Literal["ok", "missing", "wrong-chip", "multiplexer-missing", "driving"]


@dataclass(frozen=True)
class WireCheck:
    wire: Wire
    status: WireStatus
    message: str


@dataclass(frozen=True)
class LayoutReport:
    """Expected (the layout's wiring) against found (a scan), one line per wire plus surprises."""

    wires: tuple[WireCheck, ...]
    unexpected: tuple[str, ...]  # chips where the layout has none, a chip on the main bus

    @property
    def ok(self) -> bool:
        return not self.unexpected and all(w.status == "ok" for w in self.wires)

    def problems(self) -> list[str]:
        return [w.message for w in self.wires if w.status != "ok"] + list(self.unexpected)


def _check_wire(result: ScanResult, wire: Wire) -> WireCheck:
    where = (
        f"multiplexer 0x{wire.multiplexer:02X} channel {wire.channel} "
        f"(actuator row {wire.row}, column {wire.column})"
    )
    if wire.multiplexer in result.missing_multiplexers:
        message = f"Multiplexer 0x{wire.multiplexer:02X} did not answer, so {where} was not reached"
        return WireCheck(wire, "multiplexer-missing", message)
    found = result.channel(wire.multiplexer, wire.channel)
    if found is None or DRV2605_ADDRESS not in found.addresses:
        others = ", ".join(f"0x{a:02X}" for a in found.addresses) if found else ""
        instead = f" (answering instead: {others})" if others else ""
        return WireCheck(wire, "missing", f"No DRV2605L answered on {where}{instead}")
    if found.device_id not in SUPPORTED_DEVICE_IDS:
        name = device_name(found.device_id) if found.device_id is not None else "unreadable chip"
        return WireCheck(wire, "wrong-chip", f"A {name} answered on {where}, not a DRV2605L")
    if found.driving is not None:
        # Left on by a sleeve that died without switching it off (no enable line, or its EN
        # is tied high): the motor runs now, or as soon as the enable line goes high.
        return WireCheck(
            wire,
            "driving",
            f"The {device_name(found.device_id)} on {where} is left driving its motor "
            f"({found.driving}): if no sleeve runs, switch it off with 'feelmysign off'",
        )
    return WireCheck(wire, "ok", f"{device_name(found.device_id)} on {where}")


def compare_with_layout(result: ScanResult, layout: Layout) -> LayoutReport:
    """Which wired actuators have their chip, and which chips answer where none is wired."""
    wires = tuple(_check_wire(result, wire) for wire in layout.wiring)
    wired = {(w.multiplexer, w.channel) for w in layout.wiring}
    unexpected = [
        f"A chip answers at 0x{DRV2605_ADDRESS:02X} on multiplexer 0x{c.multiplexer:02X} "
        f"channel {c.channel}, where the layout wires no actuator"
        for c in result.channels
        if DRV2605_ADDRESS in c.addresses and (c.multiplexer, c.channel) not in wired
    ]
    if DRV2605_ADDRESS in result.main_bus:
        unexpected.append(
            f"A chip answers at 0x{DRV2605_ADDRESS:02X} with every channel disabled: it is on the "
            "main bus, not behind a multiplexer, and collides with every other DRV2605L"
        )
    return LayoutReport(wires, tuple(unexpected))


# The motor settings and auto-calibration results, as their registers hold them.
MOTOR_REGISTERS = {
    "rated_voltage": 0x16,
    "od_clamp": 0x17,
    "a_cal_comp": 0x18,
    "a_cal_bemf": 0x19,
    "feedback_control": 0x1A,
    "control1": 0x1B,
}


def read_motor_registers(
    bus: I2CBus, layout: Layout, result: ScanResult, report: LayoutReport
) -> dict[tuple[int, int], dict[str, int]]:
    """(multiplexer, channel) -> register name -> value, for every wired chip that answered.

    Only reads; every channel is disabled afterwards."""
    present = [m for m in layout.multiplexers if m not in result.missing_multiplexers]
    muxes = Multiplexers(bus, present)
    found: dict[tuple[int, int], dict[str, int]] = {}
    try:
        for check in report.wires:
            if check.status != "ok":
                continue
            wire = check.wire
            try:
                muxes.select(wire.multiplexer, wire.channel)
                found[(wire.multiplexer, wire.channel)] = {
                    name: bus.read_byte_data(DRV2605_ADDRESS, register)
                    for name, register in MOTOR_REGISTERS.items()
                }
            except (OSError, HardwareError):
                continue  # it answered the scan a moment ago; the table shows it as unread
    finally:
        with contextlib.suppress(HardwareError):
            muxes.deselect_all()
    return found
