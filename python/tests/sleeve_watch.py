"""A sender's view of a sleeve in the tests: its status, events and actuator frames as they
arrive from a real broker, and a way to wait for one of them."""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import threading
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.broker import Credentials
from feelmysign.connection import BrokerSettings, new_client
from feelmysign.guard import guardian_pids
from feelmysign.lifecycle import Closing
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import TelemetryName, strokes_topic, telemetry_topic

WAIT_S = 60.0  # generous: the machine running the tests may be busy

Check = Callable[[str, dict[str, Any]], bool]


def settings(credentials: Credentials, role: str) -> BrokerSettings:
    """How the ``sleeve`` or the ``sender`` account of a ``feelmysign broker`` logs in."""
    return credentials.settings("sleeve" if role == "sleeve" else "sender")


def stop_loop(client: mqtt.Client) -> None:
    """``client.loop_stop()``, minus paho's race: it sets the stop flag, then reads its
    network thread twice, and that thread sets it to None as it ends, so a thread that
    sees the flag between the two reads made loop_stop raise AttributeError. A thread
    already gone has stopped, which is all a test's clean-up asks."""
    try:
        client.loop_stop()
    except AttributeError:
        if client._thread is not None:  # not the race: a real fault
            raise


def connected_client(
    broker_settings: BrokerSettings, *, client_id: str | None = None, wait_s: float = WAIT_S
) -> mqtt.Client:
    """A paho client logged in with ``broker_settings``, its network loop running; the test
    fails unless the broker accepts the login within ``wait_s``."""
    client = new_client(broker_settings, client_id=client_id or f"test-{uuid.uuid4()}")
    connected: queue.Queue[Any] = queue.Queue()
    client.on_connect = lambda _c, _u, _f, code, _p: connected.put(code)
    client.connect(broker_settings.host, broker_settings.port)
    client.loop_start()
    code = connected.get(timeout=wait_s)
    assert not code.is_failure, code
    return client


Inbox = queue.Queue[tuple[str, bytes]]


def subscribe_all(
    client: mqtt.Client, topics: list[str], *, wait_s: float = WAIT_S
) -> tuple[Inbox, list[Any]]:
    """Every message ``client`` receives from now on, as ``(topic, payload)``, once it has
    subscribed to ``topics`` (QoS 1); with the broker's answer, a reason code a topic."""
    received: Inbox = queue.Queue()
    client.on_message = lambda _c, _u, m: received.put((m.topic, bytes(m.payload)))
    done: queue.Queue[Any] = queue.Queue()
    client.on_subscribe = lambda _c, _u, _mid, codes, _p: done.put(codes)
    client.subscribe([(topic, 1) for topic in topics])
    return received, list(done.get(timeout=wait_s))


def subscribe(client: mqtt.Client, topic: str, *, wait_s: float = WAIT_S) -> Inbox:
    """Every message on ``topic`` that ``client`` receives from now on, once subscribed."""
    return subscribe_all(client, [topic], wait_s=wait_s)[0]


@contextmanager
def reaped(process: subprocess.Popen[str]) -> Iterator[subprocess.Popen[str]]:
    """``process``, killed and waited for on the way out, however the test ends: no sleeve
    outlives its test to drive a motor of the next."""
    try:
        yield process
    finally:
        process.kill()
        process.wait(WAIT_S)


def exit_code_after(process: subprocess.Popen[str], sent: signal.Signals) -> int:
    """Send ``sent`` and wait for the process to end: its exit code, or minus the number of
    the signal that ended it. Its piped output is read and dropped."""
    process.send_signal(sent)
    # Reads what is left of a piped stderr while waiting: a process blocked writing to a
    # full pipe would never end.
    process.communicate(timeout=WAIT_S)
    return process.returncode


def killed_with_its_guardian(process: subprocess.Popen[str]) -> int:
    """``kill -9`` of a sleeve and of its guardian (feelmysign.guard), the guardian first:
    what only the restart's early all-off (or an enable line) then puts right. Its exit code
    (minus SIGKILL)."""
    for guardian in guardian_pids(process.pid):
        os.kill(guardian, signal.SIGKILL)
    return exit_code_after(process, signal.SIGKILL)


def online(name: str, body: dict[str, Any]) -> bool:
    return name == "status" and body.get("online") is True


class SleeveWatch(Closing):
    """Every message on the sleeve's ``topics`` (``status``, ``events``, ``actuators``), in
    order, as ``(topic name, body)``; logged in as the sender. ``persistent`` keeps its
    session (and so the messages for it) through broker restarts."""

    def __init__(
        self, credentials: Credentials, *topics: TelemetryName, persistent: bool = False
    ) -> None:
        sid = credentials.sleeve_id
        self.sleeve_id = sid
        self.history: list[tuple[str, dict[str, Any]]] = []
        self._seen = 0  # messages before this one were passed by next()
        self._changed = threading.Condition()
        self.client = new_client(
            settings(credentials, "sender"),
            client_id=f"watch-{uuid.uuid4()}",
            persistent_session=persistent,
        )
        wanted = [(telemetry_topic(sid, t), 0 if t == "actuators" else 1) for t in topics]
        self.client.on_connect = lambda client, *_: client.subscribe(wanted)
        self.client.on_message = self._on_message
        self.client.connect(credentials.mqtt_host, credentials.mqtt_port)
        self.client.loop_start()

    def _on_message(self, _client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        name = message.topic.rsplit("/", 1)[-1]
        body = json.loads(message.payload)
        with self._changed:
            self.history.append((name, body))
            self._changed.notify_all()

    def received(self, name: str | None = None) -> list[dict[str, Any]]:
        """The bodies received so far, on topic ``name`` or on any."""
        with self._changed:
            return [body for topic, body in self.history if name in (None, topic)]

    def wait_until(
        self, condition: Callable[[], bool], what: str, timeout_s: float = WAIT_S
    ) -> None:
        """Until ``condition()`` (called with the history locked) holds; fails after
        ``timeout_s`` without a change that makes it hold."""
        with self._changed:
            assert self._changed.wait_for(condition, timeout_s), (
                f"never saw {what}; last: {self.history[-3:]}"
            )

    def next(self, check: Check, what: str = "it") -> dict[str, Any]:
        """The first message after those already passed that passes ``check``; the ones up to
        it are passed."""
        found: list[dict[str, Any]] = []

        def seen() -> bool:
            while not found and self._seen < len(self.history):
                name, body = self.history[self._seen]
                self._seen += 1
                if check(name, body):
                    found.append(body)
            return bool(found)

        self.wait_until(seen, what)
        return found[0]

    def send(self, stroke: Stroke) -> None:
        self.client.publish(strokes_topic(self.sleeve_id), format_json(stroke), qos=1)

    def close(self) -> None:
        self.client.loop_stop()
        self.client.disconnect()
