"""The wearer's pause button: from the press to every motor off, mid-drawing.

Each round starts nothing new: one ``feelmysign sleeve --backend drv2605
--emulate-state FILE`` with a pause button (``[controls]``) against a real
Mosquitto on loopback plays a long diagonal stroke (four motors on at once, the
most a point of the grid drives), and the bench presses the emulated button
through the pipe next to the state file while a motor is on, then presses again
to resume. The emulation records when the sleeve saw the press and when every
motor was next found off (``buttons[].pressed_at``, ``silent_since``: one
clock, the sleeve's), and the bus transactions in between.

Baseline: the time the emulated bus itself takes for those transactions (each
register write replaces the state file; one replace is timed here, on the same
disk, before and after each round), so the ratio says what the sleeve adds to
the bus's own cost. On real I2C each of those writes takes about 0.2 ms at 100 kHz.
Budget: every motor off within BUDGET_MS of the press (the issue's 20 ms).

    python -m feelmysign.bench.wearer_pause [ROUNDS]
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from feelmysign.backends.emulated_button import press_in, release_in
from feelmysign.backends.emulated_state import drive_levels, read_state, write_state
from feelmysign.bench import _mqtt
from feelmysign.bench.restart_off import PAPER, sleeve_command
from feelmysign.broker import Broker
from feelmysign.connection import new_client
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

ROUNDS = 10
BUDGET_MS = 20.0
CHIP, LINE = "gpiochip0", 27
WAIT_S = 60.0
POLL_S = 0.002
HOLD_S = 0.1  # a finger's short press
_MEMORY = "/dev/shm"  # as restart_off: the emulated registers on a RAM disk where there is one


def _wait(condition: Any, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():
        if time.monotonic() > deadline:
            raise TimeoutError(what)
        time.sleep(POLL_S)


def _saved(state: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(state.read_text())
    return data


def _button(state: Path) -> dict[str, Any]:
    found: dict[str, Any] = next(b for b in _saved(state)["buttons"] if b["line"] == LINE)
    return found


def _tap(state: Path, controls: Path, paused: bool) -> dict[str, Any]:
    """A short press; returns the button's record once the sleeve is ``paused`` (or not): it
    keeps the pause on disk (fsync) before it takes the next press, however slow the disk."""
    presses = _button(state)["presses"]
    press_in(state, CHIP, LINE)
    _wait(lambda: _button(state)["presses"] == presses + 1, "the press was not taken")
    time.sleep(HOLD_S)
    release_in(state, CHIP, LINE)
    _wait(lambda: not _button(state)["pressed"], "the let-go was not taken")
    _wait(lambda: _paused(controls) == paused, "the sleeve did not take the press")
    return _button(state)


def _paused(controls: Path) -> bool | None:
    try:
        return bool(json.loads(controls.read_text())["paused"])
    except (OSError, ValueError, KeyError):
        return None


def _write_ms(state: Path) -> float:
    """One replace of the state file, as each emulated register write makes."""
    bus = read_state(state)
    copy = state.with_name("baseline.json")
    started = time.perf_counter()
    write_state(bus, copy)
    return (time.perf_counter() - started) * 1000


def _round(
    state: Path, controls: Path, client: Any, sleeve_id: str, index: int
) -> tuple[float, int]:
    """(press -> every motor off in ms, bus transactions between)."""
    stroke = Stroke((0.0, 0.0), (3.0, 2.0), 3000.0, 0.9, f"bench-pause-{index}", 0)
    client.publish(strokes_topic(sleeve_id), format_json(stroke), qos=1).wait_for_publish(WAIT_S)
    _wait(lambda: sum(level > 0 for level in drive_levels(state).values()) >= 2, "no motor on")
    button = _tap(state, controls, True)
    _wait(lambda: _saved(state)["silent_since"] is not None, "a motor stayed on")
    silent = _saved(state)["silent_since"]
    pressed = button["pressed_at"]
    _tap(state, controls, False)
    return silent["ms"] - pressed["ms"], silent["transaction"] - pressed["transaction"]


def report(rounds: int = ROUNDS) -> list[str]:
    lines = ["The wearer's pause button mid-stroke (emulated bus and button, real Mosquitto)"]
    with (
        tempfile.TemporaryDirectory() as directory,
        tempfile.TemporaryDirectory(dir=_MEMORY if os.path.isdir(_MEMORY) else None) as chips,
        Broker(state_dir=Path(directory) / "broker", port=0, ws_port=0) as broker,
    ):
        layout = Path(directory) / "paper-button.toml"
        layout.write_text(
            PAPER.read_text()
            + f'\n[controls]\npause_button = {{ chip = "{CHIP}", line = {LINE} }}\n'
        )
        state = Path(chips) / "bus.json"
        command = sleeve_command(broker.credentials_path, state, "--log-level", "warning")
        command[command.index("--layout") + 1] = str(layout)
        env = {**os.environ, "XDG_STATE_HOME": str(Path(directory) / "state")}
        sleeve_id = broker.credentials.sleeve_id
        controls = Path(directory) / "state" / "feelmysign" / "controls" / f"{sleeve_id}.json"
        log_path = Path(directory) / "sleeve.log"
        with log_path.open("w") as log:  # its log, shown if a round fails
            sleeve = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=log, env=env)
        credentials = broker.credentials
        client = new_client(credentials.settings("sender"), client_id="bench-wearer-pause")
        online = threading.Event()
        client.on_message = lambda _c, _u, message: (
            online.set() if json.loads(message.payload).get("online") else None
        )
        client.connect(credentials.mqtt_host, credentials.mqtt_port)
        client.subscribe(telemetry_topic(credentials.sleeve_id, "status"), qos=1)
        client.loop_start()
        try:
            _wait(online.is_set, "the sleeve never came online")
            off_ms: list[float] = []
            transactions: list[int] = []
            baseline_ms: list[float] = []
            for index in range(rounds):
                baseline_ms.append(_write_ms(state))
                try:
                    figure, count = _round(state, controls, client, credentials.sleeve_id, index)
                except TimeoutError:
                    print(
                        log_path.read_text()[-3000:], _saved(state).get("buttons"), file=sys.stderr
                    )
                    raise
                off_ms.append(figure)
                transactions.append(count)
                baseline_ms.append(_write_ms(state))
        finally:
            _mqtt.close(client)
            sleeve.terminate()
            sleeve.wait(WAIT_S)
    write_ms = statistics.median(baseline_ms)
    median = statistics.median(off_ms)
    bus_ms = statistics.median(transactions) * write_ms
    lines += [
        f"  baseline: one emulated register write (state file replaced)  median {write_ms:6.2f} ms"
        f"  (n={len(baseline_ms)}, before and after each round)",
        f"  transactions from the press to every motor off               median "
        f"{statistics.median(transactions):6.1f}  max {max(transactions)}",
        f"  press -> every motor off     min {min(off_ms):6.1f}  median {median:6.1f}  "
        f"max {max(off_ms):6.1f} ms  (n={len(off_ms)})  median {median / bus_ms:4.1f}x the "
        "bus's own time for those writes",
        f"  budget: max {max(off_ms):.1f} ms <= {BUDGET_MS:g} ms: "
        f"{'met' if max(off_ms) <= BUDGET_MS else 'NOT MET'}",
    ]
    return lines


if __name__ == "__main__":
    for line in report(int(sys.argv[1]) if len(sys.argv) > 1 else ROUNDS):
        print(line, flush=True)
