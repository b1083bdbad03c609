"""One feelmysign per state directory: a second ``up`` or ``broker`` there refuses at once.

Real processes throughout (``feelmysign up`` with its Mosquitto and simulated sleeve,
``feelmysign broker``, ``feelmysign send``): the second one must say who runs, leave every
file the first one's clients read byte for byte as it was, and the first must go on
working. A first one killed with SIGKILL leaves no lock behind (the kernel drops it), and
a start that fails (a port taken by some other program) leaves the previous state as it was.
"""

from __future__ import annotations

import os
import queue
import signal
import socket
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from conftest import StartBroker
from test_cli_up import FEELMYSIGN, WAIT_S, _lines, _wait_for

from feelmysign.broker import Broker, BrokerError
from feelmysign.broker.instance import INFO_NAME, LIBRARY_COMMAND, InstanceLock

pytestmark = pytest.mark.broker
FREE_PORTS = ["--port", "0", "--ws-port", "0"]
# What the clients of a running instance read, and what its Mosquitto runs from.
STATE_FILES = ("credentials.json", "sleeve-credentials.json", "mosquitto.conf", "acl", "passwd")
REFUSED = "Error: feelmysign is already running with the state directory "


def _env(tmp_path: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    env["XDG_STATE_HOME"] = str(tmp_path / "xdg")
    return env


def _web(tmp_path: Path) -> Path:
    web = tmp_path / "web"
    web.mkdir(exist_ok=True)
    (web / "index.html").write_text("<!doctype html><title>feelmysign</title>\n")
    return web


def _files(state: Path) -> dict[str, bytes | None]:
    return {
        name: (state / name).read_bytes() if (state / name).exists() else None
        for name in (*STATE_FILES, "runtime.json", INFO_NAME)
    }


class Running:
    """A feelmysign process that has said it is ready, and what it printed so far."""

    def __init__(self, process: subprocess.Popen[str], lines: queue.Queue[str]) -> None:
        self.process = process
        self.lines = lines
        self.seen: list[str] = []

    def line(self, start: str) -> str:
        return _wait_for(self.lines, start, self.seen)


@contextmanager
def _running(argv: list[str], env: dict[str, str]) -> Iterator[Running]:
    process = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env
    )
    running = Running(process, _lines(process.stdout))
    try:
        yield running
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
            try:
                process.wait(timeout=WAIT_S)
            finally:
                if process.poll() is None:
                    process.kill()
                    process.wait()


def _up(state: Path, tmp_path: Path, *more: str) -> list[str]:
    return [
        FEELMYSIGN,
        "up",
        "--state-dir",
        str(state),
        "--web-dir",
        str(_web(tmp_path)),
        *more,
    ]


def _run(argv: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        argv, capture_output=True, text=True, timeout=WAIT_S, env=env, check=False
    )


def _send_line(state: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    credentials = str(state / "credentials.json")
    return _run([FEELMYSIGN, "send", "--credentials", credentials, "--shape", "line"], env)


def test_a_second_up_or_broker_on_the_same_state_directory_refuses_and_changes_nothing(
    tmp_path: Path,
) -> None:
    env, state = _env(tmp_path), tmp_path / "state"
    with _running([*_up(state, tmp_path), *FREE_PORTS, "--http-port", "0"], env) as first:
        page = first.line("  Draw here:").split(":", 1)[1].strip()
        broker_line = first.line("  Broker:").split(":", 1)[1].strip()
        first.line("Press Ctrl-C to stop.")
        before = _files(state)
        assert all(before[name] is not None for name in STATE_FILES), sorted(before)

        # Free ports everywhere: only the state directory is shared, and that alone refuses.
        second = _run([*_up(state, tmp_path), *FREE_PORTS, "--http-port", "0"], env)
        assert second.returncode == 1, second.stdout + second.stderr
        assert second.stderr.startswith(f"{REFUSED}{state} (feelmysign up, pid {first.process.pid}")
        assert f"Its page:    {page}" in second.stderr, second.stderr
        assert f"Its broker:  {broker_line}" in second.stderr, second.stderr
        assert f"'kill {first.process.pid}'" in second.stderr
        assert "--state-dir OTHER_DIR" in second.stderr and "Traceback" not in second.stderr
        assert second.stdout == ""  # not even "Port ... is taken": it stopped before that

        broker = _run([FEELMYSIGN, "broker", "--state-dir", str(state), *FREE_PORTS], env)
        assert broker.returncode == 1, broker.stdout + broker.stderr
        assert broker.stderr.startswith(f"{REFUSED}{state} (feelmysign up, pid ")
        assert "feelmysign broker --state-dir OTHER_DIR" in broker.stderr

        assert _files(state) == before
        sent = _send_line(state, env)
        assert sent.returncode == 0, sent.stdout + sent.stderr
        assert "The sleeve played 1 of 1 strokes" in sent.stdout
    assert first.process.returncode == 0, first.seen
    assert not (state / INFO_NAME).exists()  # a clean stop takes its description away


def test_an_up_killed_with_sigkill_does_not_block_the_next_one(tmp_path: Path) -> None:
    env, state = _env(tmp_path), tmp_path / "state"
    argv = [*_up(state, tmp_path), *FREE_PORTS, "--http-port", "0"]
    with _running(argv, env) as first:
        first.line("Press Ctrl-C to stop.")
        first.process.kill()
        first.process.wait(timeout=WAIT_S)
    assert (state / INFO_NAME).exists()  # left behind by the killed one: only words
    with _running(argv, env) as again:
        again.line("Press Ctrl-C to stop.")
        sent = _send_line(state, env)
        assert sent.returncode == 0, sent.stdout + sent.stderr
        assert "The sleeve played 1 of 1 strokes" in sent.stdout
    assert again.process.returncode == 0, again.seen


def test_up_beside_a_running_broker_on_its_state_directory_refuses(tmp_path: Path) -> None:
    env, state = _env(tmp_path), tmp_path / "state"
    argv = [FEELMYSIGN, "broker", "--state-dir", str(state), *FREE_PORTS]
    with _running(argv, env) as broker:
        mqtt = broker.line("  MQTT:").split(":", 1)[1].strip()
        broker.line("Ready.")
        before = _files(state)
        up = _run([*_up(state, tmp_path), *FREE_PORTS, "--http-port", "0"], env)
        assert up.returncode == 1, up.stdout + up.stderr
        assert up.stderr.startswith(f"{REFUSED}{state} (feelmysign broker, pid ")
        assert f"Its broker:  {mqtt} and ws://" in up.stderr
        assert "feelmysign up --state-dir OTHER_DIR" in up.stderr
        assert _files(state) == before
    assert broker.process.returncode == 0, broker.seen


def test_a_start_that_fails_on_a_taken_port_leaves_the_state_as_it_was(
    tmp_path: Path, start_broker: StartBroker
) -> None:
    env, state = _env(tmp_path), tmp_path / "state"
    start_broker(state_dir=state).stop()  # a previous run's state: its files, no instance
    before = _files(state)
    with socket.socket() as other:  # some other program, not feelmysign, holds a port
        other.bind(("127.0.0.1", 0))
        other.listen()
        taken = str(other.getsockname()[1])
        page = _run([*_up(state, tmp_path), *FREE_PORTS, "--http-port", taken], env)
        assert page.returncode == 1, page.stdout + page.stderr
        assert page.stderr.startswith(
            f"Error: cannot serve the drawing client on 127.0.0.1:{taken}"
        )
        assert _files(state) == before
        mqtt = _run(
            [*_up(state, tmp_path), "--port", taken, "--ws-port", "0", "--http-port", "0"], env
        )
        assert mqtt.returncode == 1, mqtt.stdout + mqtt.stderr
        assert mqtt.stderr.startswith(f"Error: The MQTT port {taken} is already in use")
        assert _files(state) == before
        broker = _run(
            [FEELMYSIGN, "broker", "--state-dir", str(state), "--port", taken, "--ws-port", "0"],
            env,
        )
        assert broker.returncode == 1 and "MQTT port" in broker.stderr, broker.stderr
        assert _files(state) == before


def test_a_broker_that_never_gets_ready_puts_back_the_files_it_rewrote(
    tmp_path: Path, start_broker: StartBroker
) -> None:
    state = tmp_path / "state"
    start_broker(state_dir=state).stop()
    before = _files(state)
    hurried = Broker(state_dir=state, port=0, ws_port=0, ready_timeout_s=1e-9)
    with pytest.raises(BrokerError) as refused:
        hurried.start()
    assert refused.value.reason == "start-failed"
    assert not hurried.running and _files(state) == before
    with InstanceLock(state, "test") as lock:  # and the lock was let go
        assert lock.held


def test_two_brokers_in_one_state_directory_take_turns(tmp_path: Path) -> None:
    state = tmp_path / "state"
    first, second = (Broker(state_dir=state, port=0, ws_port=0) for _ in range(2))
    with first:
        before = _files(state)
        with pytest.raises(BrokerError) as refused:
            second.start()
        assert refused.value.reason == "already-running"
        assert f"({LIBRARY_COMMAND}, pid {os.getpid()}" in refused.value.message
        assert f"Its broker:  {first.credentials.mqtt_url}" in refused.value.message
        assert _files(state) == before and not second.running
    with second:  # the first's stop let the lock go
        assert second.credentials.mqtt_url != ""
