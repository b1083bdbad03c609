"""``feelmysign up`` keeps its parts alive and says what happens to them.

Mosquitto is a separate process: if it dies (killed, out of memory), the
watchdog says so and starts it again on the same ports with the same
credentials, so the sleeve and the page reconnect by themselves. It also says
when the sleeve loses the broker and when it is back: one line for a loss (what
was lost, what happens now) and one for the return; the sleeve's own log lines
about its connection are left out, they would say the same. The sleeve itself runs
in ``up``'s own process: if it stops, ``up`` stops with its error. A stop asked
for (Ctrl-C) is no fault: once told ``stopping()``, it says it is stopping and
reports nothing the shutdown itself causes.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from feelmysign.broker import Broker
from feelmysign.daemon import CONNECTION_STATE, Sleeve
from feelmysign.errors import BrokerError
from feelmysign.lifecycle import Started

CHECK_INTERVAL_S = 0.5  # how soon a dead broker or a lost sleeve is noticed
SETTLE_S = 0.2  # a sleeve that lost the broker: time for a dying broker to be seen dead


class Watchdog(Started):
    """Use as a context manager around the broker's life; ``watch`` the sleeve once it runs."""

    def __init__(self, broker: Broker) -> None:
        self._broker = broker
        self._stopped = threading.Event()
        self._stopping = threading.Event()
        self._wake = threading.Event()  # set by a stop of either kind: no waiting out the interval
        self._sleeve: Sleeve | None = None
        self._listening: Callable[[], bool] = lambda: True
        self._thread = threading.Thread(target=self._run, name="feelmysign-watchdog", daemon=True)

    def start(self) -> None:
        # Kept now: a broker that died no longer tells its ports and accounts.
        self._credentials = self._broker.credentials
        self._thread.start()

    def stop(self) -> None:
        self._stopped.set()
        self._wake.set()
        self._thread.join(timeout=5.0)
        self._broker.stop()  # a broker started here again is stopped here too
        logging.getLogger(Sleeve.__module__).removeFilter(self._reported_here)

    def watch(self, sleeve: Sleeve, listening: Callable[[], bool] | None = None) -> None:
        """Report on ``sleeve``; "Back:" also waits for ``listening()`` (the drawing log):
        a drawing sent after that line is then in the terminal too."""
        self._sleeve = sleeve
        if listening is not None:
            self._listening = listening
        logging.getLogger(Sleeve.__module__).addFilter(self._reported_here)

    def _reported_here(self, record: logging.LogRecord) -> bool:
        """Leave out the sleeve's own lines on a lost broker once it had connected: said here.

        Before its first connection they stay: they say why it does not connect.
        """
        marked = all(getattr(record, key, None) == v for key, v in CONNECTION_STATE.items())
        sleeve = self._sleeve
        return not (marked and sleeve is not None and sleeve.counts["connections"] > 0)

    def stopping(self) -> None:
        """A stop was asked for: what follows (the sleeve leaving the broker) is no fault.

        Safe in a signal handler: it only sets events; the watchdog's thread prints.
        """
        self._stopping.set()
        self._wake.set()

    def _run(self) -> None:
        connections = 0
        lost = False  # a loss was said, its return not yet
        restarted_on = ""  # the address of a broker started again, until the sleeve is back
        while True:
            self._wake.wait(CHECK_INTERVAL_S)
            if self._stopping.is_set():
                print(
                    "Stopping: every motor off, then the drawing client and the broker.",
                    flush=True,
                )
                return
            if self._stopped.is_set():
                return
            sleeve = self._sleeve
            restarted = self._check_broker(wait_s=0.0)
            if (
                not restarted
                and sleeve is not None
                and connections > 0
                and not sleeve.connected.is_set()
                and not lost
            ):
                # The sleeve may have seen its broker go a moment before it could be seen dead.
                restarted = self._check_broker(wait_s=SETTLE_S)
                if not restarted and not self._stopped.is_set():
                    lost = True
                    print("The sleeve lost the broker; it reconnects by itself.", flush=True)
            if restarted:
                url = self._broker.credentials.mqtt_url
                if sleeve is None:
                    print(f"Back: the broker is running again on {url}.", flush=True)
                    continue
                lost, restarted_on = True, url
            if sleeve is None:
                continue
            now = sleeve.counts["connections"]
            if lost and now > connections and sleeve.connected.is_set() and self._listening():
                lost = False
                if restarted_on:
                    print(
                        f"Back: the broker is running again on {restarted_on} "
                        "and the sleeve is connected to it.",
                        flush=True,
                    )
                else:
                    print("Back: the sleeve is connected to the broker again.", flush=True)
                restarted_on = ""
            if not lost:
                connections = now

    def _check_broker(self, *, wait_s: float) -> bool:
        """True when the broker had died and was started again."""
        try:
            self._broker.check_running(wait_s=wait_s)
        except BrokerError as error:
            if self._stopped.is_set():
                return False
            how = f"exit code {error.exit_code}" if error.exit_code is not None else error.reason
            print(
                f"The broker stopped ({how}; its log: {error.log_path}); starting it again "
                "on the same ports: the sleeve and the page reconnect by themselves.",
                flush=True,
            )
            return self._restart()
        return False

    def _restart(self) -> bool:
        c = self._credentials
        broker = Broker(
            state_dir=self._broker.state_dir,
            port=c.mqtt_port,
            ws_port=c.ws_port,
            sleeve_id=c.sleeve_id,
            lock=self._broker.lock,  # up holds it: the new broker runs under it
        )
        try:
            broker.start()
        except BrokerError as error:
            print(
                f"Could not start the broker again: {error}\n"
                "Stop with Ctrl-C and run 'make up' again.",
                flush=True,
            )
            self._stopped.set()
            return False
        self._broker = broker
        return True
