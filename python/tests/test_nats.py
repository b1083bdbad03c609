"""feelmysign on a real 3-node NATS cluster (JetStream, MQTT listeners, deploy/nats/node.conf):
the sleeve, the CLI sender and the ACL mirrored as NATS permissions, and a node killed
while a drawing is sent."""

from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from sleeve_watch import connected_client, stop_loop, subscribe, subscribe_all

from feelmysign.broker.credentials import Account, reuse_or_create
from feelmysign.broker.nats_cluster import NatsCluster
from feelmysign.connection import BrokerSettings, new_client, parse_broker_url
from feelmysign.daemon import sleeve_client_id
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

WAIT_S = 60.0
SLEEVE = "sleeve1"
OTHER = Account("sleeve-arm2", "arm2-password-0123456789")

pytestmark = pytest.mark.broker
# The sleeve's pace limits on a cluster (docs/deploy.md): a node's failure may hold
# strokes back for up to about 10 s, and they still play.
CLUSTER_PACE = ("--max-lag-ms", "30000", "--max-age-ms", "60000")
ACK_WAIT_S = 10.0  # deploy/nats/mqtt.conf: a stroke not acknowledged is sent again after it


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[NatsCluster]:
    state = tmp_path_factory.mktemp("nats")
    credentials = reuse_or_create(
        state / "credentials.json", sleeve_id=SLEEVE, mqtt_url="mqtt://x:1", ws_url="ws://x:2"
    )
    with NatsCluster(state, credentials, other_sleeves={"arm2": OTHER}) as running:
        yield running


def client(url: str, account: Account, *, client_id: str | None = None) -> mqtt.Client:
    settings = parse_broker_url(url, username=account.username, password=account.password)
    return connected_client(settings, client_id=client_id, wait_s=WAIT_S)


def feelmysign(*args: str) -> list[str]:
    return [sys.executable, "-m", "feelmysign", *args]


def test_the_acl_holds_on_nats_a_sleeve_reads_only_its_own_strokes(cluster: NatsCluster) -> None:
    a, b = cluster.nodes[0].mqtt_url, cluster.nodes[1].mqtt_url
    c = cluster.credentials
    first = client(a, c.sleeve)
    second = client(b, OTHER)
    sender = client(b, c.sender)
    try:
        # NATS refuses the subscription outright (SUBACK 0x80), where Mosquitto grants it
        # and filters what it delivers; either way nothing of arm2's may arrive.
        spy, codes = subscribe_all(first, [strokes_topic("arm2"), strokes_topic(SLEEVE)])
        assert [code.is_failure for code in codes] == [True, False]
        own = subscribe(second, strokes_topic("arm2"))
        sender.publish(strokes_topic("arm2"), b"private", qos=1).wait_for_publish(10)
        sender.publish(strokes_topic(SLEEVE), b"own", qos=1).wait_for_publish(10)
        assert own.get(timeout=WAIT_S) == (strokes_topic("arm2"), b"private")
        # Ordered per publisher: "own" comes after anything the spy could have read.
        assert spy.get(timeout=WAIT_S) == (strokes_topic(SLEEVE), b"own")
        assert spy.empty()
    finally:
        for paho in (first, second, sender):
            stop_loop(paho)


class Events:
    """The sleeve's events as the sender sees them, on a node that stays up.

    ``played`` maps each stroke (drawing, seq) to the distinct payloads of its played
    events: a QoS 1 event sent again after a failover is the same bytes, a stroke
    played twice would be two events with different timestamps. ``refused`` maps each
    stroke to the reasons it was refused for.
    """

    def __init__(self, url: str, account: Account) -> None:
        self.played: dict[tuple[str, int], set[str]] = {}
        self.refused: dict[tuple[str, int], set[str]] = {}
        self._order: list[tuple[str, int]] = []  # the strokes, in the order they played
        self._lock = threading.Condition()
        # A persistent session, subscribed on every connect: a node that drops its
        # clients while JetStream moves its leaders must not make the watcher miss events.
        settings = parse_broker_url(url, username=account.username, password=account.password)
        self.client = new_client(settings, client_id="events-watcher", persistent_session=True)
        self.client.on_message = self._on_message
        subscribed = threading.Event()

        def on_connect(paho: mqtt.Client, *_args: Any) -> None:
            paho.subscribe(telemetry_topic(SLEEVE, "events"), qos=1)

        self.client.on_connect = on_connect
        self.client.on_subscribe = lambda *_args: subscribed.set()
        self.client.connect(settings.host, settings.port)
        self.client.loop_start()
        assert subscribed.wait(WAIT_S), "the events watcher could not subscribe"

    def _on_message(self, _c: Any, _u: Any, message: mqtt.MQTTMessage) -> None:
        event = json.loads(message.payload)
        if "drawing" not in event or "seq" not in event:
            return
        key = (event["drawing"], event["seq"])
        with self._lock:
            if event.get("type") in ("played", "adjusted"):
                if key not in self.played:
                    self._order.append(key)
                self.played.setdefault(key, set()).add(message.payload.decode())
            elif event.get("type") in ("rejected", "cancelled", "safety"):
                self.refused.setdefault(key, set()).add(str(event.get("reason")))
            self._lock.notify_all()

    def wait_played(self, drawing: str, count: int) -> None:
        with self._lock:
            self._lock.wait_for(lambda: len(self.played_seqs(drawing)) >= count, WAIT_S)

    def wait_settled(self, drawing: str, count: int) -> None:
        """Until ``count`` strokes of ``drawing`` were played or refused (not as copies)."""
        with self._lock:
            self._lock.wait_for(lambda: len(self.settled(drawing)) >= count, WAIT_S)

    def settled(self, drawing: str) -> set[int]:
        with self._lock:
            refused = {seq for seq, why in self.refusals(drawing).items() if why != {"duplicate"}}
            return set(self.played_seqs(drawing)) | refused

    def played_seqs(self, drawing: str) -> list[int]:
        with self._lock:
            return sorted(seq for (d, seq) in self.played if d == drawing)

    def order(self, drawing: str) -> list[int]:
        with self._lock:
            return [seq for (d, seq) in self._order if d == drawing]

    def refusals(self, drawing: str) -> dict[int, set[str]]:
        with self._lock:
            return {seq: reasons for (d, seq), reasons in self.refused.items() if d == drawing}


def _send(cluster: NatsCluster, *shape: str) -> subprocess.Popen[str]:
    """The CLI sender on node b, drawing ``shape`` at a hand's pace."""
    return _run_as(
        cluster.credentials.sender,
        *("send", "--broker", cluster.nodes[1].mqtt_url, "--id", SLEEVE, "--shape", *shape),
        # Node b may drop its clients while JetStream elects new leaders for the
        # streams node a led; the sender reconnects and sends the stroke again.
        *("--timeout-s", "40"),
        # The test reads the sleeve's events itself: the sender returns once the broker has it all.
        "--no-wait",
    )


def _run_as(account: Account, command: str, *args: str) -> subprocess.Popen[str]:
    """``feelmysign command args`` logged in as ``account``, its output in one pipe."""
    return subprocess.Popen(
        feelmysign(command, "--username", account.username, *args),
        env={**os.environ, "FEELMYSIGN_PASSWORD": account.password},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )


@pytest.fixture
def fresh_cluster(tmp_path: Path) -> Iterator[NatsCluster]:
    """A cluster of its own, for a test that kills one of its nodes."""
    credentials = reuse_or_create(
        tmp_path / "credentials.json", sleeve_id=SLEEVE, mqtt_url="mqtt://x:1", ws_url="ws://x:2"
    )
    with NatsCluster(tmp_path / "cluster", credentials) as running:
        yield running


@dataclass
class Failover:
    events: Events
    first: str  # the drawing node a's death cut
    second: str  # the drawing sent after it
    said: str  # what the sender and the sleeve printed


def _kill_the_sleeves_node_mid_drawing(cluster: NatsCluster, *pace: str) -> Failover:
    """A sleeve on node a (b and c to fail over to) with the sleeve options ``pace``; a
    drawing of 12 strokes sent from node b at a hand's pace; node a killed (SIGKILL)
    once two strokes played; then a drawing of 4 strokes."""
    c = cluster.credentials
    sleeve = _run_as(c.sleeve, "sleeve", "--broker", cluster.mqtt_urls, "--id", SLEEVE, *pace)
    events = Events(cluster.nodes[1].mqtt_url, c.sender)
    first_out = ""
    try:
        _wait_online(cluster, c.sender)
        send = _send(cluster, "circle", "--segments", "12")
        first = _drawing_of_first_line(send)
        events.wait_played(first, 2)
        cluster.kill(0)
        out = first_out = send.communicate(timeout=WAIT_S * 2)[0]
        assert send.returncode == 0, out
        events.wait_settled(first, 12)
        # Back on another node: the next drawing plays in full.
        second_send = _send(cluster, "square")
        second = _drawing_of_first_line(second_send)
        out = second_send.communicate(timeout=WAIT_S)[0]
        assert second_send.returncode == 0, out
        # Played or refused: with the default pace a stroke of it may be refused as late, and
        # waiting for four played would then wait out WAIT_S (each test asserts what it needs).
        events.wait_settled(second, 4)
    finally:
        stop_loop(events.client)
        sleeve.terminate()
        sleeve_out = sleeve.communicate(timeout=WAIT_S)[0]
    assert f"connected to {cluster.nodes[0].mqtt_url}" in sleeve_out, sleeve_out
    moved = [f"connected to {n.mqtt_url}" in sleeve_out for n in cluster.nodes[1:]]
    assert any(moved), sleeve_out
    said = f"the sender said:\n{first_out}\nthe sleeve said:\n{sleeve_out}"
    return Failover(events, first, second, said)


def test_a_sleeve_moves_to_another_node_when_its_node_dies_and_plays_every_stroke_once(
    fresh_cluster: NatsCluster,
) -> None:
    # JetStream holds the strokes sent while it elects new leaders for what node a led
    # (4 to 9 s): the sleeve's pace limits for a cluster (docs/deploy.md) let it play
    # them late rather than skip them.
    run = _kill_the_sleeves_node_mid_drawing(fresh_cluster, *CLUSTER_PACE)
    events, said = run.events, run.said
    # Every stroke of the cut drawing played exactly once: none lost, none refused (a
    # copy the broker delivers again after the failover is dropped as a duplicate), none
    # played twice.
    assert events.played_seqs(run.first) == list(range(12)), said
    assert all(why == {"duplicate"} for why in events.refusals(run.first).values()), said
    assert events.played_seqs(run.second) == [0, 1, 2, 3], said
    assert all(len(payloads) == 1 for payloads in events.played.values()), "played twice"


def test_with_the_default_pace_a_failover_skips_strokes_only_out_loud(
    fresh_cluster: NatsCluster,
) -> None:
    run = _kill_the_sleeves_node_mid_drawing(fresh_cluster)
    events, said = run.events, run.said
    # The sleeve keeps to real time: what the election held back more than 1 s may be
    # refused as late (or stale), and each refusal is reported. Every stroke of the cut
    # drawing is played or reported, none is played twice, and none both.
    assert events.settled(run.first) == set(range(12)), said
    refused = {seq: why - {"duplicate"} for seq, why in events.refusals(run.first).items()}
    assert all(why <= {"late", "stale"} for why in refused.values()), said
    assert not {seq for seq, why in refused.items() if why} & set(events.played_seqs(run.first))
    # The drawing sent after the failover may still meet the election's tail (held at the
    # broker): the same rule holds for it, and the sleeve is back in real time by its end.
    assert events.settled(run.second) == {0, 1, 2, 3}, said
    after = {seq: why - {"duplicate"} for seq, why in events.refusals(run.second).items()}
    assert all(why <= {"late", "stale"} for why in after.values()), said
    assert 3 in events.played_seqs(run.second), said
    assert all(len(payloads) == 1 for payloads in events.played.values()), "played twice"


def _drawing_of_first_line(send: subprocess.Popen[str]) -> str:
    """The drawing id in the first stroke line the sender prints."""
    assert send.stdout is not None
    while True:
        line = send.stdout.readline()
        if not line:
            raise AssertionError(f"the sender printed no stroke (exit {send.wait()})")
        if '"drawing":"' in line:
            return line.split('"drawing":"')[1].split('"')[0]


def _wait_online(cluster: NatsCluster, sender: Account) -> None:
    watcher = client(cluster.nodes[1].mqtt_url, sender)
    try:
        statuses = subscribe(watcher, telemetry_topic(SLEEVE, "status"))
        deadline = time.monotonic() + WAIT_S
        while time.monotonic() < deadline:
            _topic, payload = statuses.get(timeout=WAIT_S)
            if json.loads(payload).get("online"):
                return
        raise AssertionError("the sleeve never came online")
    finally:
        stop_loop(watcher)


def test_settings_take_several_urls_of_one_cluster() -> None:
    settings = parse_broker_url("mqtt://a:1883,mqtt://b:1884, mqtt://c:1885")
    assert [e.url for e in settings.endpoints()] == [
        "mqtt://a:1883",
        "mqtt://b:1884",
        "mqtt://c:1885",
    ]
    assert isinstance(settings, BrokerSettings) and settings.urls.count(",") == 2


def test_a_stroke_redelivered_after_later_ones_plays_once(cluster: NatsCluster) -> None:
    """A stroke the broker acknowledged to its sender and never got acknowledged for (the
    sleeve's connection went away with it in flight, as when its node dies) comes again
    after ack_wait: on NATS, after the strokes sent since. It plays, once: it is not
    refused for coming out of order (it was, as ``out_of_order``, and so lost)."""
    c = cluster.credentials
    node = cluster.nodes[2]
    # The sleeve's session receives stroke 0 and goes away without acknowledging it.
    settings = parse_broker_url(
        node.mqtt_url, username=c.sleeve.username, password=c.sleeve.password
    )
    session = sleeve_client_id(SLEEVE, c.sleeve.password)
    away = new_client(settings, client_id=session, persistent_session=True)
    away.manual_ack_set(True)
    got: queue.Queue[bytes] = queue.Queue()
    away.on_message = lambda _c, _u, m: got.put(bytes(m.payload))
    subscribed = threading.Event()
    away.on_connect = lambda paho, *_: paho.subscribe(strokes_topic(SLEEVE), qos=1)
    away.on_subscribe = lambda *_: subscribed.set()
    away.connect(settings.host, settings.port)
    away.loop_start()
    assert subscribed.wait(WAIT_S)
    sender = client(node.mqtt_url, c.sender)
    drawing = str(uuid.uuid4())

    def send(seq: int) -> None:
        stroke = Stroke((0.0, 1.0), (2.0, 1.0), 200.0, 0.5, drawing, seq, time.time() * 1000)
        sender.publish(strokes_topic(SLEEVE), format_json(stroke), qos=1).wait_for_publish(10)

    events = Events(node.mqtt_url, c.sender)
    sleeve: subprocess.Popen[str] | None = None
    try:
        send(0)
        assert json.loads(got.get(timeout=WAIT_S))["seq"] == 0
        delivered_s = time.monotonic()
        away.disconnect()  # a clean exit: the session, and stroke 0 unacknowledged, stay
        stop_loop(away)
        sleeve = _run_as(
            c.sleeve, "sleeve", "--broker", node.mqtt_url, "--id", SLEEVE, *CLUSTER_PACE
        )
        _wait_online(cluster, c.sender)
        back_within_ack_wait = time.monotonic() - delivered_s < ACK_WAIT_S - 2
        for seq in (1, 2, 3):
            send(seq)
        events.wait_settled(drawing, 4)
    finally:
        stop_loop(events.client)
        stop_loop(sender)
        said = ""
        if sleeve is not None:
            sleeve.terminate()
            said = sleeve.communicate(timeout=WAIT_S)[0]
    assert events.played_seqs(drawing) == [0, 1, 2, 3], (events.refusals(drawing), said)
    assert all(why == {"duplicate"} for why in events.refusals(drawing).values()), said
    assert all(len(payloads) == 1 for payloads in events.played.values()), "played twice"
    if back_within_ack_wait:  # else NATS may send stroke 0 again before the others
        assert events.order(drawing) == [1, 2, 3, 0], said


def test_a_port_taken_before_a_node_binds_it_starts_the_cluster_on_other_ports(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A port picked free can be taken by another program before nats-server binds it: the
    node stops at once ("address already in use"), and the cluster starts on other ports."""
    import socket

    from feelmysign.broker import _process as process_

    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen()
    port = taken.getsockname()[1]
    picked_free = process_.free_port
    picks = iter([port])  # the first port picked is the one another program holds

    def free_port(host: str) -> int:
        return next(picks, None) or picked_free(host)

    monkeypatch.setattr(process_, "free_port", free_port)
    credentials = reuse_or_create(
        tmp_path / "credentials.json", sleeve_id=SLEEVE, mqtt_url="mqtt://x:1", ws_url="ws://x:2"
    )
    try:
        with NatsCluster(tmp_path / "nats", credentials) as running:
            assert port not in {p for n in running.nodes for p in (n.client_port, n.mqtt_port)}
            logs = (tmp_path / "nats" / "a.log").read_text(errors="replace")
            assert "address already in use" in logs  # the first start met the taken port
            stop_loop(client(running.nodes[0].mqtt_url, credentials.sender))
    finally:
        taken.close()
