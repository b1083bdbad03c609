"""Real processes for the delivery tests: a ``feelmysign sleeve`` to kill, a watcher of its
events and a sender that knows which strokes the broker acknowledged."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NamedTuple

import paho.mqtt.client as mqtt
from conftest import StartBroker
from sleeve_watch import SleeveWatch, settings

from feelmysign.bench.sleeve import sleeve_command
from feelmysign.broker import Broker, Credentials
from feelmysign.connection import new_client
from feelmysign.lifecycle import Closing
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic

WAIT_S = 60.0  # generous: the machine running the tests may be busy


# The paper sleeve's floor (docs/protocol.md, catching up): a stroke this short plays as sent,
# never faster, so a drawing of n such strokes sent at once plays for n x FLOOR_MS.
FLOOR_MS = 73.701


def wait_for(condition: Callable[[], bool], what: str, timeout_s: float = WAIT_S) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)  # another process's progress: nothing here to wait on


class SleeveProcess(Closing):
    """``feelmysign sleeve`` (simulator, --record) as a child process; ``with`` stops it."""

    def __init__(self, credentials_path: Path, record: Path, *extra: str) -> None:
        self.record = record
        self.log = record.with_suffix(".log")
        command = sleeve_command(
            credentials_path, "--record", str(record), "--log-level", "info", *extra
        )
        with self.log.open("ab") as log:
            self.process = subprocess.Popen(command, stdout=log, stderr=log)

    def kill(self) -> None:
        self.process.send_signal(signal.SIGKILL)
        self.process.wait(10)

    def pause(self) -> None:
        os.kill(self.process.pid, signal.SIGSTOP)

    def resume(self) -> None:
        os.kill(self.process.pid, signal.SIGCONT)

    def stop(self) -> None:
        if self.process.poll() is None:
            self.resume()
            self.process.terminate()
            try:
                self.process.wait(15)
            except subprocess.TimeoutExpired:
                self.kill()

    def close(self) -> None:
        self.stop()

    def started(self) -> int:
        """How many strokes the stopped sleeve started, by its own count (the line it prints as
        it stops): one per start, however many copies of each event a watcher received. Those
        played whole and those cut short (by the stop itself, one still playing then)."""
        found = re.findall(
            r"stopped, every motor off \((\d+) played(?:, (\d+) cut short)?", self.log.read_text()
        )
        assert found, f"the sleeve did not say what it played as it stopped: see {self.log}"
        played, cut = found[-1]
        return int(played) + int(cut or 0)

    def changes(self) -> list[dict[str, Any]]:
        if not self.record.exists():
            return []
        lines = self.record.read_text().splitlines()
        return [json.loads(line) for line in lines if line.strip()]


class Watcher(SleeveWatch):
    """Every event and status the sleeve publishes, through broker restarts (persistent)."""

    def __init__(self, credentials: Credentials) -> None:
        super().__init__(credentials, "events", "status", persistent=True)

    def snapshot(self) -> list[dict[str, Any]]:
        return self.received("events")

    def is_online(self, since_wall_ms: float = 0.0) -> bool:
        """Whether the sleeve's last status says online, published at or after ``since_wall_ms``."""
        status = self.received("status")
        return bool(status) and status[-1]["online"] and status[-1]["at_ms"] >= since_wall_ms

    def stop(self) -> None:
        self.close()


class Sender:
    """Publishes strokes of one drawing with QoS 1 and records which ones the broker acked."""

    def __init__(self, credentials: Credentials, *, persistent: bool = True) -> None:
        self.topic = strokes_topic(credentials.sleeve_id)
        self.drawing = str(uuid.uuid4())
        self.acked: set[int] = set()
        self.connections = 0
        self._seq_of_mid: dict[int, int] = {}
        self._early: set[int] = set()  # acks that came before publish() returned the mid
        self._lock = threading.Lock()
        self.client = new_client(
            settings(credentials, "sender"),
            client_id=f"send-{uuid.uuid4()}",
            persistent_session=persistent,
        )
        self.client.on_publish = self._on_publish
        self.client.on_connect = self._on_connect
        self.client.connect(credentials.mqtt_host, credentials.mqtt_port)
        self.client.loop_start()

    def _on_connect(self, *_: Any) -> None:
        with self._lock:
            self.connections += 1

    def _on_publish(self, _client: mqtt.Client, _userdata: Any, mid: int, *_: Any) -> None:
        with self._lock:
            if mid in self._seq_of_mid:
                self.acked.add(self._seq_of_mid.pop(mid))
            else:
                self._early.add(mid)

    def publish(self, seq: int, stroke: Stroke) -> None:
        payload = format_json(stroke)
        # Not under our lock: paho calls on_publish holding its own locks, which publish takes.
        info = self.client.publish(self.topic, payload, qos=1)
        with self._lock:
            if info.mid in self._early:  # acknowledged before we knew its id
                self._early.discard(info.mid)
                self.acked.add(seq)
            else:
                self._seq_of_mid[info.mid] = seq

    def published(self) -> set[int]:
        with self._lock:
            return set(self._seq_of_mid.values()) | self.acked

    def acked_seqs(self) -> set[int]:
        with self._lock:
            return set(self.acked)

    def stop(self) -> None:
        self.client.loop_stop()
        self.client.disconnect()


class Delivery(NamedTuple):
    broker: Broker
    watcher: Watcher
    sleeve: SleeveProcess
    sender: Sender


@contextmanager
def delivery(
    start_broker: StartBroker, tmp_path: Path, *sleeve_options: str, sleeve_login: bool = False
) -> Iterator[Delivery]:
    """A broker (state in ``tmp_path``/state), a watcher, a sleeve as its own process (with
    ``sleeve_options``; ``sleeve_login``: the sleeve's own credentials file rather than the
    broker's) and a sender, once the sleeve is online; all stopped at the end."""
    broker = start_broker(state_dir=tmp_path / "state")
    watcher = Watcher(broker.credentials)
    credentials_path = broker.sleeve_credentials_path if sleeve_login else broker.credentials_path
    sleeve = SleeveProcess(credentials_path, tmp_path / "sleeve.jsonl", *sleeve_options)
    sender = Sender(broker.credentials)
    try:
        wait_for(watcher.is_online, "the sleeve to come online")
        yield Delivery(broker, watcher, sleeve, sender)
    finally:
        sender.stop()
        watcher.stop()
        sleeve.stop()


def stroke(drawing: str, seq: int, duration_ms: float, *, sent_at_ms: float | None) -> Stroke:
    """Strokes of a drawing walking along the grid's top row, back and forth."""
    x = float(seq % 3)
    return Stroke((x, 0.0), (x + 1.0, 0.0), duration_ms, 0.8, drawing, seq, sent_at_ms)


def by_seq(events: list[dict[str, Any]], drawing: str) -> dict[int, list[dict[str, Any]]]:
    found: dict[int, list[dict[str, Any]]] = {}
    for event in events:
        if event.get("drawing") == drawing and "seq" in event:
            found.setdefault(event["seq"], []).append(event)
    return found


def starts(events: list[dict[str, Any]], drawing: str) -> dict[int, set[float]]:
    """When each stroke of ``drawing`` started (its ``first_command_at_ms``), by seq.

    A watcher may receive one event twice across a broker restart: events are QoS 1, at
    least once, and a broker killed after it passed an event on, before it recorded the
    acknowledgement (the sleeve's to it, or the watcher's), sends the event again. Such
    copies say the same ``first_command_at_ms``: one start. Two starts are two clock readings.
    """
    found: dict[int, set[float]] = {}
    for event in played(events):
        if event.get("drawing") == drawing:
            found.setdefault(event["seq"], set()).add(event["first_command_at_ms"])
    return found


def plays(events: list[dict[str, Any]], drawing: str) -> dict[int, int]:
    """How many times each stroke of ``drawing`` started (see ``starts``)."""
    return {seq: len(times) for seq, times in starts(events, drawing).items()}


def felt_more_than_once(events: list[dict[str, Any]], drawing: str) -> dict[int, list[float]]:
    """The strokes of ``drawing`` that started more than once, with their start times."""
    return {seq: sorted(times) for seq, times in starts(events, drawing).items() if len(times) > 1}


def played(events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [e for e in events if e["type"] in ("played", "adjusted")]
