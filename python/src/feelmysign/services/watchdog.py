"""``feelmysign up`` keeps its parts alive and says what happens to them.

Mosquitto is a separate process: if it dies (killed, out of memory), the
watchdog says so and starts it again on the same ports with the same
credentials, so the sleeve and the page reconnect by themselves. A broker whose
process runs but that answers nothing (stopped, hung) is found by a connection of
the watchdog's own that pings it every few seconds, confirmed by a login that gets
no answer, and started again the same way. It also says
when the sleeve loses the broker and when it is back: one line for a loss (what
was lost, what happens now) and one for the return; the sleeve's own log lines
about its connection are left out, they would say the same. The sleeve itself runs
in ``up``'s own process: if it stops, ``up`` stops with its error. A stop asked
for (Ctrl-C) is no fault: once told ``stopping()``, it says it is stopping and
reports nothing the shutdown itself causes.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from feelmysign.broker import Broker
from feelmysign.connection import BrokerSettings, new_client, probe_login
from feelmysign.daemon import CONNECTION_STATE, Sleeve
from feelmysign.errors import BrokerError
from feelmysign.lifecycle import Started

CHECK_INTERVAL_S = 0.5  # how soon a dead broker or a lost sleeve is noticed
SETTLE_S = 0.2  # a sleeve that lost the broker: time for a dying broker to be seen dead
# The watchdog's own connection pings an idle broker this often, and gives it up when a ping
# has no answer within as long again: a broker that stopped answering is noticed in about
# twice this. MQTT pings are not in Mosquitto's log (a login per check would be).
HEARTBEAT_S = 5
# While that connection is down, a login is tried at most this often; no answer within
# PROBE_TIMEOUT_S from a broker whose process runs: it is stopped or hung.
PROBE_EVERY_S = 5.0
PROBE_TIMEOUT_S = 3.0

if TYPE_CHECKING:
    import paho.mqtt.client as mqtt


class Watchdog(Started):
    """Use as a context manager around the broker's life; ``watch`` the sleeve once it runs."""

    def __init__(self, broker: Broker) -> None:
        self._broker = broker
        self._stopped = threading.Event()
        self._stopping = threading.Event()
        self._wake = threading.Event()  # set by a stop of either kind: no waiting out the interval
        self._sleeve: Sleeve | None = None
        self._listening: Callable[[], bool] = lambda: True
        self._heartbeat: _Heartbeat | None = None
        self._next_probe = 0.0
        self._thread = threading.Thread(target=self._run, name="feelmysign-watchdog", daemon=True)

    def start(self) -> None:
        # Kept now: a broker that died no longer tells its ports and accounts.
        self._credentials = self._broker.credentials
        self._heartbeat = _Heartbeat(self._credentials.settings("sender"))
        self._thread.start()

    def stop(self) -> None:
        self._stopped.set()
        self._wake.set()
        self._thread.join(timeout=5.0)
        if self._heartbeat is not None:
            self._heartbeat.stop()
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
            restarted = self._check_broker(wait_s=0.0) or self._check_answers()
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

    def _check_answers(self) -> bool:
        """True when the broker's process runs but it answers nothing, and it was started
        again: its ping connection is down and a login gets no answer either."""
        heartbeat = self._heartbeat
        now = time.monotonic()
        if heartbeat is None or heartbeat.up() or now < self._next_probe:
            return False
        self._next_probe = now + PROBE_EVERY_S
        pid = self._broker.pid
        if not self._broker.running:
            return False  # it died: _check_broker says so
        answer = probe_login(
            self._credentials.settings("sender"),
            client_id=f"feelmysign-up-watchdog-probe-{os.getpid()}",
            timeout_s=PROBE_TIMEOUT_S,
        )
        # A refused login is an answer: the broker runs (its accounts are another matter).
        if answer is not None or self._stopped.is_set() or self._stopping.is_set():
            return False
        # A broker that is exiting refuses connections before it can be seen dead.
        if self._check_broker(wait_s=SETTLE_S):
            return True
        if not self._broker.running or self._stopped.is_set():
            return False
        print(
            f"The broker (pid {pid}) is running but answers nothing: no reply to a ping within "
            f"{HEARTBEAT_S} s nor to a login within {PROBE_TIMEOUT_S:g} s (stopped or hung; "
            f"its log: {self._broker.log_path}). Stopping it and starting it again on the same "
            "ports: the sleeve and the page reconnect by themselves.",
            flush=True,
        )
        self._broker.stop()
        return self._restart()

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


class _Heartbeat:
    """A connection of the watchdog's own that pings the broker every HEARTBEAT_S when idle
    (paho's keepalive), and reconnects by itself; ``up()`` says whether it is connected now.
    It subscribes to nothing and publishes nothing."""

    def __init__(self, settings: BrokerSettings) -> None:
        self._connected = threading.Event()
        client = new_client(settings, client_id=f"feelmysign-up-watchdog-{os.getpid()}")
        client.on_connect = self._on_connect
        client.on_disconnect = lambda *_: self._connected.clear()
        client.reconnect_delay_set(min_delay=1, max_delay=2)
        client.connect_async(settings.host, settings.port, keepalive=HEARTBEAT_S)
        client.loop_start()
        self._client: mqtt.Client = client

    def _on_connect(self, _client: Any, _userdata: Any, _flags: Any, code: Any, _p: Any) -> None:
        if not code.is_failure:
            self._connected.set()

    def up(self) -> bool:
        return self._connected.is_set()

    def stop(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()
