"""A DRV2605L lost while its motor is on, on a sleeve without an enable line: it stays up.

A real sleeve process against a real Mosquitto, its chips emulated with registers in a
state file. The chip's wire comes loose (``"connected": false``) while its motor runs,
mid-stroke: no software can switch that motor off then, but the sleeve must not die of
it (which would leave nobody to switch it off when the wire comes back). It cuts the
stroke, says which chip in a ``safety`` event and in its status (``degraded``),
switches every other motor off, keeps trying the lost chip, and switches it off as
soon as it answers again; then strokes play on it again.
"""

from __future__ import annotations

import signal
import subprocess
from pathlib import Path

from lost_chip import a_motor_on, excerpt, register_drive, set_connected, wait_until
from sleeve_watch import WAIT_S, SleeveWatch, online, reaped

from feelmysign.backends.emulated_state import drive_levels
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.layout import load_layout
from feelmysign.stroke import Stroke


def test_a_chip_lost_while_its_motor_is_on_leaves_the_sleeve_up_and_is_switched_off_when_back(
    broker: Broker, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    wires = {(w.multiplexer, w.channel): w for w in load_layout(restart_off.PAPER).wiring}
    with SleeveWatch(broker.credentials, "status", "events") as watcher:
        command = restart_off.sleeve_command(broker.credentials_path, state)
        with reaped(
            subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        ) as sleeve:
            watcher.next(online, "the sleeve online")
            watcher.send(restart_off.LONG_STROKE)  # row 1, 8 s
            key = a_motor_on(state)
            set_connected(state, key, False)
            print("lost while on:", excerpt(state, key))
            lost = watcher.next(
                lambda n, b: b.get("type") == "safety" and b.get("reason") == "chip_lost",
                "a safety event for the lost chip",
            )
            multiplexer, _, channel = key.partition("/")
            wire = wires[(int(multiplexer, 16), int(channel))]
            assert (lost["row"], lost["column"]) == (wire.row, wire.column), lost
            assert f"multiplexer {multiplexer} channel {channel}" in lost["message"], lost
            # Every other motor off; the lost one may run on (nothing can reach it).
            wait_until(
                lambda: all(v == 0 for k, v in drive_levels(state).items() if k != key),
                "every reachable motor off",
            )
            status = watcher.next(
                lambda n, b: n == "status" and b.get("hardware", {}).get("state") == "degraded",
                "a degraded status naming the chip",
            )
            assert status["hardware"]["lost"] == [
                {
                    "row": wire.row,
                    "column": wire.column,
                    "multiplexer": multiplexer,
                    "channel": wire.channel,
                }
            ], status
            assert sleeve.poll() is None, "the sleeve died of a lost chip"
            print("after the loss:", excerpt(state, key))

            # The wire comes back: the motor is switched off by the retry, unasked.
            set_connected(state, key, True)
            back = watcher.next(
                lambda n, b: b.get("type") == "safety" and b.get("reason") == "chip_back",
                "a chip_back event",
            )
            assert (back["row"], back["column"]) == (wire.row, wire.column), back
            assert register_drive(state, key) == 0.0
            assert set(drive_levels(state).values()) == {0.0}
            print("wire back:", excerpt(state, key))
            watcher.next(
                lambda n, b: n == "status" and b.get("hardware", {}).get("state") == "ok",
                "the status ok again",
            )
            # And the next stroke plays, on that chip too.
            x, y = float(wire.column), float(wire.row)
            other = 0.0 if x > 0 else 1.0
            watcher.send(Stroke((x, y), (other, y), 400.0, 0.9, "after", 0))
            watcher.next(
                lambda n, b: b.get("drawing") == "after" and b.get("type") == "played",
                "the stroke on the chip that came back played",
            )
            sleeve.send_signal(signal.SIGTERM)
            _, errors = sleeve.communicate(timeout=WAIT_S)
            assert sleeve.returncode == 0, errors
    events = watcher.received("events")
    print("events:", [(e.get("type"), e.get("reason"), e.get("drawing")) for e in events])
    # The failed write is told (error "backend"); the player never stopped.
    assert not any(e.get("reason") == "player_crashed" for e in events), events
    assert "Traceback" not in errors, errors
    assert set(drive_levels(state).values()) == {0.0}
