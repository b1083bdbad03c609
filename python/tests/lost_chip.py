"""Helpers for the tests that unplug a DRV2605L from a running sleeve's emulated bus.

The sleeve keeps its chips' registers in a state file (``--emulate-state``) and takes a
fault set in that file at its next bus transaction, as a loose wire would show.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from feelmysign.backends.emulated_state import drive_levels, read_state
from feelmysign.bench import restart_off

WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly
ENABLE = '[i2c]\nenable = { chip = "gpiochip0", line = 17 }\n'


def wait_until(condition: Callable[[], bool], what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < deadline, f"never: {what}"
        time.sleep(0.005)


def a_motor_on(state: Path) -> str:
    """The chip (its state file key) of the first motor seen on."""
    while True:
        on = [key for key, level in drive_levels(state).items() if level > 0]
        if on:
            return on[0]
        wait_until(lambda: any(level > 0 for level in drive_levels(state).values()), "a motor on")


def paper_with_enable(folder: Path) -> Path:
    """The paper's layout with every chip's EN pin on gpiochip0 line 17."""
    text = restart_off.PAPER.read_text()
    assert "[i2c]\n" in text
    path = folder / "paper-enable.toml"
    path.write_text(text.replace("[i2c]\n", ENABLE, 1))
    return path


def saved(state: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(state.read_text())
    return data


def set_connected(state: Path, key: str, connected: bool) -> float:
    """Set the chip's wire in the file, again if the sleeve's own write raced the edit; the
    wall clock (ms) of the last edit."""
    deadline = time.monotonic() + WAIT_S
    edited_ms = 0.0
    while _connected(state, key) != connected:
        assert time.monotonic() < deadline, f"the chip {key} never became connected={connected}"
        data = saved(state)
        data["chips"][key]["connected"] = connected
        edited = state.with_name("edit.json")
        edited.write_text(json.dumps(data))
        edited_ms = time.time() * 1000
        edited.replace(state)
        time.sleep(0.02)
    return edited_ms


def _connected(state: Path, key: str) -> bool:
    multiplexer, _, channel = key.partition("/")
    return read_state(state).chips[(int(multiplexer, 16), int(channel))].connected


def register_drive(state: Path, key: str) -> float:
    """What the chip's registers alone would drive its motor with, whatever its EN pin says."""
    multiplexer, _, channel = key.partition("/")
    chip = read_state(state).chips[(int(multiplexer, 16), int(channel))]
    chip.enabled = True
    return chip.output


def excerpt(state: Path, *keys: str) -> str:
    """A few lines of the state file, for the report of what a fault left: the fields as the
    last process wrote them, and ``drive_now`` (every motor's drive as it is now: the line
    falls when its holder dies, and no process is left to write that)."""
    data = saved(state)
    chips = {
        key: {k: data["chips"][key][k] for k in ("connected", "drive", "lost_at")} for key in keys
    }
    now = {key: level for key, level in drive_levels(state).items() if level}
    line = data.get("enable")
    if line is not None:
        line = {k: line[k] for k in ("level", "holder", "effective", "changed_at", "rises")}
    return json.dumps({"enable": line, "chips": chips, "drive_now": now})
