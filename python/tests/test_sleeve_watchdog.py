"""A sleeve stopped with SIGSTOP mid-stroke: systemd's watchdog kills it and every motor goes off.

The sleeve runs as its own process against a real Mosquitto, its chips emulated
with registers in a state file (they outlive the process, as real chips' do).
This test plays systemd's part as deploy/feelmysign-sleeve.service sets it up
(systemd itself does not run here): it hands the sleeve a notify socket and the
unit's ``WatchdogSec``, reads ``READY=1`` and the ``WATCHDOG=1`` pings, and when
the pings stop for a period it does what the unit says: ``WatchdogSignal``
(SIGKILL), ``ExecStopPost`` (``feelmysign off``), then the restart. No time is
asserted beyond systemd's own rule; the order is: playing, pings, stop, no
pings for a period, kill, every motor off, restarted and ready again.
"""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from sleeve_watch import SleeveWatch, exit_code_after, online, reaped

from feelmysign.backends.emulated_state import drive_levels
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.guard import guardian_pids
from feelmysign.service_manager import ServiceManager, WatchdogFeeder

WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly
UNIT = Path(__file__).resolve().parents[2] / "deploy" / "feelmysign-sleeve.service"


def unit_setting(name: str) -> str:
    found = re.search(rf"^{name}=(.*)$", UNIT.read_text(encoding="utf-8"), re.MULTILINE)
    assert found, f"{UNIT} sets no {name}="
    return found.group(1).strip()


class NotifySocket:
    """The service manager's end of sd_notify: one datagram a message."""

    def __init__(self, folder: Path) -> None:
        self.path = folder / "notify"
        self._socket = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self._socket.bind(str(self.path))

    def next(self, timeout_s: float) -> str | None:
        """The next message, or None when none came in ``timeout_s``."""
        self._socket.settimeout(timeout_s)
        try:
            return self._socket.recv(4096).decode()
        except TimeoutError:
            return None

    def expect(self, message: str) -> None:
        deadline = time.monotonic() + WAIT_S
        while time.monotonic() < deadline:
            if self.next(1.0) == message:
                return
        pytest.fail(f"no {message} from the sleeve in {WAIT_S:g} s")

    def close(self) -> None:
        self._socket.close()


@pytest.fixture
def notify() -> Iterator[NotifySocket]:
    with tempfile.TemporaryDirectory(prefix="fms-") as folder:  # a short path for AF_UNIX
        listening = NotifySocket(Path(folder))
        yield listening
        listening.close()


def start_sleeve(broker: Broker, state: Path, notify: NotifySocket) -> subprocess.Popen[str]:
    watchdog_s = float(unit_setting("WatchdogSec"))
    env = dict(os.environ, NOTIFY_SOCKET=str(notify.path), WATCHDOG_USEC=str(int(watchdog_s * 1e6)))
    command = restart_off.sleeve_command(broker.credentials_path, state)
    return subprocess.Popen(
        command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, text=True
    )


def test_a_stopped_sleeve_stops_pinging_and_the_watchdog_restart_switches_every_motor_off(
    broker: Broker, notify: NotifySocket, tmp_path: Path
) -> None:
    assert unit_setting("Type") == "notify"
    assert unit_setting("WatchdogSignal") == "SIGKILL"  # a stopped process takes no other
    watchdog_s = float(unit_setting("WatchdogSec"))
    state = tmp_path / "bus.json"
    with SleeveWatch(broker.credentials, "status", "events") as watcher:
        with reaped(start_sleeve(broker, state, notify)) as sleeve:
            notify.expect("READY=1")
            watcher.next(online, "the sleeve online")
            notify.expect("WATCHDOG=1")
            watcher.send(restart_off.LONG_STROKE)  # row 1, 8 s
            deadline = time.monotonic() + WAIT_S
            while not any(level > 0 for level in drive_levels(state).values()):
                assert time.monotonic() < deadline, "the stroke never switched a motor on"
                time.sleep(0.01)
            notify.expect("WATCHDOG=1")  # still pinging while it plays

            # The watchdog alone: the sleeve's guardian (feelmysign.guard), which would switch
            # the motors of a stopped sleeve off first, is gone (killed, as systemd may).
            for guardian in guardian_pids(sleeve.pid):
                os.kill(guardian, signal.SIGKILL)
            sleeve.send_signal(signal.SIGSTOP)
            # systemd's rule: no ping for a whole period, and the watchdog fires. Pings sent
            # before the stop may still be queued; after them, silence.
            deadline = time.monotonic() + WAIT_S
            while (message := notify.next(watchdog_s)) is not None:
                assert message == "WATCHDOG=1", message
                assert time.monotonic() < deadline, "a stopped sleeve kept pinging"
            # Stopped, the sleeve left its motor on: what the watchdog is for.
            assert any(level > 0 for level in drive_levels(state).values())
            # WatchdogSignal
            assert exit_code_after(sleeve, signal.SIGKILL) == -signal.SIGKILL

        # ExecStopPost: every motor off at once, before the restart.
        command = [sys.executable, "-m", "feelmysign", "off", "--layout", str(restart_off.PAPER)]
        off = subprocess.run(
            [*command, "--emulate-state", str(state)],
            capture_output=True,
            text=True,
            timeout=WAIT_S,
        )
        assert off.returncode == 0, off.stderr
        assert set(drive_levels(state).values()) == {0.0}

        # Restart=: the sleeve comes back, ready, its motors still off.
        with reaped(start_sleeve(broker, state, notify)) as restarted:
            notify.expect("READY=1")
            watcher.next(online, "the restarted sleeve online")
            notify.expect("WATCHDOG=1")
            assert exit_code_after(restarted, signal.SIGTERM) == 0
    assert set(drive_levels(state).values()) == {0.0}


def test_a_stuck_player_gets_no_ping(notify: NotifySocket) -> None:
    """The pings follow the player's loop, not merely the process: a hung player is killed too."""
    manager = ServiceManager.from_environment(
        {"NOTIFY_SOCKET": str(notify.path), "WATCHDOG_USEC": "200000"}
    )
    assert manager is not None and manager.watchdog_s == pytest.approx(0.2)
    stuck = False
    feeder = WatchdogFeeder(manager, lambda max_age_s: not stuck)
    feeder.start()
    try:
        notify.expect("READY=1")
        notify.expect("WATCHDOG=1")
        stuck = True
        # Any ping already queued, then none for many periods.
        deadline = time.monotonic() + WAIT_S
        while (message := notify.next(1.0)) is not None:
            assert message == "WATCHDOG=1"
            assert time.monotonic() < deadline, "a stuck player still got pings"
    finally:
        feeder.stop()
    assert notify.next(WAIT_S) == "STOPPING=1"


def test_no_manager_without_a_notify_socket_and_no_watchdog_for_another_process() -> None:
    assert ServiceManager.from_environment({}) is None
    other = ServiceManager.from_environment(
        {"NOTIFY_SOCKET": "@x", "WATCHDOG_USEC": "2000000", "WATCHDOG_PID": str(os.getpid() + 1)}
    )
    assert other is not None and other.watchdog_s is None
