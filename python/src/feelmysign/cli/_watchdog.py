"""``feelmysign up`` keeps its parts alive and says what happens to them.

Mosquitto is a separate process: if it dies (killed, out of memory), the
watchdog says so and starts it again on the same ports with the same
credentials, so the sleeve and the page reconnect by themselves. It also says
when the sleeve loses the broker and when it is back. The sleeve itself runs
in ``up``'s own process: if it stops, ``up`` stops with its error. A stop asked
for (Ctrl-C) is no fault: once told ``stopping()``, it says it is stopping and
reports nothing the shutdown itself causes.
"""

from __future__ import annotations

import threading
from urllib.parse import urlsplit

from feelmysign.broker import Broker
from feelmysign.daemon import Sleeve
from feelmysign.errors import BrokerError
from feelmysign.lifecycle import Started

CHECK_INTERVAL_S = 0.5  # how soon a dead broker or a lost sleeve is noticed


class Watchdog(Started):
    """Use as a context manager around the broker's life; ``watch`` the sleeve once it runs."""

    def __init__(self, broker: Broker) -> None:
        self._broker = broker
        self._stopped = threading.Event()
        self._stopping = threading.Event()
        self._wake = threading.Event()  # set by a stop of either kind: no waiting out the interval
        self._sleeve: Sleeve | None = None
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

    def watch(self, sleeve: Sleeve) -> None:
        self._sleeve = sleeve

    def stopping(self) -> None:
        """A stop was asked for: what follows (the sleeve leaving the broker) is no fault.

        Safe in a signal handler: it only sets events; the watchdog's thread prints.
        """
        self._stopping.set()
        self._wake.set()

    def _run(self) -> None:
        connections = 0
        lost = False
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
            restarted = self._check_broker()
            sleeve = self._sleeve
            if sleeve is None:
                continue
            if restarted or (connections > 0 and not sleeve.connected.is_set() and not lost):
                lost = True
                print("The sleeve lost the broker; it reconnects by itself.", flush=True)
            now = sleeve.counts["connections"]
            if lost and now > connections and sleeve.connected.is_set():
                lost = False
                print("The sleeve is back: connected to the broker again.", flush=True)
            if not lost:
                connections = now

    def _check_broker(self) -> bool:
        """True when the broker had died and was started again."""
        try:
            self._broker.check_running()
        except BrokerError as error:
            if self._stopped.is_set():
                return False
            print(f"The broker stopped: {error}", flush=True)
            return self._restart()
        return False

    def _restart(self) -> bool:
        c = self._credentials
        broker = Broker(
            state_dir=self._broker.state_dir,
            port=urlsplit(c.mqtt_url).port or 0,
            ws_port=urlsplit(c.ws_url).port or 0,
            sleeve_id=c.sleeve_id,
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
        print(f"The broker is running again on {broker.credentials.mqtt_url}.", flush=True)
        return True
