"""Restart to all-off: how long motors a killed sleeve left on keep running once it restarts.

Each round starts ``feelmysign sleeve --backend drv2605 --emulate-state FILE``
against a real Mosquitto on loopback, sends a long stroke, ``kill -9``s the
sleeve while a motor is on, restarts it and polls the state file until every
chip is off. Measured from the restart (the new process being spawned) to the
first poll that finds every motor off; once with every chip present, once
with one chip missing (the sleeve then exits with an error, every other motor
off). Baseline: spawning the same Python that only exits (``python -c pass``),
the least any restart can take.

    python -m feelmysign.bench.restart_off [ROUNDS]
"""

from __future__ import annotations

import json
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.backends.emulated_state import drive_levels
from feelmysign.broker import Broker, Credentials
from feelmysign.connection import BrokerSettings, new_client
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

PAPER = Path(__file__).resolve().parents[3].parent / "deploy" / "layouts" / "paper-sleeve.toml"
ROUNDS = 5
POLL_S = 0.0005  # a poll reads a few kB of JSON: about a tenth of a millisecond
WAIT_S = 60.0
LONG_STROKE = Stroke((0.0, 1.0), (3.0, 1.0), 8000.0, 0.9, "bench-kill", 0)


def sleeve_command(credentials_path: Path, state: Path, *extra: str) -> list[str]:
    """``feelmysign sleeve`` on the paper's layout, its chips emulated with registers in
    ``state`` (they outlive the process, as real chips' do)."""
    return [
        sys.executable,
        "-m",
        "feelmysign",
        "sleeve",
        "--backend",
        "drv2605",
        "--emulate-state",
        str(state),
        "--layout",
        str(PAPER),
        "--credentials",
        str(credentials_path),
        "--no-legacy",
        *extra,
    ]


def _wait(condition: Any, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():
        if time.monotonic() > deadline:
            raise TimeoutError(what)
        time.sleep(POLL_S)


def _all_off(state: Path) -> bool:
    return not any(drive_levels(state).values())


class _Online:
    """Counts the sleeve's "online" status messages."""

    def __init__(self, c: Credentials) -> None:
        settings = BrokerSettings(
            c.mqtt_host, c.mqtt_port, username=c.sender.username, password=c.sender.password
        )
        self.count = 0
        self._lock = threading.Lock()
        self.client = new_client(settings, client_id="bench-restart-watch")
        self.client.on_message = self._on_message
        self.client.connect(c.mqtt_host, c.mqtt_port)
        self.client.subscribe(telemetry_topic(c.sleeve_id, "status"), qos=1)
        self.client.loop_start()
        self.sleeve_id = c.sleeve_id

    def _on_message(self, client: mqtt.Client, userdata: Any, message: mqtt.MQTTMessage) -> None:
        if json.loads(message.payload).get("online"):
            with self._lock:
                self.count += 1

    def close(self) -> None:
        self.client.loop_stop()
        self.client.disconnect()


def _kill_mid_stroke(command: list[str], state: Path, online: _Online) -> None:
    seen = online.count
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        _wait(lambda: online.count > seen, "the sleeve did not come online")
        online.client.publish(
            strokes_topic(online.sleeve_id), format_json(LONG_STROKE), qos=1
        ).wait_for_publish(WAIT_S)
        _wait(lambda: not _all_off(state), "no motor came on")
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait(WAIT_S)


def _restart_to_off_ms(command: list[str], state: Path) -> tuple[float, float]:
    """(restart -> first register write, restart -> every motor off), in ms."""
    before = state.stat().st_mtime_ns
    started = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        first_write_ms = None
        while not _all_off(state):
            if first_write_ms is None and state.stat().st_mtime_ns != before:
                first_write_ms = (time.perf_counter() - started) * 1000
            if time.perf_counter() - started > WAIT_S:
                raise TimeoutError("the restarted sleeve left a motor on")
            time.sleep(POLL_S)
        off_ms = (time.perf_counter() - started) * 1000
        return (off_ms if first_write_ms is None else first_write_ms), off_ms
    finally:
        process.send_signal(signal.SIGTERM)
        process.wait(WAIT_S)


def _remove_an_idle_chip(state: Path) -> None:
    saved = json.loads(state.read_text())
    idle = next(name for name, chip in sorted(saved["chips"].items()) if chip["drive"] == 0)
    del saved["chips"][idle]
    state.write_text(json.dumps(saved))


def _python_start_ms() -> float:
    started = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    return (time.perf_counter() - started) * 1000


def _figures(name: str, values: list[float], baseline: float) -> str:
    median = statistics.median(values)
    return (
        f"  {name:<50} min {min(values):6.1f}  median {median:6.1f}  max {max(values):6.1f} ms"
        f"  (n={len(values)})  median {median / baseline:4.1f}x baseline"
    )


def report(rounds: int = ROUNDS) -> list[str]:
    lines = ["Restart after kill -9 mid-stroke (emulated state file, real Mosquitto)"]
    baseline = statistics.median(_python_start_ms() for _ in range(rounds))
    lines.append(f"  {'baseline: spawn python -c pass':<50} median {baseline:6.1f} ms")
    with (
        tempfile.TemporaryDirectory() as directory,
        Broker(state_dir=Path(directory) / "broker", port=0, ws_port=0) as broker,
    ):
        online = _Online(broker.credentials)
        try:
            for missing in (False, True):
                times = []
                for index in range(rounds):
                    state = Path(directory) / f"bus-{missing}-{index}.json"
                    command = sleeve_command(
                        broker.credentials_path, state, "--log-level", "warning"
                    )
                    _kill_mid_stroke(command, state, online)
                    if missing:
                        _remove_an_idle_chip(state)
                    times.append(_restart_to_off_ms(command, state))
                suffix = ", one chip missing" if missing else ""
                lines.append(
                    _figures(
                        "restart -> first register write" + suffix, [t[0] for t in times], baseline
                    )
                )
                lines.append(
                    _figures("restart -> every motor off" + suffix, [t[1] for t in times], baseline)
                )
        finally:
            online.close()
    return lines


if __name__ == "__main__":
    for line in report(int(sys.argv[1]) if len(sys.argv) > 1 else ROUNDS):
        print(line, flush=True)
