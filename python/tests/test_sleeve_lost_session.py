"""A broker restarted without persistence forgets the sleeve's session, and the strokes it held
for the sleeve: the sleeve says so when it reconnects, rather than a plain "new session"."""

from __future__ import annotations

import time
from pathlib import Path

from bare_mosquitto import BareMosquitto, sleeve_process, wait_in_log

CONNECTED = "connected to mqtt://127.0.0.1:"
SAID = "no longer had the sleeve's session"


def _run(tmp_path: Path, persistence: bool) -> str:
    """The sleeve's log across a restart of its broker (SIGKILL, then started again)."""
    settings = [f"persistence {'true' if persistence else 'false'}"]
    if persistence:
        settings += [
            f"persistence_location {tmp_path}/",
            "autosave_interval 1",
            "autosave_on_changes true",
        ]
    log = tmp_path / "sleeve.log"
    with BareMosquitto(tmp_path, settings) as broker, sleeve_process(broker.url, log) as sleeve:
        wait_in_log(log, CONNECTED, sleeve)
        time.sleep(1.5)  # the session saved (with persistence)
        broker.stop(kill=not persistence)  # SIGTERM saves the database as it exits
        broker.start()
        return wait_in_log(log, CONNECTED, sleeve, count=2)


def test_a_broker_that_forgot_the_sleeves_session_is_said(tmp_path: Path) -> None:
    said = _run(tmp_path, persistence=False)
    assert said.count("(new session)") == 2, said
    assert said.count(SAID) == 1, said
    assert "persistence true" in said, said


def test_a_resumed_session_says_nothing(tmp_path: Path) -> None:
    said = _run(tmp_path, persistence=True)
    assert "(resumed session)" in said, said
    assert SAID not in said, said
