"""A Mosquitto configured by the test alone (none of ``feelmysign broker``'s files), and a sleeve
process that logs to a file: what brokers configured by others do to a sleeve and its senders."""

from __future__ import annotations

import os
import pwd
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

WAIT_S = 90.0


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


class BareMosquitto:
    """Mosquitto on a free loopback port with ``settings`` (config lines) and anonymous logins,
    running as the user running the test (as root it would switch to 'mosquitto', which cannot
    write a database in the test's folder). Stopped on leaving the ``with``."""

    def __init__(self, folder: Path, settings: list[str]) -> None:
        self.port = _free_port()
        self.url = f"mqtt://127.0.0.1:{self.port}"
        self._conf = folder / "mosquitto.conf"
        user = pwd.getpwuid(os.getuid()).pw_name
        lines = [f"user {user}", f"listener {self.port} 127.0.0.1", "allow_anonymous true"]
        self._conf.write_text("\n".join([*lines, *settings]) + "\n")
        self._process: subprocess.Popen[bytes] | None = None

    def start(self) -> None:
        self._process = subprocess.Popen(
            ["mosquitto", "-c", str(self._conf)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

    def stop(self, *, kill: bool = False) -> None:
        """SIGTERM (it saves its database), or SIGKILL."""
        process, self._process = self._process, None
        if process is not None:
            process.kill() if kill else process.terminate()
            process.wait(timeout=WAIT_S)

    def __enter__(self) -> BareMosquitto:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


@contextmanager
def sleeve_process(url: str, log: Path) -> Iterator[subprocess.Popen[bytes]]:
    """``feelmysign sleeve`` (simulated, no legacy topic) on ``url``, its log lines in ``log``;
    stopped with SIGTERM on leaving (killed if it does not stop), and its log free of
    tracebacks."""
    with log.open("w") as stderr:
        sleeve = subprocess.Popen(
            [sys.executable, "-m", "feelmysign", "sleeve", "--no-legacy", "--broker", url],
            stdout=subprocess.DEVNULL,
            stderr=stderr,
        )
    try:
        yield sleeve
        sleeve.send_signal(signal.SIGTERM)
        sleeve.wait(timeout=WAIT_S)
    finally:
        sleeve.kill()
    assert "Traceback" not in log.read_text(), log.read_text()


def wait_in_log(log: Path, text: str, sleeve: subprocess.Popen[bytes], *, count: int = 1) -> str:
    """The log once ``text`` is in it ``count`` times (the test fails if the sleeve ends or
    WAIT_S passes first)."""
    deadline = time.monotonic() + WAIT_S
    while log.read_text().count(text) < count:
        assert sleeve.poll() is None, log.read_text()
        assert time.monotonic() < deadline, f"{text!r} not {count} times:\n{log.read_text()}"
        time.sleep(0.1)
    return log.read_text()
