"""systemd's watchdog for the sleeve: a sleeve that stops playing is killed, its motors off.

A DRV2605L drives its motor until told otherwise, so a sleeve process that is
stopped (SIGSTOP, a debugger) or hangs would leave the motor it last switched on
running. Its unit (deploy/feelmysign-sleeve.service) is ``Type=notify`` with
``WatchdogSec=``: the sleeve says ``READY=1`` once its motors are off and its
player runs, then ``WATCHDOG=1`` a few times a watchdog period for as long as the
player's thread goes round its loop. When the pings stop, systemd kills the
process (``WatchdogSignal=SIGKILL``: a stopped process does not take any other
signal), ``ExecStopPost`` runs ``feelmysign off``, and the restart switches
every motor off again before anything else.

The protocol is one datagram per message to the ``AF_UNIX`` socket named in
``$NOTIFY_SOCKET`` (a leading ``@`` is the abstract namespace), as sd_notify(3)
describes; ``$WATCHDOG_USEC`` is the period, ``$WATCHDOG_PID`` (when set) the
process meant. Without ``$NOTIFY_SOCKET`` (not under systemd) nothing is sent.
"""

from __future__ import annotations

import logging
import os
import socket
import threading
from collections.abc import Callable, Mapping

log = logging.getLogger(__name__)

PINGS_PER_PERIOD = 4  # sd_watchdog_enabled(3) advises at least two per period


class ServiceManager:
    """The notify socket of the service manager that started this process."""

    def __init__(self, address: str, watchdog_s: float | None) -> None:
        self._address = "\0" + address[1:] if address.startswith("@") else address
        self.watchdog_s = watchdog_s
        self._socket = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM | socket.SOCK_CLOEXEC)

    @classmethod
    def from_environment(cls, env: Mapping[str, str] = os.environ) -> ServiceManager | None:
        """The manager ``env`` names; None when not started by one (no ``$NOTIFY_SOCKET``)."""
        address = env.get("NOTIFY_SOCKET", "")
        if not address or address[0] not in "/@":
            return None
        watchdog_s: float | None = None
        meant = env.get("WATCHDOG_PID", "")
        try:
            if not meant or int(meant) == os.getpid():
                usec = int(env.get("WATCHDOG_USEC", "0"))
                watchdog_s = usec / 1e6 if usec > 0 else None
        except ValueError:
            log.warning("ignoring a malformed WATCHDOG_USEC or WATCHDOG_PID")
        return cls(address, watchdog_s)

    def notify(self, message: str) -> None:
        """Send ``message`` (e.g. ``READY=1``); a manager that went away is not our failure."""
        try:
            self._socket.sendto(message.encode("utf-8"), self._address)
        except OSError as error:
            log.debug("service manager: %s not sent: %s", message, error)

    def close(self) -> None:
        self._socket.close()


class WatchdogFeeder:
    """Says ``WATCHDOG=1`` a few times a period while ``healthy(max_age_s)`` holds."""

    def __init__(self, manager: ServiceManager, healthy: Callable[[float], bool]) -> None:
        self._manager = manager
        self._healthy = healthy
        self._stopped = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """``READY=1``, then the pings (if the manager has a watchdog)."""
        self._manager.notify("READY=1")
        period = self._manager.watchdog_s
        if period is None:
            return
        self._thread = threading.Thread(
            target=self._run, args=(period,), name="feelmysign-watchdog-ping", daemon=True
        )
        self._thread.start()

    def _run(self, period: float) -> None:
        interval = period / PINGS_PER_PERIOD
        while not self._stopped.wait(interval):
            # The player goes round its loop at least once a second; one that has not done
            # so for most of a period is stuck: no ping, and systemd kills the process.
            if self._healthy(period * 0.75):
                self._manager.notify("WATCHDOG=1")
            else:
                log.error("the player is stuck: no watchdog ping; systemd restarts the sleeve")

    def stop(self) -> None:
        """``STOPPING=1``: the shutdown that follows may outlast a period without pings."""
        self._stopped.set()
        self._manager.notify("STOPPING=1")
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        self._manager.close()
