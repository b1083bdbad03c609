"""The emulated I2C bus behaves like the hardware the DRV2605L backend is tested against."""

from __future__ import annotations

import errno

import pytest

from feelmysign.backends.emulated_i2c import (
    DRV2604_DEVICE_ID,
    BusConflictError,
    EmulatedI2CBus,
    Transaction,
)
from feelmysign.layout import Layout, Wire

DRV = 0x5A
STATUS, MODE, RTP_INPUT, FEEDBACK_CONTROL, CONTROL3 = 0x00, 0x01, 0x02, 0x1A, 0x1D


def two_mux_bus() -> EmulatedI2CBus:
    bus = EmulatedI2CBus()
    bus.add_multiplexer(0x70)
    bus.add_multiplexer(0x71)
    bus.attach_chip(0x70, 0)
    bus.attach_chip(0x70, 1)
    bus.attach_chip(0x71, 0)
    return bus


def test_a_fresh_chip_holds_the_datasheet_reset_values() -> None:
    chip = two_mux_bus().chip(mux=0x70, channel=0)
    assert chip.registers[STATUS] == 0xE0  # DEVICE_ID 7: DRV2605L
    assert chip.registers[MODE] == 0x40  # standby
    assert chip.registers[RTP_INPUT] == 0x00
    assert chip.registers[FEEDBACK_CONTROL] == 0x36  # ERM
    assert chip.registers[CONTROL3] == 0xA0  # signed RTP data
    assert chip.standby and not chip.lra and not chip.rtp_unsigned
    assert chip.output == 0.0


def test_a_chip_answers_only_while_its_channel_is_selected() -> None:
    bus = two_mux_bus()
    with pytest.raises(OSError) as missing:
        bus.read_byte_data(DRV, STATUS)
    assert missing.value.errno == errno.EREMOTEIO == 121
    bus.write_byte(0x70, 1 << 1)
    assert bus.read_byte_data(DRV, STATUS) == 0xE0
    assert bus.chip(mux=0x70, channel=1).reads[STATUS] == 1
    assert bus.chip(mux=0x70, channel=0).reads[STATUS] == 0


def test_the_multiplexer_control_register_is_the_channel_mask_and_reads_back() -> None:
    bus = two_mux_bus()
    bus.write_byte(0x71, 0b0000_0100)
    assert bus.read_byte(0x71) == 0b0000_0100
    assert bus.multiplexer(0x71).enabled_channels == (2,)
    bus.write_byte_data(0x71, 0xFF, 0x01)  # the TCA9548A keeps the last byte written
    assert bus.multiplexer(0x71).control == 0x01


def test_two_selected_chips_on_one_multiplexer_are_a_counted_conflict() -> None:
    bus = two_mux_bus()
    bus.write_byte(0x70, 0b11)
    with pytest.raises(BusConflictError) as conflict:
        bus.write_byte_data(DRV, RTP_INPUT, 10)
    assert conflict.value.address == DRV
    assert conflict.value.devices == ["DRV2605L 0x70/0", "DRV2605L 0x70/1"]
    assert bus.conflicts == 1
    assert bus.chip(mux=0x70, channel=0).registers[RTP_INPUT] == 0  # nothing was written


def test_selected_chips_on_two_multiplexers_are_a_conflict_too() -> None:
    bus = two_mux_bus()
    bus.write_byte(0x70, 0b01)
    bus.write_byte(0x71, 0b01)
    assert bus.max_enabled_channels == 2
    with pytest.raises(BusConflictError):
        bus.read_byte_data(DRV, STATUS)
    assert bus.conflicts == 1
    assert bus.log[-1].error is not None and "bus conflict" in bus.log[-1].error


def test_a_missing_or_disconnected_device_gives_remote_io_error() -> None:
    bus = two_mux_bus()
    with pytest.raises(OSError, match="Remote I/O error"):
        bus.write_byte(0x72, 0)  # no multiplexer there
    bus.write_byte(0x70, 1)
    bus.chip(mux=0x70, channel=0).connected = False
    with pytest.raises(OSError) as missing:
        bus.read_byte_data(DRV, STATUS)
    assert missing.value.errno == errno.EREMOTEIO
    bus.multiplexer(0x70).connected = False
    with pytest.raises(OSError):
        bus.read_byte(0x70)
    assert bus.conflicts == 0


def test_the_log_and_the_counters_record_every_transaction() -> None:
    bus = two_mux_bus()
    bus.write_byte(0x70, 1)
    bus.write_byte_data(DRV, RTP_INPUT, 200)
    bus.write_byte_data(DRV, RTP_INPUT, 201)
    assert list(bus.log) == [
        Transaction("write_byte", 0x70, None, 1, "TCA9548A 0x70"),
        Transaction("write_byte_data", DRV, RTP_INPUT, 200, "DRV2605L 0x70/0"),
        Transaction("write_byte_data", DRV, RTP_INPUT, 201, "DRV2605L 0x70/0"),
    ]
    chip = bus.chip(mux=0x70, channel=0)
    assert chip.writes[RTP_INPUT] == 2 and chip.write_count == 2
    assert bus.multiplexer(0x70).writes == 1
    assert bus.write_count == 3 and bus.read_count == 0


def test_read_only_registers_ignore_writes_and_dev_reset_restores_defaults() -> None:
    bus = two_mux_bus()
    chip = bus.chip(mux=0x70, channel=0)
    bus.write_byte(0x70, 1)
    bus.write_byte_data(DRV, STATUS, 0x00)
    assert chip.registers[STATUS] == 0xE0
    bus.write_byte_data(DRV, RTP_INPUT, 99)
    bus.write_byte_data(DRV, MODE, 0x05)
    bus.write_byte_data(DRV, MODE, 0x80)  # DEV_RESET
    assert chip.registers[MODE] == 0x40 and chip.registers[RTP_INPUT] == 0


def test_a_wrong_chip_reports_its_own_device_id() -> None:
    bus = two_mux_bus()
    bus.attach_chip(0x71, 3, device_id=DRV2604_DEVICE_ID)
    bus.write_byte(0x71, 1 << 3)
    assert bus.read_byte_data(DRV, STATUS) >> 5 == 4


def test_the_output_follows_the_mode_and_the_rtp_data_format() -> None:
    chip = two_mux_bus().chip(mux=0x70, channel=0)
    chip.registers[RTP_INPUT] = 0xC8  # 200
    chip.registers[MODE] = 0x05
    assert chip.output == 0.0  # signed data: 0xC8 is negative, a brake
    chip.registers[CONTROL3] |= 0x08
    assert chip.output == pytest.approx(200 / 255)
    chip.registers[MODE] = 0x45  # standby wins
    assert chip.output == 0.0


def test_bad_bytes_and_closed_buses_are_caught() -> None:
    bus = two_mux_bus()
    with pytest.raises(ValueError, match="value 256"):
        bus.write_byte(0x70, 256)
    bus.write_byte(0x70, 1)
    with pytest.raises(ValueError, match="register 0x40 does not exist"):
        bus.read_byte_data(DRV, 0x40)
    bus.close()
    with pytest.raises(ValueError, match="closed"):
        bus.read_byte(0x70)


def test_for_layout_wires_one_chip_per_actuator() -> None:
    layout = Layout(
        rows=1,
        columns=2,
        spacing_cm=3.0,
        multiplexers=(0x70, 0x73),
        wiring=(Wire(0, 0, 0x70, 5), Wire(0, 1, 0x73, 0)),
    )
    bus = EmulatedI2CBus.for_layout(layout)
    assert sorted(bus.chips) == [(0x70, 5), (0x73, 0)]
    assert bus.enabled_channels() == []
