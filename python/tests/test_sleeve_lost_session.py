"""A broker restarted without persistence forgets the sleeve's session, and the strokes it held
for the sleeve: the sleeve says so when it reconnects, rather than a plain "new session"."""

from __future__ import annotations

import os
import pwd
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

WAIT_S = 90.0
CONNECTED = "connected to mqtt://127.0.0.1:"
SAID = "no longer had the sleeve's session"


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _broker(conf: Path) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        ["mosquitto", "-c", str(conf)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )


def _wait_for(log: Path, text: str, count: int, sleeve: subprocess.Popen[bytes]) -> str:
    deadline = time.monotonic() + WAIT_S
    while log.read_text().count(text) < count:
        assert sleeve.poll() is None, log.read_text()
        assert time.monotonic() < deadline, f"{text!r} not {count} times:\n{log.read_text()}"
        time.sleep(0.1)
    return log.read_text()


def _run(tmp_path: Path, persistence: bool) -> str:
    """The sleeve's log across a restart of its broker (SIGKILL, then started again)."""
    port = _free_port()
    conf = tmp_path / "mosquitto.conf"
    # (Stays the user running the test: as root, Mosquitto would switch to 'mosquitto', which
    # cannot write its database here.)
    user = [f"user {pwd.getpwuid(os.getuid()).pw_name}"]
    lines = [*user, f"listener {port} 127.0.0.1", "allow_anonymous true"]
    lines += [f"persistence {'true' if persistence else 'false'}"]
    if persistence:
        lines += [
            f"persistence_location {tmp_path}/",
            "autosave_interval 1",
            "autosave_on_changes true",
        ]
    conf.write_text("\n".join(lines) + "\n")
    broker = _broker(conf)
    log = tmp_path / "sleeve.log"
    try:
        with log.open("w") as stderr:
            command = [sys.executable, "-m", "feelmysign", "sleeve", "--no-legacy"]
            command += ["--broker", f"mqtt://127.0.0.1:{port}"]
            sleeve = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=stderr)
        try:
            _wait_for(log, CONNECTED, 1, sleeve)
            time.sleep(1.5)  # the session saved (with persistence)
            if persistence:
                broker.terminate()  # saves its database as it exits
            else:
                broker.kill()
            broker.wait(timeout=WAIT_S)
            broker = _broker(conf)
            said = _wait_for(log, CONNECTED, 2, sleeve)
            sleeve.send_signal(signal.SIGTERM)
            sleeve.wait(timeout=WAIT_S)
        finally:
            sleeve.kill()
    finally:
        broker.terminate()
        broker.wait(timeout=WAIT_S)
    assert "Traceback" not in log.read_text()
    return said


def test_a_broker_that_forgot_the_sleeves_session_is_said(tmp_path: Path) -> None:
    said = _run(tmp_path, persistence=False)
    assert said.count("(new session)") == 2, said
    assert said.count(SAID) == 1, said
    assert "persistence true" in said, said


def test_a_resumed_session_says_nothing(tmp_path: Path) -> None:
    said = _run(tmp_path, persistence=True)
    assert "(resumed session)" in said, said
    assert SAID not in said, said
