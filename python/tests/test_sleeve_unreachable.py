"""A sleeve started before its broker says once that it cannot reach it, not at every retry,
and connects by itself when the broker comes."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from conftest import StartBroker

from feelmysign.bench.sleeve import sleeve_command
from feelmysign.connection import RECONNECT_MAX_S
from feelmysign.daemon import UNREACHABLE_REMINDER_S

WAIT_S = 60.0
UNREACHABLE = "cannot reach the broker"


def _wait_for(log: Path, text: str) -> str:
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        said = log.read_text()
        if text in said:
            return said
        time.sleep(0.1)
    raise AssertionError(f"no {text!r} in the sleeve's log: {log.read_text()}")


def test_an_unreachable_broker_is_said_once_and_the_sleeve_connects_when_it_comes(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    broker = start_broker(state_dir=tmp_path / "state")
    c = broker.credentials
    broker.stop()  # its credentials file stays: the sleeve logs in once it is back
    log = tmp_path / "sleeve.log"
    with log.open("w") as stderr:
        sleeve = subprocess.Popen(
            sleeve_command(broker.credentials_path, "--no-legacy"),
            stdout=subprocess.DEVNULL,
            stderr=stderr,
        )
    try:
        _wait_for(log, UNREACHABLE)
        # Three retries at least, far less than a reminder's interval.
        retries_s = 3 * RECONNECT_MAX_S + 1.0
        assert retries_s < UNREACHABLE_REMINDER_S
        time.sleep(retries_s)
        said = log.read_text()
        assert said.count(UNREACHABLE) == 1, said
        assert "publishes no clock" not in said  # no broker reached: nothing was checked
        start_broker(state_dir=tmp_path / "state", port=c.mqtt_port, ws_port=c.ws_port)
        said = _wait_for(log, "connected to")
        assert said.count(UNREACHABLE) == 1, said
        sleeve.send_signal(signal.SIGTERM)
        sleeve.wait(timeout=WAIT_S)
    finally:
        sleeve.kill()
    assert sleeve.returncode == 0, log.read_text()


def test_a_refused_login_is_said_alone_without_the_clock_line(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    """A wrong password: the refusal and the error, nothing on a clock that was not read."""
    broker = start_broker(state_dir=tmp_path / "state")
    c = broker.credentials
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "feelmysign",
            "sleeve",
            "--backend",
            "sim",
            "--no-legacy",
            "--broker",
            c.mqtt_url,
            "--id",
            c.sleeve_id,
            "--username",
            c.sleeve.username,
            "--password",
            "not-the-password",
        ],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    said = done.stdout + done.stderr
    assert done.returncode == 1, said
    assert "refused the sleeve: Not authorized" in said, said
    assert "clock" not in said, said
