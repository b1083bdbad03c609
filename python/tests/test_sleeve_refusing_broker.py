"""A broker that closes the sleeve's connection at each login (here: Mosquitto with
retain_available false, which drops a client publishing a retained message) is named, with
what such a broker usually refuses, once, instead of an endless 'lost the broker'."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

WAIT_S = 90.0
SAID = "closed the connection within"


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def test_a_broker_refusing_retained_messages_is_named(tmp_path: Path) -> None:
    port = _free_port()
    conf = tmp_path / "mosquitto.conf"
    conf.write_text(
        f"listener {port} 127.0.0.1\nallow_anonymous true\nretain_available false\n"
        "persistence false\n"
    )
    broker = subprocess.Popen(
        ["mosquitto", "-c", str(conf)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    log = tmp_path / "sleeve.log"
    try:
        with log.open("w") as stderr:
            sleeve = subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "feelmysign",
                    "sleeve",
                    "--no-legacy",
                    "--broker",
                    f"mqtt://127.0.0.1:{port}",
                ],
                stdout=subprocess.DEVNULL,
                stderr=stderr,
            )
        try:
            deadline = time.monotonic() + WAIT_S
            while SAID not in log.read_text() and time.monotonic() < deadline:
                assert sleeve.poll() is None, log.read_text()
                time.sleep(0.2)
            said = log.read_text()
            assert SAID in said and "retain_available false" in said, said
            assert said.count(SAID) == 1
            # Never logged in: no broker was "lost".
            assert "closed the connection before taking the login" in said, said
            assert "lost the broker" not in said, said
            sleeve.send_signal(signal.SIGTERM)
            sleeve.wait(timeout=WAIT_S)
        finally:
            sleeve.kill()
    finally:
        broker.terminate()
        broker.wait(timeout=WAIT_S)
    assert "Traceback" not in log.read_text()
