"""The enable line in the layout and in the hardware backend, on the emulated bus, in process.

The order is what makes the line a safety: low before any I2C at start-up, high only
once every chip is off and checked (and reads back off), low before any I2C "off"
and at the very transaction that finds a chip gone; high again only when every chip
answers. The emulated line counts its rises and records when it changed (the bus's
transaction count), so each test reads the order from the bus itself.
"""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
from pathlib import Path

import pytest

from feelmysign.backends import Drv2605Backend, EmulatedI2CBus
from feelmysign.backends.emulated_i2c import RTP_INPUT, EmulatedDRV2605L, EmulatedEnableLine
from feelmysign.backends.emulated_state import drive_levels, open_state_bus
from feelmysign.backends.factory import enable_line_for
from feelmysign.bench import restart_off
from feelmysign.errors import HardwareError, LayoutError
from feelmysign.layout import EnableLine, Layout, check_layout, load_layout, parse_layout

LINE = EnableLine(chip="gpiochip0", line=17)


def layout_with_line() -> Layout:
    return dataclasses.replace(load_layout(restart_off.PAPER), enable=LINE)


def backend_on(bus: EmulatedI2CBus, layout: Layout) -> Drv2605Backend:
    return Drv2605Backend(layout, bus=bus, enable=enable_line_for(layout, bus))


def line_of(bus: EmulatedI2CBus) -> EmulatedEnableLine:
    assert bus.enable_line is not None
    return bus.enable_line


def record_changes(bus: EmulatedI2CBus) -> list[tuple[bool, int]]:
    """Every change of the bus's line from now on: (level, bus transactions before it)."""
    changes: list[tuple[bool, int]] = []
    line, original = line_of(bus), bus.enable_changed

    def changed() -> None:
        changes.append((line.level, bus.transactions))
        original()

    bus.enable_changed = changed  # type: ignore[method-assign]
    return changes


# --- the layout -----------------------------------------------------------------------------


def paper_text(enable: str) -> str:
    return restart_off.PAPER.read_text().replace("[i2c]\n", f"[i2c]\nenable = {enable}\n", 1)


def test_a_layout_takes_an_enable_line_and_checks_it_as_it_checks_every_key() -> None:
    assert parse_layout(paper_text('{ chip = "gpiochip0", line = 17 }')).enable == LINE
    assert parse_layout(paper_text('{ chip = "/dev/gpiochip4", line = 0 }')).enable == EnableLine(
        "/dev/gpiochip4", 0
    )
    assert load_layout(restart_off.PAPER).enable is None  # optional: without it, as before
    with pytest.raises(LayoutError) as caught:
        parse_layout(paper_text('{ chip = "gpio0", line = "GPIO17", pin = 11 }'))
    problems = caught.value.problems
    assert any(p.startswith("i2c.enable.pin: unknown key") for p in problems), problems
    assert any(p.startswith("i2c.enable.chip: must be a GPIO chip name") for p in problems)
    assert any("17 for GPIO17" in p for p in problems if p.startswith("i2c.enable.line"))
    assert len(problems) == 3, problems


@pytest.mark.parametrize(
    ("enable", "problem"),
    [
        ("{ line = 17 }", "i2c.enable.chip: missing"),
        ('{ chip = "gpiochip0" }', "i2c.enable.line: missing"),
        (
            '{ chip = "gpiochip0", line = 1024 }',
            "i2c.enable.line: must be a whole number from 0 to 1023",
        ),
        (
            '{ chip = "gpiochip0", line = -1 }',
            "i2c.enable.line: must be a whole number from 0 to 1023",
        ),
        ("17", "i2c.enable: must be a table such as"),
    ],
)
def test_a_bad_enable_line_is_named_with_what_is_allowed(enable: str, problem: str) -> None:
    with pytest.raises(LayoutError) as caught:
        parse_layout(paper_text(enable))
    assert any(p.startswith(problem) for p in caught.value.problems), caught.value.problems


def test_an_enable_line_needs_wiring_and_belongs_in_the_i2c_table() -> None:
    bare = "rows = 2\ncolumns = 2\nspacing_cm = 3.0\n"
    with pytest.raises(LayoutError) as caught:
        parse_layout(bare + '[i2c]\nenable = { chip = "gpiochip0", line = 17 }\n')
    assert any(
        p.startswith("i2c.enable: an enable line needs i2c.wiring") for p in caught.value.problems
    )
    with pytest.raises(LayoutError) as caught:
        parse_layout('enable = { chip = "gpiochip0", line = 17 }\n' + bare)
    assert any("belongs in the [i2c] table" in p for p in caught.value.problems)
    assert check_layout(layout_with_line()).enable == LINE  # a layout built in code, the same rules


# --- the backend ------------------------------------------------------------------------------


def test_at_start_the_line_is_low_before_any_i2c_and_high_only_once_every_chip_is_checked() -> None:
    layout = layout_with_line()
    bus = EmulatedI2CBus.for_layout(layout)
    line = line_of(bus)
    changes = record_changes(bus)
    backend = backend_on(bus, layout)
    backend.open()
    assert changes[0] == (False, 0)  # requested low before the first transaction
    assert changes[-1] == (True, bus.transactions)  # high after the last one of the start
    assert line.rises == 1 and line.effective_high
    # Every chip was read back as off (MODE and RTP_INPUT) before the line went high.
    reads = [t for t in bus.log if t.op == "read_byte_data" and t.register == RTP_INPUT]
    assert len(reads) == len(layout.wiring)
    backend.close()
    assert not line.effective_high and line.holder is None


def test_the_line_is_dropped_before_any_i2c_off_and_stays_low_at_close() -> None:
    layout = layout_with_line()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = backend_on(bus, layout)
    backend.open()
    backend.set_intensity(1, 1, 0.7)
    before = bus.transactions
    changes = record_changes(bus)
    backend.close()
    assert changes[0] == (False, before)  # low before the close's first transaction
    assert bus.transactions > before  # and then the off went out over I2C
    assert all(level is False for level, _ in changes)  # never high again on the way out
    assert all(chip.output == 0 and chip.standby for chip in bus.chips.values())


def test_a_chip_lost_while_on_drops_the_line_at_the_failed_write_and_it_rises_when_back() -> None:
    layout = layout_with_line()
    bus = EmulatedI2CBus.for_layout(layout)
    backend = backend_on(bus, layout)
    backend.open()
    backend.set_intensity(1, 1, 0.7)
    wire = next(w for w in layout.wiring if (w.row, w.column) == (1, 1))
    chip = bus.chip(mux=wire.multiplexer, channel=wire.channel)
    assert chip.output > 0
    chip.connected = False
    with pytest.raises(HardwareError, match=f"channel {wire.channel}"):
        backend.set_intensity(1, 1, 0.3)
    line = line_of(bus)
    assert chip.lost_at is not None and line.changed_at is not None
    assert line.changed_at[1] == chip.lost_at[1]  # at that very transaction
    assert not line.effective_high and chip.output == 0  # its registers still say on
    assert backend.silenced and set(backend.lost) == {(1, 1)}
    backend.all_off()  # the others off over I2C; the line stays low
    assert not line.effective_high and backend.retry_lost() == []
    chip.connected = True
    assert backend.retry_lost() == [(1, 1)]
    assert line.effective_high and not backend.silenced and backend.lost == {}
    assert chip.output == 0 and chip.standby
    backend.set_intensity(1, 1, 0.5)  # set up again, and it plays
    assert chip.output == pytest.approx(0.5, abs=0.01)
    backend.close()


def test_a_chip_that_ignores_writes_with_en_low_keeps_the_line_low() -> None:
    """The datasheet says a DRV2605L may not take writes while EN is low: one that kept a
    level must not be woken by the line going high."""
    layout = layout_with_line()
    bus = EmulatedI2CBus.for_layout(layout)
    wire = layout.wiring[0]
    stubborn = bus.chip(mux=wire.multiplexer, channel=wire.channel)
    stubborn.registers[RTP_INPUT] = 0x80
    stubborn.registers[0x01] = 0x05  # RTP mode: it would drive at once with EN high
    ignore = EmulatedDRV2605L.write

    def write(register: int, value: int) -> None:
        if stubborn.enabled:
            ignore(stubborn, register, value)

    stubborn.write = write  # type: ignore[method-assign]
    backend = backend_on(bus, layout)
    with pytest.raises(HardwareError, match='did not take its "off"') as caught:
        backend.open()
    assert "stays low" in str(caught.value)
    assert line_of(bus).rises == 0 and stubborn.output == 0


def test_feelmysign_off_drops_the_line_before_any_i2c(tmp_path: Path) -> None:
    layout = layout_with_line()
    state = tmp_path / "bus.json"
    bus = open_state_bus(state, layout)
    backend = backend_on(bus, layout)
    backend.open()
    backend.set_intensity(0, 0, 0.9)
    # A second process (feelmysign off) while none holds the line: the sleeve was killed.
    data = json.loads(state.read_text())
    data["enable"]["holder"] = {"pid": 2**22 + 1, "start": 1}  # no such process
    state.write_text(json.dumps(data))
    assert set(drive_levels(state).values()) == {0.0}  # the pull-down, before anyone acts
    other = open_state_bus(state, layout)
    before = other.transactions
    changes = record_changes(other)
    problems = backend_on(other, layout).switch_off_unchecked()
    assert problems == []
    assert changes[0] == (False, before)  # taken, low, before any I2C
    assert other.transactions > before and all(level is False for level, _ in changes)
    line = line_of(other)
    assert line.holder is None and line.rises == line_of(bus).rises  # let go, never raised
    assert all(chip.output == 0 and chip.standby for chip in other.chips.values())


# --- the commands -----------------------------------------------------------------------------


def feelmysign(tmp_path: Path, *arguments: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "state")}
    return subprocess.run(
        [*restart_off.feelmysign_command(), *arguments],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )


def test_scan_reports_the_line_and_off_and_buzz_leave_it_low(tmp_path: Path) -> None:
    layout = tmp_path / "layout.toml"
    layout.write_text(paper_text('{ chip = "gpiochip0", line = 17 }'))
    state = tmp_path / "bus.json"
    where = ["--layout", str(layout), "--emulate-state", str(state)]

    buzz = feelmysign(tmp_path, "buzz", "1", "1", "--duration-ms", "50", *where)
    assert buzz.returncode == 0, buzz.stderr
    assert "Enable line gpiochip0 line 17 high" in buzz.stdout
    assert buzz.stdout.rstrip().endswith("Every motor is off. Enable line gpiochip0 line 17 low.")
    assert json.loads(state.read_text())["enable"]["rises"] == 1

    scan = feelmysign(tmp_path, "scan", "--json", *where)
    assert scan.returncode == 0, scan.stderr
    assert json.loads(scan.stdout)["enable"] == {
        "line": "gpiochip0 line 17",
        "holder": "free (nobody drives it; the pull-down holds it)",
        "level": "low",
        "problem": None,
    }
    off = feelmysign(tmp_path, "off", *where)
    assert off.returncode == 0, off.stderr
    assert "the emulated enable line (gpiochip0 line 17) is low" in off.stdout
    saved = json.loads(state.read_text())["enable"]
    assert (saved["level"], saved["holder"], saved["rises"]) == (0, None, 1)


def test_a_layout_with_a_line_on_a_pi_without_that_gpio_chip_says_what_to_fix(
    tmp_path: Path,
) -> None:
    from feelmysign.backends.enable import GpiodLine

    line = GpiodLine(EnableLine(chip="gpiochip99", line=17))
    with pytest.raises(HardwareError, match="there is no /dev/gpiochip99; list the GPIO chips"):
        line.request()
    assert not line.high
    line.release()  # never taken: nothing to let go
