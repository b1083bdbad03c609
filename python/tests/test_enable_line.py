"""The enable line on real sleeve processes: every DRV2605L's EN pin on one pulled-down GPIO.

A real ``feelmysign sleeve`` against a real Mosquitto, on the paper's layout with
``i2c.enable``; its chips and the line emulated in a state file. The emulated line
models the pull-down: it is high only while the process that drove it high lives, and
a chip whose EN is low drives nothing. A chip's wire comes loose by an edit of the file
(``"connected": false``), which the running sleeve takes at its next bus transaction.

- a chip lost while its motor is on, then ``kill -9``: every motor at 0 once the sleeve
  is gone, though the lost chip's registers still say "on";
- a chip lost while its motor is on, mid-drawing: every motor at 0 within 20 ms of the
  wire coming loose, by the times the file records (the sleeve reads the chips whose
  motors run every 5 ms), a ``safety`` event naming the chip, a ``silenced`` status;
  the line goes high again once the chip answers, and strokes play again;
- a restart with a chip missing: the line never goes high, every motor at 0, a clear
  error naming the chip.
"""

from __future__ import annotations

import signal
import subprocess
from pathlib import Path

from lost_chip import (
    a_motor_on,
    excerpt,
    paper_with_enable,
    register_drive,
    saved,
    set_connected,
    wait_until,
)
from sleeve_watch import SleeveWatch, exit_code_after, killed_with_its_guardian, online, reaped

from feelmysign.backends.emulated_state import drive_levels
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.layout import load_layout
from feelmysign.stroke import Stroke

WAIT_S = 60.0
MAX_OFF_MS = 20.0  # from the failed transaction to every motor off (issue: single-fault safe)


def sleeve_command(broker: Broker, state: Path, layout: Path) -> list[str]:
    command = restart_off.sleeve_command(broker.credentials_path, state)
    command[command.index("--layout") + 1] = str(layout)
    return command


def start(broker: Broker, state: Path, layout: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        sleeve_command(broker, state, layout),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_a_chip_lost_while_on_then_kill_9_leaves_every_motor_off(
    broker: Broker, tmp_path: Path
) -> None:
    state, layout = tmp_path / "bus.json", paper_with_enable(tmp_path)
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout)) as sleeve,
    ):
        watcher.next(online, "the sleeve online")
        assert saved(state)["enable"]["effective"] == 1  # high while it runs, checked
        watcher.send(restart_off.LONG_STROKE)
        key = a_motor_on(state)
        print("before the fault:", excerpt(state, key))
        set_connected(state, key, False)
        assert killed_with_its_guardian(sleeve) == -signal.SIGKILL
    print("after kill -9:", excerpt(state, key))
    # Nobody switched the lost chip off over I2C: its registers still say "on"...
    assert register_drive(state, key) > 0
    # ...and yet no motor runs: nobody drives the line any more, the pull-down holds it low.
    assert set(drive_levels(state).values()) == {0.0}


def test_kill_9_while_the_line_is_high_leaves_every_motor_off_with_no_process_left(
    broker: Broker, tmp_path: Path
) -> None:
    """The dead man's switch alone: the sleeve dies with the line high and a motor on; no
    process writes "low" or "off", and still nothing is driven once it is gone."""
    state, layout = tmp_path / "bus.json", paper_with_enable(tmp_path)
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout)) as sleeve,
    ):
        watcher.next(online, "the sleeve online")
        watcher.send(restart_off.LONG_STROKE)
        key = a_motor_on(state)
        assert killed_with_its_guardian(sleeve) == -signal.SIGKILL
    print("after kill -9 with the line high:", excerpt(state, key))
    line = saved(state)["enable"]
    assert (line["level"], line["holder"]["pid"]) == (1, sleeve.pid)  # left high by the dead
    assert register_drive(state, key) > 0  # and the chip still told to drive
    assert set(drive_levels(state).values()) == {0.0}


def test_a_chip_lost_while_on_mid_drawing_drops_the_line_at_once_and_says_which(
    broker: Broker, tmp_path: Path
) -> None:
    state, layout = tmp_path / "bus.json", paper_with_enable(tmp_path)
    wires = {(w.multiplexer, w.channel): w for w in load_layout(layout).wiring}
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout)) as sleeve,
    ):
        watcher.next(online, "the sleeve online")
        watcher.send(restart_off.LONG_STROKE)
        key = a_motor_on(state)
        rises = saved(state)["enable"]["rises"]
        print("before the fault:", excerpt(state, key))
        edited_ms = set_connected(state, key, False)
        lost = watcher.next(
            lambda n, b: b.get("type") == "safety" and b.get("reason") == "chip_lost",
            "a safety event for the lost chip",
        )
        multiplexer, _, channel = key.partition("/")
        wire = wires[(int(multiplexer, 16), int(channel))]
        assert (lost["row"], lost["column"]) == (wire.row, wire.column), lost
        assert f"multiplexer {multiplexer} channel {channel}" in lost["message"], lost
        assert "silent" in lost["message"], lost
        after = saved(state)
        print("after the fault:", excerpt(state, key))
        line, lost_at = after["enable"], after["chips"][key]["lost_at"]
        assert line["level"] == 0 and line["effective"] == 0, line
        # lost_at: when the wire came loose for the sleeve (it took the edit of the file);
        # the line fell after, within MAX_OFF_MS by the clock both were recorded on.
        assert line["changed_at"]["transaction"] >= lost_at["transaction"], (line, lost_at)
        off_ms = line["changed_at"]["ms"] - lost_at["ms"]
        print(
            f"every motor off {off_ms:.3f} ms after the chip came loose for the sleeve, "
            f"{line['changed_at']['ms'] - edited_ms:.3f} ms after the test's edit of the file"
        )
        assert 0 <= off_ms <= MAX_OFF_MS, (line, lost_at)
        assert set(drive_levels(state).values()) == {0.0}
        status = watcher.next(
            lambda n, b: n == "status" and b.get("hardware", {}).get("state") == "silenced",
            "a silenced status",
        )
        assert status["hardware"]["enable"] == "low", status
        assert [(c["row"], c["column"]) for c in status["hardware"]["lost"]] == [
            (wire.row, wire.column)
        ]
        # Silent: a stroke elsewhere is refused out loud, not played unfelt.
        watcher.send(Stroke((0.0, 0.0), (1.0, 0.0), 300.0, 0.9, "while-silent", 0))
        refused = watcher.next(
            lambda n, b: b.get("drawing") == "while-silent", "the stroke while silent"
        )
        assert (refused["type"], refused["reason"]) == ("rejected", "silenced"), refused
        assert saved(state)["enable"]["rises"] == rises  # never high while the chip is lost

        # The wire comes back: the chip is switched off, checked, and the line goes high.
        set_connected(state, key, True)
        watcher.next(
            lambda n, b: b.get("type") == "safety" and b.get("reason") == "chip_back",
            "a chip_back event",
        )
        wait_until(lambda: saved(state)["enable"]["effective"] == 1, "the line high again")
        print("wire back:", excerpt(state, key))
        assert register_drive(state, key) == 0.0
        watcher.send(Stroke((0.0, 0.0), (1.0, 0.0), 300.0, 0.9, "after", 0))
        watcher.next(
            lambda n, b: b.get("drawing") == "after" and b.get("type") == "played",
            "a stroke played once the chip is back",
        )
        rises = saved(state)["enable"]["rises"]
        assert exit_code_after(sleeve, signal.SIGTERM) == 0
    assert saved(state)["enable"]["effective"] == 0
    assert saved(state)["enable"]["rises"] == rises  # low first, and kept low, on the way out
    assert set(drive_levels(state).values()) == {0.0}
    events = watcher.received("events")
    assert not any(e.get("reason") == "player_crashed" for e in events), events


def test_a_restart_with_a_chip_missing_keeps_the_line_low_and_says_which(
    broker: Broker, tmp_path: Path
) -> None:
    state, layout = tmp_path / "bus.json", paper_with_enable(tmp_path)
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout)) as sleeve,
    ):
        watcher.next(online, "the sleeve online")
        watcher.send(restart_off.LONG_STROKE)
        key = a_motor_on(state)
        assert killed_with_its_guardian(sleeve) == -signal.SIGKILL
    set_connected(state, key, False)  # and its wire came loose meanwhile
    before = saved(state)["enable"]
    print("before the restart:", excerpt(state, key))
    assert register_drive(state, key) > 0 and set(drive_levels(state).values()) == {0.0}

    restarted = subprocess.run(
        sleeve_command(broker, state, layout), capture_output=True, text=True, timeout=WAIT_S
    )
    print("after the restart:", excerpt(state, key))
    assert restarted.returncode == 1, restarted.stderr
    assert restarted.stderr.startswith("Error: "), restarted.stderr
    assert "Traceback" not in restarted.stderr
    multiplexer, _, channel = key.partition("/")
    assert f"No DRV2605L answered on multiplexer {multiplexer} channel {channel}" in (
        restarted.stderr
    )
    assert "enable line (gpiochip0 line 17) stays low" in restarted.stderr, restarted.stderr
    line = saved(state)["enable"]
    assert line["rises"] == before["rises"], line  # it never went high
    assert line["effective"] == 0
    assert set(drive_levels(state).values()) == {0.0}
