"""An ACL that drops the sleeve's events (Mosquitto grants the publish and drops it; MQTT 3.1.1
cannot say so): ``send`` sees the sleeve online yet hears nothing, and says that the broker's
access rules are the likely cause, rather than asking whether the sleeve runs."""

from __future__ import annotations

import os
import pwd
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

WAIT_S = 60.0


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _feelmysign(*argv: str) -> list[str]:
    return [sys.executable, "-m", "feelmysign", *argv]


def test_send_names_the_acl_when_an_online_sleeve_is_never_heard(tmp_path: Path) -> None:
    port = _free_port()
    acl = tmp_path / "acl"
    # Anonymous clients (the sleeve and the sender here) may use every topic of sleeve1 but its
    # events: the sleeve plays, and its answers are dropped.
    acl.write_text(
        "".join(
            f"topic readwrite feelmysign/sleeve1/{name}\n"
            for name in ("strokes", "control", "status", "actuators", "clock")
        )
    )
    conf = tmp_path / "mosquitto.conf"
    user = pwd.getpwuid(os.getuid()).pw_name
    conf.write_text(
        f"user {user}\nlistener {port} 127.0.0.1\nallow_anonymous true\nacl_file {acl}\n"
        "persistence false\n"
    )
    broker = subprocess.Popen(
        ["mosquitto", "-c", str(conf)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    url = f"mqtt://127.0.0.1:{port}"
    log = tmp_path / "sleeve.log"
    try:
        with log.open("w") as stderr:
            sleeve = subprocess.Popen(
                _feelmysign("sleeve", "--no-legacy", "--broker", url),
                stdout=subprocess.DEVNULL,
                stderr=stderr,
            )
        try:
            deadline = time.monotonic() + WAIT_S
            while "connected to" not in log.read_text():
                assert sleeve.poll() is None, log.read_text()
                assert time.monotonic() < deadline, log.read_text()
                time.sleep(0.1)
            sent = subprocess.run(
                _feelmysign("send", "--broker", url, "--shape", "line", "--timeout-s", "2"),
                capture_output=True,
                text=True,
                timeout=WAIT_S,
            )
            # The sleeve played it: its own journal line says so.
            deadline = time.monotonic() + WAIT_S
            while " played; " not in log.read_text():
                assert time.monotonic() < deadline, log.read_text()
                time.sleep(0.1)
            sleeve.send_signal(signal.SIGTERM)
            sleeve.wait(timeout=WAIT_S)
        finally:
            sleeve.kill()
    finally:
        broker.terminate()
        broker.wait(timeout=WAIT_S)
    assert sent.returncode == 1, sent.stdout + sent.stderr
    assert "The sleeve played 0 of 1 strokes; no answer for stroke(s) 1 " in sent.stderr
    assert "is online (its status), yet none of its answers reached this sender" in sent.stderr
    assert "access rules (ACL)" in sent.stderr and "feelmysign/sleeve1/events" in sent.stderr
    assert "is sleeve 'sleeve1' running" not in sent.stderr, sent.stderr
    assert "Traceback" not in sent.stderr + log.read_text()
