"""``feelmysign scan`` and ``buzz`` on the emulated bus and the simulator, the backend factory,
and the wiring table of docs/sleeve-hardware.md against the paper's layout file."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from feelmysign.backends import EmulatedI2CBus, SimBackend
from feelmysign.backends import factory as factory_module
from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_i2c import DRV2604_DEVICE_ID, MODE, RTP_INPUT
from feelmysign.backends.factory import open_backend
from feelmysign.cli import main
from feelmysign.cli import scan as scan_cli
from feelmysign.errors import LayoutError, ParameterError
from feelmysign.layout import PAPER_SLEEVE, Layout, load_layout

REPOSITORY = Path(__file__).resolve().parents[2]
PAPER_LAYOUT_FILE = REPOSITORY / "deploy" / "layouts" / "paper-sleeve.toml"
HARDWARE_DOC = REPOSITORY / "docs" / "sleeve-hardware.md"
PAPER = str(PAPER_LAYOUT_FILE)
NO_SUCH_BUS = 250  # /dev/i2c-250: no machine has that many buses


@pytest.fixture(autouse=True)
def no_layout_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("FEELMYSIGN_LAYOUT", raising=False)


@pytest.fixture
def paper() -> Layout:
    return load_layout(PAPER_LAYOUT_FILE)


@pytest.fixture
def emulated_buses(monkeypatch: pytest.MonkeyPatch) -> list[EmulatedI2CBus]:
    """Every emulated bus the backend factory makes (for --emulate), to look at afterwards."""
    made: list[EmulatedI2CBus] = []

    def for_layout(layout: Layout, **options: Any) -> EmulatedI2CBus:
        bus = EmulatedI2CBus.for_layout(layout, **options)
        made.append(bus)
        return bus

    monkeypatch.setattr(factory_module, "EmulatedI2CBus", SimpleNamespace(for_layout=for_layout))
    return made


def _scan_with(
    monkeypatch: pytest.MonkeyPatch, bus: EmulatedI2CBus
) -> Callable[..., tuple[int, str]]:
    """Run scan as on real hardware, with ``bus`` standing in for /dev/i2c-N."""
    opened: list[int] = []

    def open_bus(bus_number: int) -> EmulatedI2CBus:
        opened.append(bus_number)
        return bus

    monkeypatch.setattr(scan_cli, "_open_bus", open_bus)

    def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
        code = main(["scan", "--layout", PAPER, *argv])
        assert opened[-1] == 1  # the layout's bus
        return code, capsys.readouterr().out

    return run


def _statuses(out: str) -> dict[tuple[str, str], str]:
    """(multiplexer, channel) -> status, read from the printed table by its header's columns."""
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("multiplexer  channel"))
    status_at = lines[start].index("status")
    statuses = {}
    for line in lines[start + 1 :]:
        if not line:
            break
        multiplexer, channel = line.split()[:2]
        statuses[(multiplexer, channel)] = line[status_at:].strip()
    return statuses


# --- scan ---------------------------------------------------------------------------------------


def test_scan_of_the_emulated_paper_sleeve_matches(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scan", "--layout", PAPER, "--emulate"]) == 0
    out = capsys.readouterr().out
    assert scan_cli.EMULATED_NOTE in out  # it says that nothing real was probed
    statuses = _statuses(out)
    assert list(statuses.values()).count("ok") == 12
    assert [statuses[("0x71", str(c))] for c in range(4, 8)] == ["free"] * 4
    assert re.search(r"^0x70\s+0\s+row 0, column 0\s+0x5A DRV2605L\s+ok$", out, re.MULTILINE)
    assert "All 12 actuators answer as the layout says." in out


def test_scan_json_is_one_object(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scan", "--layout", PAPER, "--emulate", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert (report["ok"], report["emulated"], report["problems"]) == (True, True, [])
    assert len(report["channels"]) == 16
    assert report["channels"][6] == {
        "multiplexer": "0x70",
        "channel": 6,
        "expected": {"row": 1, "column": 2},
        "found": "0x5A DRV2605L",
        "status": "ok",
    }


def test_scan_names_missing_wrong_and_unexpected_chips(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], paper: Layout
) -> None:
    bus = EmulatedI2CBus.for_layout(paper)
    bus.detach_chip(0x70, 5)
    bus.chip(mux=0x71, channel=2).device_id = DRV2604_DEVICE_ID
    bus.attach_chip(0x71, 6)
    code, out = _scan_with(monkeypatch, bus)(capsys)
    assert code == 1
    statuses = _statuses(out)
    assert statuses[("0x70", "5")] == "MISSING"
    assert statuses[("0x71", "2")] == "WRONG CHIP"
    assert statuses[("0x71", "6")] == "UNEXPECTED"
    assert list(statuses.values()).count("ok") == 10
    assert "10 of 12 actuators answer as the layout says. Problems:" in out
    assert "No DRV2605L answered on multiplexer 0x70 channel 5 (actuator row 1, column 1)" in out
    assert "A DRV2604 answered on multiplexer 0x71 channel 2" in out
    assert "multiplexer 0x71 channel 6, where the layout wires no actuator" in out
    assert bus.enabled_channels() == [] and bus.closed  # left as found, and let go


def test_scan_says_which_multiplexer_is_missing(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], paper: Layout
) -> None:
    bus = EmulatedI2CBus.for_layout(paper)
    bus.multiplexer(0x71).connected = False
    code, out = _scan_with(monkeypatch, bus)(capsys)
    assert code == 1
    statuses = _statuses(out)
    assert [statuses[("0x71", str(c))] for c in range(4)] == ["multiplexer missing"] * 4
    assert ("0x71", "4") not in statuses  # nothing expected there, nothing to say
    assert "Multiplexer 0x71 did not answer" in out


def test_scan_without_i2c_says_what_to_do(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scan", "--layout", PAPER, "--bus", str(NO_SUCH_BUS)]) == 1
    error = capsys.readouterr().err
    assert error.startswith(f"Error: I2C bus {NO_SUCH_BUS} does not exist")
    assert "raspi-config" in error and "--emulate" in error


def test_scan_with_an_unwired_layout_checks_nothing_and_fails(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["scan", "--emulate"]) == 1
    assert "wires no actuator, so nothing was checked" in capsys.readouterr().out


def test_scan_bad_bus_number(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scan", "--layout", PAPER, "--bus", "-1"]) == 1
    assert "--bus = -1 is not allowed" in capsys.readouterr().err


def test_scan_runs_as_a_command() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "feelmysign", "scan", "--layout", PAPER, "--emulate"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "All 12 actuators answer" in result.stdout


# --- buzz ---------------------------------------------------------------------------------------


def test_buzz_on_the_simulator_turns_one_motor_on_then_off(
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["buzz", "1", "2", "--backend", "sim", "--intensity", "0.5", "--duration-ms", "20"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "Buzzing row 1, column 2 on the simulator at intensity 0.5 for 20 ms" in out
    changes = re.findall(r"row (\d), column (\d): intensity ([\d.]+)", out)
    assert changes == [("1", "2", "0.5"), ("1", "2", "0")]
    assert "Every motor is off." in out


def test_buzz_on_the_emulated_hardware_drives_the_wired_chip_only(
    emulated_buses: list[EmulatedI2CBus], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["buzz", "1", "2", "--layout", PAPER, "--emulate", "--duration-ms", "10"]) == 0
    out = capsys.readouterr().out
    assert "(DRV2605L on multiplexer 0x70 channel 6, an emulated I2C bus)" in out
    (bus,) = emulated_buses
    rtp_writes = [
        (t.device, t.value)
        for t in bus.log
        if t.op == "write_byte_data" and t.register == RTP_INPUT and t.value
    ]
    assert rtp_writes == [("DRV2605L 0x70/6", round(PAPER_SLEEVE.default_intensity * 255))]
    assert all(chip.standby and chip.output == 0 for chip in bus.chips.values())
    assert bus.enabled_channels() == []


def test_buzz_caps_intensity_and_on_time_at_the_layout_s(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    layout = tmp_path / "gentle.toml"
    layout.write_text(
        'name = "gentle"\nrows = 2\ncolumns = 2\nspacing_cm = 3.0\ndefault_intensity = 0.3\n'
        "[safety]\nmax_intensity = 0.5\nmax_stroke_duration_ms = 15\nmax_on_time_ms = 15\n"
    )
    argv = ["buzz", "0", "1", "--backend", "sim", "--layout", str(layout)]
    assert main([*argv, "--intensity", "0.9", "--duration-ms", "60000"]) == 0
    out = capsys.readouterr().out
    assert "Intensity 0.9 capped at the layout's safety.max_intensity 0.5." in out
    assert "Duration 60000 ms capped at the layout's safety.max_on_time_ms 15 ms." in out
    assert "at intensity 0.5 for 15 ms" in out


@pytest.mark.parametrize(
    ("row", "column", "says"),
    [
        ("3", "0", "row = 3 is not allowed; it must be an integer in 0..2 (the grid is 3 x 4)"),
        ("0", "4", "column = 4 is not allowed; it must be an integer in 0..3"),
        ("-1", "0", "row = -1 is not allowed"),
    ],
)
def test_buzz_a_motor_outside_the_grid_names_the_range(
    row: str, column: str, says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["buzz", row, column, "--backend", "sim"]) == 1
    assert says in capsys.readouterr().err


@pytest.mark.parametrize(
    ("option", "says"),
    [
        (["--intensity", "1.5"], "--intensity = 1.5 is not allowed; it must be a number in [0, 1]"),
        (["--duration-ms", "0"], "--duration-ms = 0.0 is not allowed"),
    ],
)
def test_buzz_bad_values_name_the_range(
    option: list[str], says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["buzz", "0", "0", "--backend", "sim", *option]) == 1
    assert says in capsys.readouterr().err


def test_buzz_on_hardware_needs_a_wired_layout(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["buzz", "0", "0"]) == 1
    error = capsys.readouterr().err
    assert "i2c.wiring: missing" in error and "--layout FILE" in error and "--backend sim" in error


def test_buzz_without_i2c_says_what_to_do(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    layout = tmp_path / "layout.toml"
    text = PAPER_LAYOUT_FILE.read_text()
    layout.write_text(re.sub(r"^bus = 1\b", f"bus = {NO_SUCH_BUS}", text, flags=re.MULTILINE))
    assert main(["buzz", "0", "0", "--layout", str(layout)]) == 1
    error = capsys.readouterr().err
    assert f"I2C bus {NO_SUCH_BUS} does not exist" in error and "--backend sim" in error


def test_buzz_switches_everything_off_on_ctrl_c(
    emulated_buses: list[EmulatedI2CBus],
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    def interrupted(_seconds: float) -> None:
        (bus,) = emulated_buses
        assert bus.chip(mux=0x70, channel=0).output > 0  # on when Ctrl-C comes
        raise KeyboardInterrupt

    monkeypatch.setattr("feelmysign.cli.buzz.time.sleep", interrupted)
    assert main(["buzz", "0", "0", "--layout", PAPER, "--emulate"]) == 130
    (bus,) = emulated_buses
    assert all(chip.output == 0 and chip.standby for chip in bus.chips.values())
    out = capsys.readouterr().out
    assert "Interrupted after" in out and "Every motor is off." in out


# --- the backend factory ----------------------------------------------------------------------


def test_factory_sim_records_to_a_file(tmp_path: Path) -> None:
    record = tmp_path / "felt.jsonl"
    with open_backend("sim", PAPER_SLEEVE, record=record) as backend:
        assert isinstance(backend, SimBackend)
        backend.set_intensity(0, 1, 0.5)
    lines = record.read_text().splitlines()
    assert [line.count('"intensity"') for line in lines] == [1, 1]  # on, then off at close


def test_factory_emulated_drv2605_drives_the_emulated_chip(
    emulated_buses: list[EmulatedI2CBus], paper: Layout
) -> None:
    backend = open_backend("drv2605", paper, emulate=True)
    try:
        assert isinstance(backend, Drv2605Backend)
        backend.set_intensity(2, 3, 1.0)
        (bus,) = emulated_buses
        assert bus.chip(mux=0x71, channel=3).output == 1.0
    finally:
        backend.close()
    assert bus.chip(mux=0x71, channel=3).standby


@pytest.mark.parametrize(
    ("name", "options", "error", "says"),
    [
        ("tactor", {}, ParameterError, "'sim' (the simulator) or 'drv2605'"),
        ("drv2605", {}, LayoutError, "i2c.wiring: missing"),
        ("sim", {"emulate": True}, ParameterError, "use them with --backend drv2605"),
        ("sim", {"record": "/nonexistent/x.jsonl"}, ParameterError, "a file that can be written"),
    ],
)
def test_factory_refuses_what_cannot_work(
    name: Any, options: dict[str, Any], error: type[Exception], says: str
) -> None:
    with pytest.raises(error, match=re.escape(says)):
        open_backend(name, PAPER_SLEEVE, **options)


def test_factory_refuses_a_record_with_the_hardware(paper: Layout, tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match="only the simulator records"):
        open_backend("drv2605", paper, record=tmp_path / "x.jsonl", emulate=True)


# --- the hardware documentation -------------------------------------------------------------


def test_the_documented_wiring_table_is_the_paper_layout_s(paper: Layout) -> None:
    rows = re.findall(
        r"^\| (\d+) \| (\d+) \| \((\d+), (\d+)\) \| (0x7[0-7]) \| (\d) \|$",
        HARDWARE_DOC.read_text(encoding="utf-8"),
        re.MULTILINE,
    )
    documented = [
        (int(row), int(column), int(multiplexer, 16), int(channel))
        for row, column, x, y, multiplexer, channel in rows
        if (x, y) == (column, row)  # the grid point column agrees with row and column
    ]
    assert len(documented) == len(rows)
    layout_wiring = [(w.row, w.column, w.multiplexer, w.channel) for w in paper.wiring]
    assert documented == layout_wiring


def test_every_status_scan_gives_a_fault_is_explained_in_troubleshooting(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], paper: Layout
) -> None:
    # One chip of each fault; the builder looks the status up in the doc's Troubleshooting.
    bus = EmulatedI2CBus.for_layout(paper)
    bus.detach_chip(0x70, 3)  # MISSING
    bus.chip(mux=0x71, channel=2).device_id = DRV2604_DEVICE_ID  # WRONG CHIP
    bus.attach_chip(0x71, 6)  # UNEXPECTED
    left_on = bus.chip(mux=0x70, channel=4)  # DRIVING: as a killed sleeve leaves it
    left_on.registers[RTP_INPUT] = 0x66
    left_on.registers[MODE] = 0x05
    code, out = _scan_with(monkeypatch, bus)(capsys)
    assert code == 1
    faults = {status for status in _statuses(out).values() if status not in ("ok", "free")}
    assert faults == {"MISSING", "WRONG CHIP", "UNEXPECTED", "DRIVING"}
    doc = HARDWARE_DOC.read_text(encoding="utf-8")
    troubleshooting = doc[doc.index("## Troubleshooting") :]
    for status in faults:
        assert f"(`{status}`" in troubleshooting or f"`{status}` in `scan`" in troubleshooting, (
            status
        )
    bring_up = doc[doc.index("## Bring-up, step by step") : doc.index("## Motors off")]
    for status in faults:
        assert f"`{status}`" in bring_up, status  # step 4 lists what Troubleshooting explains


def test_scan_names_a_motor_left_driving_and_fails(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], paper: Layout
) -> None:
    # As a sleeve killed without an enable line leaves a chip: in real-time playback at a level.
    bus = EmulatedI2CBus.for_layout(paper)
    chip = bus.chip(mux=0x70, channel=4)
    chip.registers[RTP_INPUT] = 0x66
    chip.registers[MODE] = 0x05  # out of standby, real-time playback
    assert chip.output > 0.0
    code, out = _scan_with(monkeypatch, bus)(capsys)
    assert code == 1
    statuses = _statuses(out)
    assert statuses[("0x70", "4")] == "DRIVING"
    assert list(statuses.values()).count("ok") == 11
    assert "is left driving its motor (MODE 0x05, RTP_INPUT 0x66)" in out
    assert "'feelmysign off'" in out
    assert chip.output > 0.0  # scan only reads: it changes nothing on the bus
