"""The all-off a starting ``sleeve`` or ``buzz`` does before parsing its command line."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import pytest

from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_state import drive_levels, open_state_bus
from feelmysign.cli._early_off import switch_off_early
from feelmysign.layout import load_layout

REPO = Path(__file__).resolve().parents[2]
PAPER = str(REPO / "deploy" / "layouts" / "paper-sleeve.toml")


def _left_on(path: Path) -> None:
    layout = load_layout(PAPER)
    backend = Drv2605Backend(layout, bus=open_state_bus(path, layout))
    backend.open()
    backend.set_intensity(2, 2, 1.0)  # and the process "dies": nothing closes it
    assert drive_levels(path)["0x71/2"] == 1.0


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
