"""The sleeve daemon against a real Mosquitto: it plays, reports, survives garbage and restarts."""

from __future__ import annotations

import base64
import itertools
import json
import subprocess
import threading
import time
import uuid
from collections.abc import Iterator
from dataclasses import replace
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from vectors import load

from feelmysign.backends.sim import SimBackend
from feelmysign.broker import Broker, Credentials
from feelmysign.connection import BrokerSettings, new_client
from feelmysign.control import Cancel, format_control
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.errors import FeelMySignError
from feelmysign.events import Cancelled, Rejected, event_from_json
from feelmysign.layout import Layout
from feelmysign.planner import plan
from feelmysign.protocol import format_json
from feelmysign.services.drawing_log import DrawingSummaries
from feelmysign.stroke import Stroke
from feelmysign.topics import sleeve_topic as topic

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
LEGACY = "deviceOne/line"


def _settings(credentials: Credentials, role: str, password: str | None = None) -> BrokerSettings:
    settings = credentials.settings("sleeve" if role == "sleeve" else "sender")
    return replace(settings, password=password or settings.password)


class Running:
    """A sleeve on a thread, with a client that watches its events."""

    def __init__(self, credentials: Credentials, **options: Any) -> None:
        self.backend = SimBackend(PAPER)
        self.sleeve = Sleeve(
            _settings(credentials, "sleeve"),
            PAPER,
            self.backend,
            SleeveOptions(sleeve_id=credentials.sleeve_id, **options),
        )
        self.events: list[dict[str, Any]] = []
        self.status: list[dict[str, Any]] = []
        self._changed = threading.Condition()
        # A persistent session: events published while the watcher reconnects wait for it.
        self.watcher = new_client(
            _settings(credentials, "sender"),
            client_id=f"watch-{uuid.uuid4()}",
            persistent_session=True,
        )
        self.watcher.on_message = self._on_message
        sid = credentials.sleeve_id
        # Subscribed on every connect: the watcher follows the sleeve through broker restarts.
        self.watcher.on_connect = lambda client, *_: client.subscribe(
            [(topic(sid, "events"), 1), (topic(sid, "status"), 1)]
        )
        # Its subscription is in the broker (and in what a restarted broker loads) only once
        # granted: before that, events would be dropped.
        self._watching = threading.Event()
        self.watcher.on_subscribe = lambda *_: self._watching.set()
        self.watcher.reconnect_delay_set(1, 2)
        self.watcher.connect(credentials.mqtt_host, credentials.mqtt_port)
        self.watcher.loop_start()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.error: BaseException | None = None
        self.thread.start()
        assert self.sleeve.connected.wait(30), "the sleeve did not connect"
        assert self._watching.wait(30), "the watcher did not subscribe"

    def _run(self) -> None:
        try:
            self.sleeve.run()
        except BaseException as error:
            self.error = error

    def _on_message(self, client: mqtt.Client, userdata: Any, message: mqtt.MQTTMessage) -> None:
        with self._changed:
            target = self.status if message.topic.endswith("/status") else self.events
            target.append(json.loads(message.payload))
            self._changed.notify_all()

    def wait_events(self, count: int, timeout_s: float = 30.0) -> list[dict[str, Any]]:
        with self._changed:
            ok = self._changed.wait_for(lambda: len(self.events) >= count, timeout_s)
            assert ok, f"{len(self.events)} of {count} events: {self.events[-3:]}"
            return list(self.events)

    def stop(self) -> None:
        self.sleeve.stop()
        self.thread.join(10)
        self.watcher.loop_stop()
        self.watcher.disconnect()
        self.backend.close()


@pytest.fixture
def running(broker: Broker) -> Iterator[Running]:
    sleeve = Running(broker.credentials)
    yield sleeve
    sleeve.stop()


def _sender(credentials: Credentials) -> mqtt.Client:
    client = new_client(_settings(credentials, "sender"), client_id=f"send-{uuid.uuid4()}")
    client.connect(credentials.mqtt_host, credentials.mqtt_port)
    client.loop_start()
    return client


def test_legacy_payload_from_mosquitto_pub_plays_the_planned_commands(
    running: Running, broker: Broker
) -> None:
    c = broker.credentials
    subprocess.run(
        [
            "mosquitto_pub",
            "-h",
            c.mqtt_host,
            "-p",
            str(c.mqtt_port),
            "-u",
            c.sender.username,
            "-P",
            c.sender.password,
            "-q",
            "1",
            "-t",
            LEGACY,
            "-m",
            "0,0,3,2,1500",
        ],
        check=True,
        timeout=10,
    )
    (event,) = running.wait_events(1)
    assert event["type"] == "played" and event["topic"] == LEGACY
    schedule = plan(Stroke((0.0, 0.0), (3.0, 2.0), 1500.0), PAPER)
    running.sleeve.player.timing_errors_ms.clear()
    _wait_quiet(running)
    ons = [
        (ch.row, ch.column, round(ch.intensity, 6))
        for ch in running.backend.changes
        if ch.intensity
    ]
    # The planner's merged commands, in order: each (row, column, intensity) piece switched on.
    expected = [(cmd.row, cmd.column, round(cmd.intensity, 6)) for cmd in schedule.commands]
    assert sorted(ons) == sorted(expected)
    t0 = running.backend.changes[0].t_ms
    first_on = {
        (ch.row, ch.column): ch.t_ms - t0
        for ch in reversed(running.backend.changes)
        if ch.intensity
    }
    # Each actuator comes on in the planned order (how late, on a busy machine, is a figure
    # of make bench: the sleeve's timing errors).
    planned_on: dict[tuple[int, int], float] = {}
    for cmd in schedule.commands:
        key = (cmd.row, cmd.column)
        planned_on[key] = min(cmd.start_ms, planned_on.get(key, cmd.start_ms))
    for a, b in itertools.permutations(planned_on, 2):
        if planned_on[a] < planned_on[b]:
            assert first_on[a] <= first_on[b], (a, b, first_on, planned_on)


def test_a_drawing_plays_in_order_back_to_back(running: Running, broker: Broker) -> None:
    sender = _sender(broker.credentials)
    drawing = str(uuid.uuid4())
    points = [(k % 4 * 1.0, (k // 4) % 3 * 1.0) for k in range(21)]
    for seq, (start, end) in enumerate(itertools.pairwise(points)):
        stroke = Stroke(start, end, 120.0, 0.8, drawing, seq)
        sender.publish(
            topic(broker.credentials.sleeve_id, "strokes"), format_json(stroke), qos=1
        ).wait_for_publish(5)
    events = running.wait_events(20)
    assert [e["seq"] for e in events] == list(range(20))
    assert {e["type"] for e in events} <= {"played", "adjusted"}
    # What went over the wire reads back as the typed events, unchanged.
    assert all(event_from_json(e).to_json() == e for e in events)
    for before, after in itertools.pairwise(events):
        if after["queued_ms"] > 0:  # arrived while the one before was playing: starts as it ends
            planned_gap_ms = after["start_at_ms"] - (before["start_at_ms"] + before["duration_ms"])
            assert planned_gap_ms == pytest.approx(0.0, abs=0.05)  # two clocks read per stroke
    sender.loop_stop()


def test_a_stroke_after_later_ones_plays_and_every_copy_is_a_duplicate(
    running: Running, broker: Broker
) -> None:
    # What a broker that fails over does (NATS after ack_wait): a stroke comes again after
    # later ones, as a copy of one already played or refused, or for the first time.
    sender = _sender(broker.credentials)
    drawing = str(uuid.uuid4())
    now_ms = time.time() * 1000

    def send(seq: int, sent_at_ms: float = now_ms) -> None:
        stroke = Stroke((0.0, 0.0), (3.0, 2.0), 120.0, 0.8, drawing, seq, sent_at_ms)
        sid = broker.credentials.sleeve_id
        sender.publish(topic(sid, "strokes"), format_json(stroke), qos=1).wait_for_publish(5)

    for seq in (0, 2, 3, 1):
        send(seq)
    played = running.wait_events(4)
    assert [e["seq"] for e in played] == [0, 2, 3, 1]
    assert {e["type"] for e in played} <= {"played", "adjusted"}
    send(4, sent_at_ms=now_ms - 60_000)  # stale
    assert running.wait_events(5)[4]["reason"] == "stale"
    for seq in (2, 4, 1):
        send(seq)  # copies, and fresh by their send time: still played or refused once
    copies = running.wait_events(8)[5:]
    assert [(e["reason"], e["seq"]) for e in copies] == [("duplicate", s) for s in (2, 4, 1)]
    # Each copy says whether its stroke was felt: 2 and 1 played, 4 refused as stale.
    assert [e["original_played"] for e in copies] == [True, False, True]
    assert "played once already" in copies[0]["message"]
    assert "was not played before" in copies[1]["message"]
    sender.loop_stop()


def _garbage() -> list[tuple[str, bytes, str]]:
    """Every invalid protocol vector as (topic kind, payload, expected reason)."""
    items = []
    for _, case in load("protocol"):
        expected = case.get("expected", {})
        if expected.get("accepted", True) or case.get("layout", {}).get("rows") != 3:
            continue
        encoding = case["payload_encoding"]
        if encoding == "json-value":
            continue  # a value that is not bytes at all (None, a list): MQTT cannot carry it
        raw = case["payload"]
        payload = base64.b64decode(raw) if encoding == "base64" else raw.encode()
        kind = "json" if payload.lstrip()[:1] == b"{" or encoding != "utf-8" else "legacy"
        if case.get("format") not in ("auto", kind):
            continue
        items.append((kind, payload, expected["reason"]))
    return items


def test_garbage_never_stops_the_sleeve_and_every_valid_stroke_plays(broker: Broker) -> None:
    running = Running(broker.credentials, rate_per_s=1e6, burst=10**6)
    try:
        garbage = _garbage()
        assert len({reason for _, _, reason in garbage}) >= 15 and len(garbage) >= 30
        sender = _sender(broker.credentials)
        sid = broker.credentials.sleeve_id
        valid_count, sent = 0, []
        for k in range(1000):
            if k % 10 == 0:
                stroke = Stroke(
                    (0.0, float(k % 3)), (1.0, float(k % 3)), 80.0, None, "g", valid_count
                )
                sent.append(sender.publish(topic(sid, "strokes"), format_json(stroke), qos=1))
                valid_count += 1
            else:
                kind, payload, _ = garbage[k % len(garbage)]
                sent.append(
                    sender.publish(
                        LEGACY if kind == "legacy" else topic(sid, "strokes"), payload, qos=1
                    )
                )
        for info in sent:
            info.wait_for_publish(10)
        events = running.wait_events(1000, timeout_s=60)
        played = [e for e in events if e["type"] in ("played", "adjusted")]
        rejected = [e for e in events if e["type"] == "rejected"]
        assert [e["seq"] for e in played] == list(range(valid_count))
        assert len(rejected) == 1000 - valid_count and all(
            e["reason"] and e["message"] for e in rejected
        )
        assert running.sleeve.counts["rejected"] == 1000 - valid_count
        assert running.error is None and running.thread.is_alive()
        sender.loop_stop()
    finally:
        running.stop()


def test_strokes_sent_while_the_broker_restarts_are_played(
    start_broker: Any, tmp_path: Any
) -> None:
    broker = start_broker(state_dir=tmp_path / "state")
    c = broker.credentials
    running = Running(c)
    try:
        # Its status follows its subscription on the same connection: once the status is
        # out, the broker has the subscription (else the broker could stop without it).
        with running._changed:
            assert running._changed.wait_for(lambda: running.status, 30)
        sender = new_client(
            _settings(c, "sender"), client_id="restart-sender", persistent_session=True
        )
        sender.reconnect_delay_set(1, 2)
        # Connected (CONNACK in) before the broker stops: else a late CONNACK could mark it
        # connected after the stop, and the publishes below would go to a closed socket.
        sender_connected = threading.Event()
        sender.on_connect = lambda *_: sender_connected.set()
        sender.connect(c.mqtt_host, c.mqtt_port)
        sender.loop_start()
        assert sender_connected.wait(30), "the sender did not connect"
        broker.stop()
        for _ in range(1000):  # paho notices the closed socket on its own thread
            if not sender.is_connected():
                break
            threading.Event().wait(0.01)
        infos = [
            sender.publish(
                topic(c.sleeve_id, "strokes"),
                format_json(Stroke((0.0, 0.0), (1.0, 0.0), 100.0, None, "r", seq)),
                qos=1,
            )
            for seq in range(5)
        ]
        start_broker(state_dir=tmp_path / "state", port=c.mqtt_port, ws_port=c.ws_port)
        # paho keeps QoS 1 messages published while away and sends them on reconnect.
        assert all(info.rc == mqtt.MQTT_ERR_NO_CONN for info in infos)
        events = running.wait_events(5, timeout_s=60)
        assert [e["seq"] for e in events if e["type"] == "played"] == list(range(5))
        sender.loop_stop()
    finally:
        running.stop()


def test_status_is_retained_and_marks_offline_on_exit(running: Running, broker: Broker) -> None:
    with running._changed:
        assert running._changed.wait_for(lambda: running.status, 10)
    assert running.status[-1]["online"] is True
    assert running.status[-1]["layout"]["rows"] == 3
    running.sleeve.stop()
    running.thread.join(10)
    with running._changed:
        assert running._changed.wait_for(lambda: running.status[-1]["online"] is False, 10)


def test_a_wrong_password_is_refused_with_a_clear_error(broker: Broker) -> None:
    settings = _settings(broker.credentials, "sleeve", password="wrong")
    sleeve = Sleeve(settings, PAPER, SimBackend(PAPER), SleeveOptions(sleeve_id="sleeve1"))
    with pytest.raises(FeelMySignError, match="refused"):
        sleeve.run()


def _wait_quiet(running: Running) -> None:
    deadline = time.monotonic() + 60
    while not running.sleeve.player.idle:
        assert time.monotonic() < deadline, "the sleeve kept playing"
        time.sleep(0.01)


def test_a_retained_stroke_is_not_played_again_and_again(broker: Broker) -> None:
    sender = _sender(broker.credentials)
    sender.publish(LEGACY, "0,0,1,0,100", qos=1, retain=True).wait_for_publish(5)
    running = Running(broker.credentials)  # subscribes after: the broker replays the retained one
    try:
        (event,) = running.wait_events(1)
        assert event["type"] == "rejected" and event["reason"] == "retained"
    finally:
        sender.publish(LEGACY, b"", qos=1, retain=True).wait_for_publish(5)  # clear it
        sender.loop_stop()
        running.stop()


def test_strokes_still_waiting_at_stop_are_reported(broker: Broker) -> None:
    running = Running(broker.credentials)
    sender = _sender(broker.credentials)
    sid = broker.credentials.sleeve_id
    for seq in range(3):
        stroke = Stroke((0.0, 0.0), (3.0, 0.0), 3000.0, None, "long", seq)
        sender.publish(topic(sid, "strokes"), format_json(stroke), qos=1).wait_for_publish(5)
    running.wait_events(1)
    # All three in the sleeve's hands (acknowledged by the broker is not yet received).
    deadline = time.monotonic() + 60
    while running.sleeve.counts["received"] < 3:
        assert time.monotonic() < deadline, f"the sleeve received {running.sleeve.counts}"
        time.sleep(0.01)
    running.sleeve.stop()
    running.thread.join(10)
    events = running.wait_events(3)  # the watcher is still listening: nothing is lost
    running.stop()
    sender.loop_stop()
    reasons = [e.get("reason") for e in events if e["type"] == "rejected"]
    assert reasons.count("stopped") == 2


def test_a_drawing_with_a_refused_stroke_and_one_cut_short_is_one_terminal_line(
    running: Running, broker: Broker
) -> None:
    # What a page sends (JSON v1, each stroke named by its drawing and seq), read back from the
    # sleeve's own events as 'feelmysign up' prints them.
    sender = _sender(broker.credentials)
    sid = broker.credentials.sleeve_id
    drawing = str(uuid.uuid4())
    sent_ms = time.time() * 1000
    strokes = [
        Stroke((0.0, 0.0), (0.0, 1.0), 120.0, 0.8, drawing, 0, sent_ms),
        Stroke((0.0, 0.0), (0.0, 9.0), 120.0, 0.8, drawing, 1, sent_ms),  # outside the grid
        Stroke((0.0, 0.0), (3.0, 2.0), 3000.0, 0.8, drawing, 2, sent_ms),  # long
    ]
    for stroke in strokes:
        sender.publish(topic(sid, "strokes"), format_json(stroke), qos=1).wait_for_publish(5)
    running.wait_events(3)  # two played, one rejected
    sender.publish(topic(sid, "control"), format_control(Cancel(drawing)), qos=1)
    events = [event_from_json(e) for e in running.wait_events(4)]
    refused = next(e for e in events if isinstance(e, Rejected))
    assert (refused.reason, refused.drawing, refused.seq) == ("outside_grid", drawing, 1)
    assert any(isinstance(e, Cancelled) and e.started and e.seq == 2 for e in events)
    summaries = DrawingSummaries()
    for event in events:
        summaries.add(event, now_s=0.0)
    [line] = summaries.finished(100.0)
    assert line.startswith(
        f"Drawing {drawing[:8]}: 1 stroke played, 1 cut short, 1 rejected (outside_grid); "
    ), line
    sender.loop_stop()
