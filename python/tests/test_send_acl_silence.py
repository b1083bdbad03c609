"""An ACL that drops the sleeve's events (Mosquitto grants the publish and drops it; MQTT 3.1.1
cannot say so): ``send`` sees the sleeve online yet hears nothing, and says that the broker's
access rules are the likely cause, rather than asking whether the sleeve runs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from bare_mosquitto import WAIT_S, BareMosquitto, sleeve_process, wait_in_log


def test_send_names_the_acl_when_an_online_sleeve_is_never_heard(tmp_path: Path) -> None:
    acl = tmp_path / "acl"
    # Anonymous clients (the sleeve and the sender here) may use every topic of sleeve1 but its
    # events: the sleeve plays, and its answers are dropped.
    acl.write_text(
        "".join(
            f"topic readwrite feelmysign/sleeve1/{name}\n"
            for name in ("strokes", "control", "status", "actuators", "clock")
        )
    )
    log = tmp_path / "sleeve.log"
    settings = [f"acl_file {acl}", "persistence false"]
    with BareMosquitto(tmp_path, settings) as broker, sleeve_process(broker.url, log) as sleeve:
        wait_in_log(log, "connected to", sleeve)
        command = [sys.executable, "-m", "feelmysign", "send", "--broker", broker.url]
        sent = subprocess.run(
            [*command, "--shape", "line", "--timeout-s", "2"],
            capture_output=True,
            text=True,
            timeout=WAIT_S,
        )
        wait_in_log(log, " played; ", sleeve)  # the sleeve played it: its own journal says so
    assert sent.returncode == 1, sent.stdout + sent.stderr
    assert "The sleeve played 0 of 1 strokes; no answer for stroke(s) 1 " in sent.stderr
    assert "is online (its status), yet none of its answers reached this sender" in sent.stderr
    assert "access rules (ACL)" in sent.stderr and "feelmysign/sleeve1/events" in sent.stderr
    assert "is sleeve 'sleeve1' running" not in sent.stderr, sent.stderr
    assert "Traceback" not in sent.stderr
