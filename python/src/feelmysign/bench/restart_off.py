"""Restart to all-off: how long motors a killed sleeve left on keep running once it restarts.

Each round starts ``feelmysign sleeve --backend drv2605 --emulate-state FILE``
against a real Mosquitto on loopback, sends a long stroke, ``kill -9``s the
sleeve while a motor is on, restarts it and polls the state file until every
chip is off. Measured from the restart (the new process being spawned) to the
first poll that finds every motor off; once with every chip present, once
with one chip missing (the sleeve then exits with an error, every other motor
off). The sleeve is started as the systemd unit starts it: the ``feelmysign``
console script beside this Python (deploy/feelmysign-sleeve.service runs
``/opt/feelmysign/bin/feelmysign sleeve``), not ``python -m feelmysign``.

Baseline: spawning the same Python that only exits (``python -c pass``), the
least any restart can take, measured just before and after each restart so
that both see the same load. Budget: every motor off within BUDGET_MS and within
BUDGET_RATIO times the baseline, with every chip and with one missing.

The package's bytecode is compiled first, as ``pip install`` does: with
PYTHONDONTWRITEBYTECODE set (as on some machines) every restart would otherwise
compile our modules from source, which no installed sleeve does.

The emulated bus is a JSON file, so the restarted sleeve imports the json
module to reach it; on a real bus it does not (feelmysign.backends.all_off).
The file is kept in memory (/dev/shm, where there is one): every emulated
register write replaces it, and a rename on a busy disk takes a few
milliseconds, ten times what the I2C write it stands for takes.

    python -m feelmysign.bench.restart_off [ROUNDS]
"""

from __future__ import annotations

import compileall
import json
import os
import shutil
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

import feelmysign
from feelmysign.backends.actuator_config import store_name_for_state_file
from feelmysign.backends.emulated_state import drive_levels
from feelmysign.bench import _mqtt
from feelmysign.broker import Broker, Credentials
from feelmysign.connection import new_client
from feelmysign.guard import guardian_pids
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

PAPER = Path(__file__).resolve().parents[3].parent / "deploy" / "layouts" / "paper-sleeve.toml"
ROUNDS = 5
POLL_S = 0.0005  # a poll reads a few kB of JSON: about a tenth of a millisecond
WAIT_S = 60.0
_MEMORY = "/dev/shm"  # a RAM disk on Linux: where the emulated chips' registers are kept
BUDGET_MS = 100.0  # restart -> every motor off, median
BUDGET_RATIO = 5.0  # ... and at most this many bare Python spawns
LONG_STROKE = Stroke((0.0, 1.0), (3.0, 1.0), 8000.0, 0.9, "bench-kill", 0)


def sleeve_command(credentials_path: Path, state: Path, *extra: str) -> list[str]:
    """``feelmysign sleeve`` on the paper's layout, its chips emulated with registers in
    ``state`` (they outlive the process, as real chips' do)."""
    return [
        *feelmysign_command(),
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


def feelmysign_command() -> list[str]:
    """The ``feelmysign`` console script of this Python's environment, as the systemd unit
    runs it; ``python -m feelmysign`` where it is not installed as a script."""
    script = Path(sys.executable).with_name("feelmysign")
    if script.is_file() and os.access(script, os.X_OK):
        return [str(script)]
    return [sys.executable, "-m", "feelmysign"]


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
        settings = c.settings("sender")
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
        _mqtt.close(self.client)


def _kill_mid_stroke(command: list[str], state: Path, online: _Online, env: dict[str, str]) -> None:
    seen = online.count
    process = subprocess.Popen(
        command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env
    )
    try:
        _wait(lambda: online.count > seen, "the sleeve did not come online")
        online.client.publish(
            strokes_topic(online.sleeve_id), format_json(LONG_STROKE), qos=1
        ).wait_for_publish(WAIT_S)
        _wait(lambda: not _all_off(state), "no motor came on")
    finally:
        # The guardian first (feelmysign.guard): it would switch every motor off itself, and
        # what is measured here is the restart's own all-off, the last line when both died.
        for guardian in guardian_pids(process.pid):
            os.kill(guardian, signal.SIGKILL)
        process.send_signal(signal.SIGKILL)
        process.wait(WAIT_S)


def _identity(state: Path) -> tuple[int, int, int]:
    info = state.stat()
    return info.st_ino, info.st_mtime_ns, info.st_size


def _restart_to_off_ms(command: list[str], state: Path, env: dict[str, str]) -> tuple[float, float]:
    """(restart -> first register write, restart -> every motor off), in ms."""
    before = _identity(state)
    started = time.perf_counter()
    process = subprocess.Popen(
        command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env
    )
    try:
        first_write_ms = None
        seen = before
        while True:
            # A stat per poll; the file is read only once it changed (each write replaces it),
            # so that polling takes as little as possible from the process being timed.
            now = _identity(state)
            if now != seen:
                seen = now
                if first_write_ms is None:
                    first_write_ms = (time.perf_counter() - started) * 1000
                if _all_off(state):
                    break
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


def _calibration_file(state_home: Path, state: Path) -> Path:
    """Where a sleeve run with ``XDG_STATE_HOME=state_home`` keeps the calibration results of
    the emulated bus in ``state`` (``actuator_config.calibration_path``)."""
    return state_home / "feelmysign" / "calibration" / f"{store_name_for_state_file(state)}.json"


def _python_start_ms() -> float:
    started = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    return (time.perf_counter() - started) * 1000


def _figures(name: str, values: list[float], baseline_ms: float) -> str:
    median = statistics.median(values)
    return (
        f"  {name:<50} min {min(values):6.1f}  median {median:6.1f}  max {max(values):6.1f} ms"
        f"  (n={len(values)})  median {median / baseline_ms:4.1f}x baseline"
    )


def _budget(name: str, off_ms: list[float], baseline_ms: float) -> str:
    median = statistics.median(off_ms)
    ratio = median / baseline_ms
    within_ms = "met" if median <= BUDGET_MS else "NOT MET"
    within_ratio = "met" if ratio <= BUDGET_RATIO else "NOT MET"
    return (
        f"  budget{name}: median {median:.1f} ms <= {BUDGET_MS:g} ms: {within_ms}; "
        f"{ratio:.1f}x <= {BUDGET_RATIO:g}x a bare spawn: {within_ratio}"
    )


def report(rounds: int = ROUNDS) -> list[str]:
    command_name = " ".join(Path(part).name for part in feelmysign_command())
    lines = [
        "Restart after kill -9 mid-stroke (emulated state file, real Mosquitto; "
        f"started as: {command_name} sleeve ...)"
    ]
    compileall.compile_dir(Path(feelmysign.__file__).parent, quiet=1)  # as pip install does
    results: dict[bool, tuple[list[float], list[tuple[float, float]]]] = {}
    with (
        tempfile.TemporaryDirectory() as directory,
        tempfile.TemporaryDirectory(dir=_MEMORY if os.path.isdir(_MEMORY) else None) as chips,
        Broker(state_dir=Path(directory) / "broker", port=0, ws_port=0) as broker,
    ):
        # Where the sleeve keeps what it needs to switch off at its next start (the wiring
        # memo): this run's own, so that the bench leaves nothing behind.
        state_home = Path(directory) / "state"
        env = {**os.environ, "XDG_STATE_HOME": str(state_home)}
        online = _Online(broker.credentials)
        calibrated: Path | None = None  # the first round's calibration results
        try:
            for missing in (False, True):
                baselines: list[float] = []
                times: list[tuple[float, float]] = []
                for index in range(rounds):
                    state = Path(chips) / f"bus-{missing}-{index}.json"
                    command = sleeve_command(
                        broker.credentials_path, state, "--log-level", "warning"
                    )
                    # Each round's bus is new, and a sleeve calibrates every chip of a bus it
                    # has no results for (a second of emulated calibration, before the stroke
                    # the kill cuts). The first round's results, kept as a sleeve keeps them,
                    # spare the later rounds that: the restart timed is the same either way,
                    # as it always finds the results its first start kept.
                    if calibrated is not None:
                        shutil.copyfile(calibrated, _calibration_file(state_home, state))
                    _kill_mid_stroke(command, state, online, env)
                    if calibrated is None:
                        calibrated = _calibration_file(state_home, state)
                    if missing:
                        _remove_an_idle_chip(state)
                    # A bare spawn on each side of the restart: they see the same load.
                    baselines.append(_python_start_ms())
                    times.append(_restart_to_off_ms(command, state, env))
                    baselines.append(_python_start_ms())
                results[missing] = baselines, times
        finally:
            online.close()
    for missing, (baselines, times) in results.items():
        suffix = ", one chip missing" if missing else ""
        baseline_ms = statistics.median(baselines)
        lines.append(
            f"  {'baseline: spawn python -c pass' + suffix:<50} min {min(baselines):6.1f}  "
            f"median {baseline_ms:6.1f} ms  (n={len(baselines)}, before and after each restart)"
        )
        lines.append(
            _figures("restart -> first register write" + suffix, [t[0] for t in times], baseline_ms)
        )
        off_ms = [t[1] for t in times]
        lines.append(_figures("restart -> every motor off" + suffix, off_ms, baseline_ms))
        lines.append(_budget(suffix and f" ({suffix[2:]})", off_ms, baseline_ms))
    return lines


if __name__ == "__main__":
    for line in report(int(sys.argv[1]) if len(sys.argv) > 1 else ROUNDS):
        print(line, flush=True)
