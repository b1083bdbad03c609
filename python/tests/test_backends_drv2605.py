"""The DRV2605L backend, register by register, against the emulated I2C bus.

The paper's sleeve: 3 rows x 4 columns, rows 0-1 on multiplexer 0x70
(channels 0-7), row 2 on multiplexer 0x71 (channels 0-3)::

    row 0   0x70/0  0x70/1  0x70/2  0x70/3
    row 1   0x70/4  0x70/5  0x70/6  0x70/7
    row 2   0x71/0  0x71/1  0x71/2  0x71/3
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import pytest
import smbus2
from hypothesis import given, settings
from hypothesis import strategies as st

from feelmysign.backends import Backend, Drv2605Backend, EmulatedI2CBus, compare_with_layout
from feelmysign.backends.emulated_i2c import DRV2604_DEVICE_ID
from feelmysign.backends.scan import scan
from feelmysign.errors import HardwareError, LayoutError
from feelmysign.layout import ActuatorType, Layout, Wire

DRV = 0x5A
STATUS, MODE, RTP_INPUT, FEEDBACK_CONTROL, CONTROL3 = 0x00, 0x01, 0x02, 0x1A, 0x1D
NOT_FOUND_HINT = "check the wiring or run 'feelmysign scan'"


def paper_layout(actuator_type: ActuatorType = "ERM", **changes: Any) -> Layout:
    wiring = [Wire(row, column, 0x70, row * 4 + column) for row in (0, 1) for column in range(4)]
    wiring += [Wire(2, column, 0x71, column) for column in range(4)]
    layout = Layout(
        rows=3,
        columns=4,
        spacing_cm=3.0,
        name="paper-sleeve",
        actuator_type=actuator_type,
        multiplexers=(0x70, 0x71),
        wiring=tuple(wiring),
    )
    return dataclasses.replace(layout, **changes)


def where(layout: Layout, row: int, column: int) -> tuple[int, int]:
    wire = next(w for w in layout.wiring if (w.row, w.column) == (row, column))
    return wire.multiplexer, wire.channel


def opened(layout: Layout, bus: EmulatedI2CBus) -> Drv2605Backend:
    backend = Drv2605Backend(layout, bus=bus)
    backend.open()
    return backend


# -- start-up -----------------------------------------------------------------------------


@pytest.mark.parametrize(("actuator_type", "feedback"), [("ERM", 0x36), ("LRA", 0xB6)])
def test_start_up_puts_every_chip_in_rtp_mode_with_the_motor_type_and_unsigned_data(
    actuator_type: ActuatorType, feedback: int
) -> None:
    layout = paper_layout(actuator_type)
    bus = EmulatedI2CBus.for_layout(layout)
    opened(layout, bus)
    assert len(bus.chips) == 12
    for chip in bus.chips.values():
        assert chip.registers[MODE] == 0x05  # RTP, out of standby
        assert chip.registers[RTP_INPUT] == 0
        assert chip.registers[FEEDBACK_CONTROL] == feedback  # N_ERM_LRA only; the rest kept
        assert chip.registers[CONTROL3] == 0xA8  # DATA_FORMAT_RTP set; the rest kept
        assert chip.reads[STATUS] == 1  # the id was checked
        assert chip.output == 0.0
    assert bus.conflicts == 0 and bus.max_enabled_channels == 1


def test_start_up_keeps_the_other_feedback_and_control3_bits() -> None:
    layout = paper_layout("LRA")
    bus = EmulatedI2CBus.for_layout(layout)
    chip = bus.chip(mux=0x71, channel=2)
    chip.registers[FEEDBACK_CONTROL] = 0x2B  # as a calibration would leave it
    chip.registers[CONTROL3] = 0x21  # ERM_OPEN_LOOP and LRA_OPEN_LOOP
    opened(layout, bus)
    assert chip.registers[FEEDBACK_CONTROL] == 0xAB
    assert chip.registers[CONTROL3] == 0x29


def test_erm_clears_a_leftover_lra_bit() -> None:
    layout = paper_layout("ERM")
    bus = EmulatedI2CBus.for_layout(layout)
    chip = bus.chip(mux=0x70, channel=0)
    chip.registers[FEEDBACK_CONTROL] = 0xB6
    opened(layout, bus)
    assert chip.registers[FEEDBACK_CONTROL] == 0x36


def left_running(bus: EmulatedI2CBus, level: int = 0xCC) -> None:
    """Every chip as a killed sleeve leaves it: real-time playback, unsigned, at ``level``."""
    for chip in bus.chips.values():
        chip.registers[CONTROL3] |= 0x08
        chip.registers[RTP_INPUT] = level
        chip.registers[MODE] = 0x05
    assert all(chip.output > 0.5 for chip in bus.chips.values())


def test_a_missing_chip_is_named_and_every_other_chip_is_switched_off_first() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    left_running(bus)
    bus.detach_chip(0x70, 3)
    with pytest.raises(HardwareError) as error:
        Drv2605Backend(layout, bus=bus).open()
    assert str(error.value) == (
        "No DRV2605L answered on multiplexer 0x70 channel 3 (actuator row 0, column 3); "
        + NOT_FOUND_HINT
        + " (every chip that answered was switched off first; a motor on a chip that did not"
        " answer may still run: if one keeps vibrating, cut the sleeve's power)"
    )
    assert len(bus.chips) == 11
    assert all(chip.output == 0.0 and chip.standby for chip in bus.chips.values())
    assert bus.enabled_channels() == []


@pytest.mark.parametrize("fault", ["missing", "broken wire", "wrong id", "missing multiplexer"])
def test_no_single_fault_at_start_up_leaves_a_reachable_motor_on(fault: str) -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    left_running(bus)
    unreachable: set[tuple[int, int]] = set()
    if fault == "missing":
        bus.detach_chip(0x71, 2)
    elif fault == "broken wire":
        bus.chip(mux=0x70, channel=5).connected = False
        unreachable.add((0x70, 5))
    elif fault == "wrong id":
        bus.chip(mux=0x70, channel=0).device_id = DRV2604_DEVICE_ID
    else:
        bus.multiplexer(0x71).connected = False
        unreachable.update((0x71, channel) for channel in range(4))
    with pytest.raises(HardwareError):
        Drv2605Backend(layout, bus=bus).open()
    drives = {key: chip.output for key, chip in bus.chips.items()}
    assert {key for key, drive in drives.items() if drive > 0} == unreachable
    assert all(chip.output == 0.0 for key, chip in bus.chips.items() if key not in unreachable)


def test_a_wrong_chip_id_is_named_with_what_was_found() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    bus.chip(mux=0x71, channel=2).device_id = DRV2604_DEVICE_ID
    with pytest.raises(HardwareError) as error:
        Drv2605Backend(layout, bus=bus).open()
    message = str(error.value)
    assert "multiplexer 0x71 channel 2 (actuator row 2, column 2)" in message
    assert "is a DRV2604, not a DRV2605L" in message


def test_the_drv2605_without_l_is_accepted() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout, device_id=3)
    backend = opened(layout, bus)
    assert backend.is_open


def test_every_failing_chip_is_listed_at_once() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    bus.detach_chip(0x70, 3)
    bus.chip(mux=0x71, channel=0).device_id = 0
    with pytest.raises(HardwareError) as error:
        Drv2605Backend(layout, bus=bus).open()
    message = str(error.value)
    assert message.startswith("2 of 12 DRV2605L chips failed the check")
    assert "multiplexer 0x70 channel 3" in message and "multiplexer 0x71 channel 0" in message


def test_a_missing_multiplexer_is_named() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    bus.multiplexer(0x71).connected = False
    with pytest.raises(HardwareError, match=r"TCA9548A multiplexer 0x71 did not answer"):
        Drv2605Backend(layout, bus=bus).open()


def test_a_missing_multiplexer_says_the_others_were_switched_off_and_its_motors_may_run() -> None:
    # As for a chip that does not answer: the motors behind it got no "off", so the
    # message must say so (cut the power), and that every motor that answered is off.
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    left_running(bus)
    bus.multiplexer(0x71).connected = False
    with pytest.raises(HardwareError) as error:
        Drv2605Backend(layout, bus=bus).open()
    message = str(error.value)
    assert message.startswith("TCA9548A multiplexer 0x71 did not answer")
    assert message.endswith(
        " (every chip that answered was switched off first; a motor on a chip that did not"
        " answer may still run: if one keeps vibrating, cut the sleeve's power)"
    )
    behind = {key for key, chip in bus.chips.items() if key[0] == 0x71}
    assert behind and all(bus.chips[key].output > 0.5 for key in behind)  # unreachable: on
    assert all(chip.output == 0.0 for key, chip in bus.chips.items() if key not in behind)


def test_the_layout_is_checked_completely_before_any_i2c_traffic() -> None:
    layout = paper_layout()
    broken = dataclasses.replace(
        layout,
        multiplexers=(0x70, 0x71, 0x69),
        wiring=(*layout.wiring[:-1], Wire(0, 0, 0x70, 9)),
    )
    bus = EmulatedI2CBus.for_layout(layout)
    with pytest.raises(LayoutError) as error:
        Drv2605Backend(broken, bus=bus).open()
    problems = error.value.problems
    assert "multiplexer 0x69 is outside the TCA9548A range 0x70..0x77" in problems
    assert any("channel 9, outside the range 0..7" in p for p in problems)
    assert any("appears twice" in p for p in problems)
    assert "no wiring for actuator(s) row 2, column 3" in problems
    assert len(bus.log) == 0


# -- opening a real bus -------------------------------------------------------------------


def test_a_bus_that_does_not_exist_says_to_enable_i2c_or_use_the_simulator() -> None:
    backend = Drv2605Backend(paper_layout(i2c_bus=250))  # no /dev/i2c-250 anywhere
    with pytest.raises(HardwareError) as error:
        backend.open()
    message = str(error.value)
    assert "/dev/i2c-250" in message and "raspi-config" in message and "--backend sim" in message
    assert "'bus' in the [i2c] table of the sleeve layout" in message  # the key as the file has it
    assert not backend.is_open


def test_a_bus_without_permission_says_to_join_the_i2c_group(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def refuse(bus: int) -> None:
        raise PermissionError(13, "Permission denied", f"/dev/i2c-{bus}")

    monkeypatch.setattr(smbus2, "SMBus", refuse)
    with pytest.raises(HardwareError, match="add the user to the i2c group") as error:
        Drv2605Backend(paper_layout()).open()
    assert "--backend sim" in str(error.value)


def test_the_backend_closes_the_bus_it_opened_and_leaves_an_injected_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    layout = paper_layout()
    own_bus = EmulatedI2CBus.for_layout(layout)
    opened_numbers: list[int] = []

    def open_bus(number: int) -> EmulatedI2CBus:
        opened_numbers.append(number)
        return own_bus

    monkeypatch.setattr(smbus2, "SMBus", open_bus)
    with Drv2605Backend(layout):
        assert not own_bus.closed
    assert opened_numbers == [1] and own_bus.closed

    injected = EmulatedI2CBus.for_layout(layout)
    with Drv2605Backend(layout, bus=injected):
        pass
    assert not injected.closed


def test_a_failed_start_up_closes_the_bus_it_opened(monkeypatch: pytest.MonkeyPatch) -> None:
    layout = paper_layout()
    own_bus = EmulatedI2CBus.for_layout(layout)
    own_bus.detach_chip(0x71, 1)
    monkeypatch.setattr(smbus2, "SMBus", lambda number: own_bus)
    with pytest.raises(HardwareError), Drv2605Backend(layout):
        pass
    assert own_bus.closed


# -- playing ------------------------------------------------------------------------------


def test_set_intensity_writes_only_the_target_rtp_register_and_only_on_change() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = opened(layout, bus)
    before = {key: chip.write_count for key, chip in bus.chips.items()}
    target = bus.chip(mux=0x70, channel=3)

    backend.set_intensity(0, 3, 0.5)
    assert target.registers[RTP_INPUT] == 128  # round(127.5)
    assert target.writes[RTP_INPUT] == 3  # start-up's off and set-up zeros, then this one
    backend.set_intensity(0, 3, 0.5)  # unchanged: nothing on the bus
    backend.set_intensity(0, 3, 0.5001)  # another intensity, the same register value
    assert target.writes[RTP_INPUT] == 3
    backend.set_intensity(0, 3, 1.0)
    assert target.registers[RTP_INPUT] == 255 and target.writes[RTP_INPUT] == 4
    assert target.output == 1.0

    after = {key: chip.write_count for key, chip in bus.chips.items()}
    changed = {key for key in after if after[key] != before[key]}
    assert changed == {(0x70, 3)}
    assert target.write_count - before[(0x70, 3)] == 2
    assert backend.snapshot()[0][3] == 1.0


def test_consecutive_writes_to_one_channel_select_it_once() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = opened(layout, bus)
    backend.set_intensity(1, 1, 0.2)
    mux_writes = bus.multiplexer(0x70).writes + bus.multiplexer(0x71).writes
    backend.set_intensity(1, 1, 0.4)
    backend.set_intensity(1, 1, 0.6)
    assert bus.multiplexer(0x70).writes + bus.multiplexer(0x71).writes == mux_writes


def test_switching_between_multiplexers_deselects_the_other_first_and_never_conflicts() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = opened(layout, bus)
    backend.set_intensity(0, 0, 0.3)  # 0x70 channel 0
    bus.log.clear()
    backend.set_intensity(2, 1, 0.7)  # 0x71 channel 1
    mux_writes = [(t.address, t.value) for t in bus.log if t.address != DRV]
    assert mux_writes == [(0x70, 0x00), (0x71, 0b10)]
    assert bus.enabled_channels() == [(0x71, 1)]
    bus.log.clear()
    backend.set_intensity(0, 2, 0.9)  # back to 0x70 channel 2
    mux_writes = [(t.address, t.value) for t in bus.log if t.address != DRV]
    assert mux_writes == [(0x71, 0x00), (0x70, 0b100)]
    assert bus.conflicts == 0 and bus.max_enabled_channels == 1
    assert bus.chip(mux=0x71, channel=1).registers[RTP_INPUT] == round(0.7 * 255)
    assert bus.chip(mux=0x70, channel=2).registers[RTP_INPUT] == round(0.9 * 255)


def test_bad_arguments_name_the_allowed_range() -> None:
    layout = paper_layout()
    backend = opened(layout, EmulatedI2CBus.for_layout(layout))
    with pytest.raises(ValueError, match=r"intensity = 1\.5 .* \[0, 1\]"):
        backend.set_intensity(0, 0, 1.5)
    with pytest.raises(ValueError, match=r"intensity = nan"):
        backend.set_intensity(0, 0, math.nan)
    with pytest.raises(ValueError, match=r"row = 3 .* 0\.\.2 \(the grid is 3 x 4\)"):
        backend.set_intensity(3, 0, 0.5)
    with pytest.raises(ValueError, match=r"column = -1 .* 0\.\.3"):
        backend.set_intensity(0, -1, 0.5)


def test_set_intensity_needs_an_open_backend() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = Drv2605Backend(layout, bus=bus)
    with pytest.raises(RuntimeError, match="open it first"):
        backend.set_intensity(0, 0, 0.5)
    assert len(bus.log) == 0


def test_a_chip_that_stops_answering_is_named_and_set_up_again_once_back() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = opened(layout, bus)
    chip = bus.chip(mux=0x71, channel=3)
    chip.connected = False
    with pytest.raises(HardwareError, match=r"multiplexer 0x71 channel 3 .* stopped answering"):
        backend.set_intensity(2, 3, 0.5)
    chip.connected = True
    chip.reset()  # as after a power glitch: standby, signed data
    backend.set_intensity(2, 3, 0.5)
    assert chip.registers[MODE] == 0x05 and chip.rtp_unsigned
    assert chip.registers[RTP_INPUT] == 128


# -- all off ------------------------------------------------------------------------------


def test_all_off_leaves_every_chip_at_rtp_0_in_standby_and_every_channel_disabled() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = opened(layout, bus)
    backend.set_intensity(0, 0, 0.5)
    backend.set_intensity(2, 3, 1.0)
    backend.all_off()
    for chip in bus.chips.values():
        assert chip.registers[RTP_INPUT] == 0
        assert chip.registers[MODE] == 0x40
    assert bus.enabled_channels() == []
    assert backend.snapshot() == [[0.0] * 4 for _ in range(3)]
    assert bus.conflicts == 0

    backend.set_intensity(2, 3, 0.25)  # playing again wakes the chip
    chip = bus.chip(mux=0x71, channel=3)
    assert chip.registers[MODE] == 0x05 and chip.registers[RTP_INPUT] == round(0.25 * 255)


def test_all_off_tries_every_chip_when_one_fails_then_names_it() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = opened(layout, bus)
    for row, column in [(0, 0), (0, 1), (2, 0)]:
        backend.set_intensity(row, column, 0.8)
    bus.chip(mux=0x70, channel=1).connected = False
    with pytest.raises(HardwareError) as error:
        backend.all_off()
    message = str(error.value)
    assert "multiplexer 0x70 channel 1 (actuator row 0, column 1)" in message
    assert "cut the sleeve's power" in message
    for key, chip in bus.chips.items():
        if key != (0x70, 1):
            assert chip.registers[RTP_INPUT] == 0 and chip.registers[MODE] == 0x40
    assert bus.enabled_channels() == []


def test_all_off_reaches_one_multiplexer_when_the_other_is_gone() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = opened(layout, bus)
    backend.set_intensity(2, 0, 0.6)  # 0x71 selected
    backend.set_intensity(1, 0, 0.6)  # 0x70 selected, 0x71 deselected
    backend.set_intensity(2, 1, 0.6)  # 0x71 channel 1 selected last
    bus.multiplexer(0x71).connected = False
    with pytest.raises(HardwareError, match="multiplexer 0x71"):
        backend.all_off()
    for channel in range(8):
        chip = bus.chip(mux=0x70, channel=channel)
        assert chip.registers[RTP_INPUT] == 0 and chip.registers[MODE] == 0x40


def test_close_switches_everything_off_and_is_idempotent() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    with Drv2605Backend(layout, bus=bus) as backend:
        assert isinstance(backend, Backend)
        backend.set_intensity(1, 2, 1.0)
    backend.close()
    assert bus.chip(mux=0x70, channel=6).registers[MODE] == 0x40
    assert bus.chip(mux=0x70, channel=6).registers[RTP_INPUT] == 0
    with pytest.raises(RuntimeError, match="closed"):
        backend.set_intensity(1, 2, 1.0)


# -- the property -------------------------------------------------------------------------

_ACTUATORS = [(row, column) for row in range(3) for column in range(4)]
_CALLS = st.lists(
    st.tuples(
        st.sampled_from(_ACTUATORS),
        st.one_of(st.floats(0.0, 1.0), st.sampled_from([0.0, 0.5, 1.0, 1 / 255, 0.5 / 255])),
    ),
    max_size=60,
)


@settings(max_examples=150, deadline=None)
@given(calls=_CALLS)
def test_any_sequence_leaves_each_rtp_register_at_the_last_intensity_without_conflict(
    calls: list[tuple[tuple[int, int], float]],
) -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout, log_size=None)
    backend = opened(layout, bus)
    last = dict.fromkeys(_ACTUATORS, 0.0)
    for (row, column), intensity in calls:
        backend.set_intensity(row, column, intensity)
        last[(row, column)] = intensity
        assert len(bus.enabled_channels()) <= 1
    for (row, column), intensity in last.items():
        chip = bus.chip(mux=where(layout, row, column)[0], channel=where(layout, row, column)[1])
        assert chip.registers[RTP_INPUT] == round(255 * intensity)
        assert chip.registers[MODE] == 0x05
    assert bus.conflicts == 0
    assert bus.max_enabled_channels == 1
    rtp_writes = sum(1 for t in bus.log if t.op == "write_byte_data" and t.register == RTP_INPUT)
    distinct_changes = _count_level_changes(calls)
    # Start-up's off and set-up zeros, then one write per change.
    assert rtp_writes == 2 * 12 + distinct_changes


def _count_level_changes(calls: list[tuple[tuple[int, int], float]]) -> int:
    levels = dict.fromkeys(_ACTUATORS, 0)
    changes = 0
    for actuator, intensity in calls:
        level = round(255 * intensity)
        if level != levels[actuator]:
            levels[actuator] = level
            changes += 1
    return changes


# -- scan ---------------------------------------------------------------------------------


def test_scan_finds_every_chip_and_matches_the_layout() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    result = scan(bus, layout.multiplexers)
    assert result.main_bus == (0x70, 0x71)
    assert result.missing_multiplexers == ()
    assert len(result.channels) == 16
    found = {(c.multiplexer, c.channel): c for c in result.channels}
    assert found[(0x70, 5)].addresses == (DRV,) and found[(0x70, 5)].device_id == 7
    assert found[(0x71, 7)].addresses == () and found[(0x71, 7)].device_id is None
    report = compare_with_layout(result, layout)
    assert report.ok and report.problems() == []
    assert bus.enabled_channels() == [] and bus.conflicts == 0


def test_scan_reports_missing_wrong_and_unexpected_chips() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    bus.detach_chip(0x70, 3)
    bus.chip(mux=0x71, channel=2).device_id = DRV2604_DEVICE_ID
    bus.attach_chip(0x71, 6)
    report = compare_with_layout(scan(bus, layout.multiplexers), layout)
    assert not report.ok
    assert report.problems() == [
        "No DRV2605L answered on multiplexer 0x70 channel 3 (actuator row 0, column 3)",
        "A DRV2604 answered on multiplexer 0x71 channel 2 (actuator row 2, column 2), "
        "not a DRV2605L",
        "A chip answers at 0x5A on multiplexer 0x71 channel 6, where the layout wires no actuator",
    ]
    statuses = {(w.wire.row, w.wire.column): w.status for w in report.wires}
    assert statuses[(0, 3)] == "missing" and statuses[(2, 2)] == "wrong-chip"
    assert statuses[(1, 1)] == "ok"


def test_scan_reports_a_missing_multiplexer_and_a_chip_on_the_main_bus() -> None:
    layout = paper_layout()
    bus = EmulatedI2CBus.for_layout(layout)
    bus.multiplexer(0x71).connected = False
    bus.attach_main_bus_chip()
    result = scan(bus, layout.multiplexers)
    assert result.missing_multiplexers == (0x71,)
    assert DRV in result.main_bus
    report = compare_with_layout(result, layout)
    statuses = {(w.wire.row, w.wire.column): w.status for w in report.wires}
    assert statuses[(2, 0)] == "multiplexer-missing"
    assert any("on the main bus" in p for p in report.problems())
