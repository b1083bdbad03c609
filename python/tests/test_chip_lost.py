"""A DRV2605L that stops answering mid-drawing, on a real sleeve process: told, not called played.

The sleeve runs as its own process against a real Mosquitto, its chips emulated
with registers in a state file. The test unplugs one chip while a stroke moves
towards it (``"connected": false`` in the file, which the running sleeve takes
at its next bus transaction, as a loose wire would). The stroke it cuts gets a
``safety`` event naming the chip; every motor is switched off; a stroke that
would start on that chip is never reported ``played``.
"""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

from sleeve_watch import SleeveWatch, online

from feelmysign.backends.emulated_state import chip_key, drive_levels, read_state
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.layout import Wire, load_layout
from feelmysign.stroke import Stroke

WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly
ROW, LOST_COLUMN = 1, 2  # restart_off.LONG_STROKE runs along row 1 from column 0 to 3 in 8 s


def wait_until(condition: object, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():  # type: ignore[operator]
        assert time.monotonic() < deadline, what
        time.sleep(0.01)


def unplug(state: Path, key: str) -> None:
    """Mark the chip disconnected in the file, again if the sleeve's own write raced the edit."""
    deadline = time.monotonic() + WAIT_S
    while read_state(state).chips and _connected(state, key):
        assert time.monotonic() < deadline, f"the chip {key} never came loose"
        saved = json.loads(state.read_text())
        saved["chips"][key]["connected"] = False
        edited = state.with_name("edit.json")
        edited.write_text(json.dumps(saved))
        edited.replace(state)
        time.sleep(0.05)


def _lost_wire() -> tuple[Wire, str]:
    """The wire of the actuator the tests unplug (ROW, LOST_COLUMN), and its chip's key."""
    wire = next(
        w for w in load_layout(restart_off.PAPER).wiring if (w.row, w.column) == (ROW, LOST_COLUMN)
    )
    return wire, chip_key(wire.multiplexer, wire.channel)


def _connected(state: Path, key: str) -> bool:
    multiplexer, _, channel = key.partition("/")
    return read_state(state).chips[(int(multiplexer, 16), int(channel))].connected


def test_a_chip_lost_mid_stroke_cuts_the_stroke_says_which_chip_and_switches_all_off(
    broker: Broker, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    wire, key = _lost_wire()
    with SleeveWatch(broker.credentials, "status", "events") as watcher:
        sleeve = subprocess.Popen(
            restart_off.sleeve_command(broker.credentials_path, state),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            watcher.next(online, "the sleeve online")
            watcher.send(restart_off.LONG_STROKE)
            watcher.next(lambda n, b: b.get("type") == "played", "the long stroke played")
            # The stroke has started at column 0; its motor at column 2 is still to come.
            wait_until(lambda: drive_levels(state)[key] == 0.0, "the lost chip was never off")
            unplug(state, key)
            cut = watcher.next(
                lambda n, b: b.get("type") == "safety", "a safety event for the lost chip"
            )
            assert cut["reason"] == "chip_lost", cut
            assert (cut["row"], cut["column"]) == (ROW, LOST_COLUMN)
            assert (cut["drawing"], cut["seq"]) == ("bench-kill", 0)
            assert f"0x{wire.multiplexer:02X}" in cut["message"], cut
            assert f"channel {wire.channel}" in cut["message"], cut
            assert "part-way" in cut["message"], cut
            wait_until(lambda: set(drive_levels(state).values()) == {0.0}, "a motor stayed on")

            # A stroke that starts on the lost chip: cut before it is felt, never played.
            start = Stroke((float(LOST_COLUMN), float(ROW)), (0.0, float(ROW)), 600.0, 0.9, "d", 0)
            watcher.send(start)
            refused = watcher.next(
                lambda n, b: b.get("drawing") == "d" and b.get("type") != "adjusted",
                "an event for the stroke on the lost chip",
            )
            assert refused["type"] == "safety" and refused["reason"] == "chip_lost", refused
            assert "before it was felt" in refused["message"], refused
            # And the sleeve goes on: a stroke away from the lost chip plays.
            watcher.send(Stroke((0.0, 0.0), (1.0, 0.0), 300.0, 0.9, "after", 0))
            watcher.next(
                lambda n, b: b.get("drawing") == "after" and b.get("type") == "played",
                "the stroke on the good chips played",
            )
            sleeve.send_signal(signal.SIGTERM)
            _, errors = sleeve.communicate(timeout=WAIT_S)
            # It stops with an error naming the chip it could not switch off (systemd then
            # restarts it, and the restart refuses to play without that chip).
            assert sleeve.returncode == 1, errors
            assert "Traceback" not in errors, errors
            assert "Error: Could not switch off every actuator" in errors, errors
            assert f"channel {wire.channel} (actuator row {ROW}, column {LOST_COLUMN})" in errors
            # Its journal counts by the fates: the stroke the chip cut part-way is cut short,
            # not played; the one it cut before it was felt is rejected.
            assert "Drawing bench-ki: 0 strokes played, 1 cut short" in errors, errors
            assert "Drawing d: 0 strokes played, 1 rejected (chip_lost)" in errors, errors
        finally:
            sleeve.kill()
            sleeve.wait(WAIT_S)
    events = watcher.received("events")
    assert not any(
        e.get("drawing") == "d" and e.get("type") in ("played", "adjusted") for e in events
    ), events
    assert set(drive_levels(state).values()) == {0.0}


def test_send_says_a_stroke_a_lost_chip_cut_part_way_once(broker: Broker, tmp_path: Path) -> None:
    """``send --wait``'s line for the stroke: 'cut part-way' once, then the sleeve's reason."""
    state = tmp_path / "bus.json"
    wire, key = _lost_wire()
    with SleeveWatch(broker.credentials, "status", "events") as watcher:
        sleeve = subprocess.Popen(
            restart_off.sleeve_command(broker.credentials_path, state),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            watcher.next(online, "the sleeve online")
            send = subprocess.Popen(
                [
                    *restart_off.feelmysign_command(),
                    "send",
                    "--credentials",
                    str(broker.credentials_path),
                    "--wait",
                    "0,1,3,1,8000",
                ],
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            watcher.next(lambda n, b: b.get("type") == "played", "the stroke played")
            wait_until(lambda: drive_levels(state)[key] == 0.0, "the lost chip was never off")
            unplug(state, key)
            out, err = send.communicate(timeout=WAIT_S)
        finally:
            sleeve.kill()
            sleeve.wait(WAIT_S)
    line = next((li for li in out.splitlines() if li.startswith("[1/1] cut")), None)
    assert line is not None, out + err
    assert line.startswith("[1/1] cut part-way (chip_lost): The DRV2605L"), line
    assert line.count("part-way") == 1, line
    assert f"channel {wire.channel}" in line, line
