"""The all-off a starting ``sleeve``, ``buzz`` or ``off`` does before parsing its command line.

It reads which chips to reach from a memo of the layout file (the layout's
exact text and the wiring it gives), and falls back to the full layout reader,
switching every channel of every multiplexer named, when the file changed.
"""

from __future__ import annotations

import errno
import json
import os
import threading
from pathlib import Path

import pytest

import feelmysign.layout
from feelmysign.backends import all_off
from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_state import drive_levels, open_state_bus, state_of
from feelmysign.early_off import switch_off_early
from feelmysign.layout import Layout, load_layout

REPO = Path(__file__).resolve().parents[2]
PAPER = str(REPO / "deploy" / "layouts" / "paper-sleeve.toml")
PAPER_TEXT = Path(PAPER).read_text()


@pytest.fixture(autouse=True)
def state_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Where the wiring memo goes: this test's own folder, never the person's home."""
    home = tmp_path / "state-home"
    monkeypatch.setenv("XDG_STATE_HOME", str(home))
    return home


def _left_on(path: Path, *actuators: tuple[int, int]) -> None:
    """A sleeve on the paper's layout that dies with ``actuators`` (row 2, column 2) on."""
    layout = load_layout(PAPER)
    backend = Drv2605Backend(layout, bus=open_state_bus(path, layout))
    backend.open()
    for row, column in actuators or ((2, 2),):
        backend.set_intensity(row, column, 1.0)  # and the process "dies": nothing closes it
    assert max(drive_levels(path).values()) == 1.0


def _editable_paper_layout(tmp_path: Path) -> tuple[Path, Path, list[str]]:
    """A copy of the paper's layout to edit, an emulated bus, and the options naming both."""
    layout_path = tmp_path / "layout.toml"
    layout_path.write_text(PAPER_TEXT)
    state = tmp_path / "bus.json"
    return layout_path, state, ["--layout", str(layout_path), "--emulate-state", str(state)]


def _memos(home: Path) -> list[Path]:
    return sorted((home / "feelmysign" / "wiring").glob("*.txt"))


def _refuse_to_parse(monkeypatch: pytest.MonkeyPatch) -> None:
    """The full layout reader fails the test if called: the memo alone must do."""

    def refuse(text: str, source: str = "") -> Layout:
        raise AssertionError("the early pass read the TOML although the memo matched")

    monkeypatch.setattr(feelmysign.layout, "parse_layout", refuse)


@pytest.mark.parametrize(
    ("command", "arguments", "switched_off"),
    [
        ("sleeve", ["--backend", "drv2605", "--layout", PAPER], True),
        ("sleeve", ["--backend=drv2605", "--layout=" + PAPER, "--broker", "x"], True),
        ("buzz", ["0", "1", "--layout", PAPER], True),  # buzz drives the chips by default
        ("sleeve", ["--layout", PAPER], False),  # the simulator: no chip to reach
        ("scan", ["--layout", PAPER], False),  # only reads
        ("sleeve", ["--backend", "drv2605", "--layout"], False),  # unparsable: left to argparse
        ("sleeve", ["--backend", "drv2605", "--layout", PAPER, "--emulate"], True),  # + state
    ],
)
def test_the_early_pass_switches_off_only_what_a_starting_command_drives(
    tmp_path: Path, command: str, arguments: list[str], switched_off: bool
) -> None:
    state = tmp_path / "bus.json"
    _left_on(state)
    switch_off_early(command, [*arguments, "--emulate-state", str(state)])
    assert (drive_levels(state)["0x71/2"] == 0.0) == switched_off


def test_the_early_pass_reads_the_layout_from_the_environment(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    state = tmp_path / "bus.json"
    _left_on(state)
    monkeypatch.setenv("FEELMYSIGN_LAYOUT", PAPER)
    switch_off_early("sleeve", ["--backend", "drv2605", "--emulate-state", str(state)])
    assert set(drive_levels(state).values()) == {0.0}


def test_a_fifo_as_layout_does_not_hang_the_early_pass(tmp_path: Path) -> None:
    fifo = tmp_path / "layout.toml"
    os.mkfifo(fifo)
    done = threading.Event()

    def run() -> None:
        switch_off_early("sleeve", ["--backend", "drv2605", "--layout", str(fifo)])
        done.set()

    threading.Thread(target=run, daemon=True).start()
    assert done.wait(30), "the early pass opened the fifo and waits for a writer"


def test_off_is_an_early_command_too(tmp_path: Path) -> None:
    state = tmp_path / "bus.json"
    _left_on(state)
    switch_off_early("off", ["--layout", PAPER, "--emulate-state", str(state)])
    assert set(drive_levels(state).values()) == {0.0}


def test_after_the_first_start_the_memo_alone_says_which_chips_to_switch_off(
    tmp_path: Path, state_home: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    state = tmp_path / "bus.json"
    _left_on(state)
    arguments = ["--backend", "drv2605", "--layout", PAPER, "--emulate-state", str(state)]
    switch_off_early("sleeve", arguments)  # the first start: the full reader, then the memo
    [memo] = _memos(state_home)
    assert memo.read_bytes().endswith(Path(PAPER).read_bytes())
    _left_on(state, (1, 3), (0, 0))
    _refuse_to_parse(monkeypatch)
    # Exactly the 12 wired chips (not the 4 free channels of 0x71): nothing fails.
    assert switch_off_early("sleeve", arguments) == []
    assert set(drive_levels(state).values()) == {0.0}


def test_a_first_start_switches_off_every_channel_of_every_multiplexer_named(
    tmp_path: Path, state_home: Path
) -> None:
    state = tmp_path / "bus.json"
    _left_on(state)
    problems = switch_off_early(
        "sleeve", ["--backend", "drv2605", "--layout", PAPER, "--emulate-state", str(state)]
    )
    assert set(drive_levels(state).values()) == {0.0}
    # The channels the layout leaves free were tried too, and nothing answered there.
    assert sorted(problems) == [
        f"DRV2605L on multiplexer 0x71 channel {channel}: no answer" for channel in range(4, 8)
    ]
    assert len(_memos(state_home)) == 1


def test_after_an_edit_the_chips_the_old_layout_wired_are_switched_off_too(
    tmp_path: Path, state_home: Path
) -> None:
    layout_path, state, arguments = _editable_paper_layout(tmp_path)
    _left_on(state)
    switch_off_early("buzz", arguments)  # the memo of the layout as it was
    _left_on(state)  # 0x71/2, which the old layout wires
    # The edit moves row 2 from multiplexer 0x71 to 0x72: the new layout no longer names
    # 0x71, but the chip the killed sleeve left on there is still driving its motor.
    layout_path.write_text(PAPER_TEXT.replace("0x71", "0x72"))
    problems = switch_off_early("buzz", arguments)
    assert drive_levels(state)["0x71/2"] == 0.0
    assert "DRV2605L on multiplexer 0x72 channel 0: no answer" in problems  # the new one tried
    assert f"source {layout_path}".encode() in _memos(state_home)[0].read_bytes()
    assert b"0x72" in _memos(state_home)[0].read_bytes()  # the memo follows the edit


@pytest.mark.parametrize(
    "memo",
    [
        b"",
        b"garbage",
        b"feelmysign-wiring/1 0.1.0\nsource /x\nlayout 3\nabc",  # another layout's
        b"feelmysign-wiring/0 0.0.1\nsource " + PAPER.encode() + b"\nlayout 3\nabc",
        b"\xff" * 100,
    ],
)
def test_an_unreadable_memo_is_a_miss_and_is_replaced(
    tmp_path: Path, state_home: Path, memo: bytes
) -> None:
    state = tmp_path / "bus.json"
    _left_on(state)
    arguments = ["--backend", "drv2605", "--layout", PAPER, "--emulate-state", str(state)]
    switch_off_early("sleeve", arguments)
    [path] = _memos(state_home)
    path.write_bytes(memo)
    _left_on(state)
    switch_off_early("sleeve", arguments)
    assert set(drive_levels(state).values()) == {0.0}
    assert path.read_bytes().startswith(b"feelmysign-wiring/1 ")


def test_a_memo_of_another_text_is_not_used(
    tmp_path: Path, state_home: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    layout_path, state, arguments = _editable_paper_layout(tmp_path)
    _left_on(state)
    switch_off_early("buzz", arguments)
    layout_path.write_text(PAPER_TEXT + "\n# an edit that changes nothing but the text\n")
    _refuse_to_parse(monkeypatch)
    problems = switch_off_early("buzz", arguments)
    assert problems and "AssertionError" in problems[0]  # it went to the full reader


def test_an_invalid_layout_leaves_no_memo_and_does_not_raise(
    tmp_path: Path, state_home: Path
) -> None:
    layout_path = tmp_path / "layout.toml"
    layout_path.write_text(PAPER_TEXT.replace("rows = 3", "rows = -3"))
    state = tmp_path / "bus.json"
    _left_on(state)
    assert (
        switch_off_early("buzz", ["--layout", str(layout_path), "--emulate-state", str(state)])
        == []
    )
    assert _memos(state_home) == []
    assert drive_levels(state)["0x71/2"] == 1.0  # left to the start-up, which says why


@pytest.mark.parametrize("memo_known", [False, True])
def test_a_missing_chip_or_multiplexer_does_not_keep_the_others_on(
    tmp_path: Path, memo_known: bool
) -> None:
    state = tmp_path / "bus.json"
    arguments = ["--backend", "drv2605", "--layout", PAPER, "--emulate-state", str(state)]
    if memo_known:
        _left_on(state)
        switch_off_early("sleeve", arguments)
    _left_on(state, (0, 0), (1, 3), (2, 2))
    saved = state_of(open_state_bus(state, None))
    del saved["chips"]["0x70/0"]  # a chip gone, and a multiplexer that no longer answers
    saved["multiplexers"]["0x70"]["connected"] = False
    state.write_text(json.dumps(saved))
    problems = switch_off_early("sleeve", arguments)
    levels = drive_levels(state)
    assert levels["0x71/2"] == 0.0  # reached through 0x71 although 0x70 is silent
    assert levels["0x70/7"] == 1.0  # behind the silent multiplexer: nothing reaches it
    assert any("multiplexer 0x70" in problem for problem in problems)


def test_the_raw_bus_writes_what_smbus_write_byte_data_would(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    reader, writer = os.pipe()
    opened: list[str] = []
    targets: list[int] = []

    def fake_open(path: str, flags: int) -> int:
        opened.append(path)
        return writer

    def fake_ioctl(fd: int, request: int, address: int) -> int:
        assert (fd, request) == (writer, 0x0703)  # I2C_SLAVE
        targets.append(address)
        return 0

    import fcntl

    monkeypatch.setattr(fcntl, "ioctl", fake_ioctl)
    monkeypatch.setattr(os, "open", fake_open)
    bus = all_off.RawI2CBus(1)
    assert all_off.switch_off(bus, {0x70: [0, 4]}) == []
    bus.close()
    written = os.read(reader, 100)
    os.close(reader)
    assert opened == ["/dev/i2c-1"]
    # RTP 0 on channel 0 then 4, standby on both, then the multiplexer deselected: a
    # one-byte write is the multiplexer's control register, a two-byte one a chip register.
    assert written == bytes.fromhex("01 0200 10 0200 01 0140 10 0140 00")
    assert targets == [0x70, 0x5A] * 4 + [0x70]  # I2C_SLAVE only when the address changes


def test_a_chip_that_does_not_answer_on_the_raw_bus_is_named_and_the_rest_go_on() -> None:
    class NoChipOnChannel2:
        def __init__(self) -> None:
            self.control = 0
            self.writes: list[tuple[int, int, int]] = []

        def write_byte(self, address: int, value: int, /) -> None:
            self.control = value

        def write_byte_data(self, address: int, register: int, value: int, /) -> None:
            if self.control == 1 << 2:
                raise OSError(errno.EREMOTEIO, "Remote I/O error")
            self.writes.append((self.control, register, value))

        def close(self) -> None:
            pass

    bus = NoChipOnChannel2()
    problems = all_off.switch_off(bus, {0x70: [1, 2, 3]})
    assert problems == ["DRV2605L on multiplexer 0x70 channel 2: no answer"]
    rtp, mode = all_off.REG_RTP_INPUT, all_off.REG_MODE
    assert bus.writes == [(2, rtp, 0), (8, rtp, 0), (2, mode, 0x40), (8, mode, 0x40)]
    assert bus.control == 0


@pytest.mark.parametrize("debug", ["", "1"])
def test_a_bug_in_the_early_pass_does_not_keep_the_start_up_from_its_own_all_off(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], debug: str
) -> None:
    import feelmysign.early_off as early

    def broken(layout_path: str, state_path: str | None, *, skip_held: bool) -> list[str]:
        raise RuntimeError("a bug")

    monkeypatch.setattr(early, "_switch_off", broken)
    monkeypatch.setenv("FEELMYSIGN_DEBUG", debug)
    problems = switch_off_early("sleeve", ["--backend", "drv2605", "--layout", PAPER])
    assert problems == ["early all-off failed: RuntimeError: a bug"]
    assert ("RuntimeError: a bug" in capsys.readouterr().err) == bool(debug)
