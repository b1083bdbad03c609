"""The NATS cluster with TLS on its MQTT and WebSocket listeners and its routes
(deploy/nats/node.conf), its certificate from the project's own CA: a sleeve joins with a
token that pins the CA and plays a stroke sent over wss:// to another node (through the
routes); a client trusting another CA is refused before it sends anything, on both
listeners; the NATS client port takes no password in clear text; a server with a
certificate from another CA cannot join the cluster."""

from __future__ import annotations

import contextlib
import json
import os
import queue
import socket
import ssl
import subprocess
import sys
import time
import urllib.error
import urllib.request
import uuid
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes
from sleeve_watch import connected_client

from feelmysign.broker import _process as process_
from feelmysign.broker.credentials import reuse_or_create
from feelmysign.broker.nats_cluster import NatsCluster, NatsNode, nats_server_path
from feelmysign.broker.tls import TlsFiles, ensure_local_ca
from feelmysign.connection import BrokerSettings, new_client, parse_broker_url
from feelmysign.connection.join_token import JoinToken
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

WAIT_S = 60.0
SLEEVE = "sleeve1"

pytestmark = pytest.mark.broker


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[NatsCluster]:
    state = tmp_path_factory.mktemp("nats-tls")
    credentials = reuse_or_create(
        state / "credentials.json", sleeve_id=SLEEVE, mqtt_url="mqtt://x:1", ws_url="ws://x:2"
    )
    tls = ensure_local_ca(state / "tls", ["127.0.0.1"])
    with NatsCluster(state / "cluster", credentials, tls=tls) as running:
        yield running


def _sender(cluster: NatsCluster, url: str, ca_file: Path | None) -> BrokerSettings:
    sender = cluster.credentials.sender
    settings = parse_broker_url(url, username=sender.username, password=sender.password)
    return replace(settings, ca_file=str(ca_file) if ca_file else None)


def _connect(settings: BrokerSettings) -> tuple[mqtt.Client, queue.Queue[Any]]:
    """A client logged in over TLS (verifying with ``settings.ca_file``), and its messages."""
    client = connected_client(settings, wait_s=WAIT_S)  # the TLS handshake happens here
    received: queue.Queue[Any] = queue.Queue()
    client.on_message = lambda _c, _u, message: received.put(json.loads(message.payload))
    return client, received


def test_the_listeners_speak_only_tls(cluster: NatsCluster) -> None:
    node = cluster.nodes[0]
    assert node.mqtt_url.startswith("mqtts://") and node.ws_url.startswith("wss://")


def test_a_sleeve_joins_the_cluster_over_tls_and_plays_a_stroke_sent_over_wss(
    cluster: NatsCluster, tmp_path: Path
) -> None:
    c = cluster.credentials
    assert cluster.tls is not None and cluster.tls.ca_fingerprint is not None
    # The token carries every node, and the CA's fingerprint instead of its file.
    token = JoinToken(
        ",".join(node.mqtt_url for node in cluster.nodes),
        SLEEVE,
        c.sleeve.username,
        c.sleeve.password,
        cluster.tls.ca_fingerprint,
    ).encode()
    sleeve = subprocess.Popen(
        [sys.executable, "-m", "feelmysign", "sleeve", "--join", token],
        env={**os.environ, "XDG_STATE_HOME": str(tmp_path / "state")},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    # The sender's page would be on node c's WebSocket listener.
    sender, events = _connect(_sender(cluster, cluster.nodes[2].ws_url, cluster.tls.ca))
    try:
        sender.subscribe(telemetry_topic(SLEEVE, "status"), qos=1)
        sender.subscribe(telemetry_topic(SLEEVE, "events"), qos=1)
        while not events.get(timeout=WAIT_S).get("online"):
            pass
        stroke = Stroke((0.0, 1.0), (2.0, 1.0), 300.0, 0.5, str(uuid.uuid4()), 0)
        sender.publish(strokes_topic(SLEEVE), format_json(stroke), qos=1)
        while (event := events.get(timeout=WAIT_S)).get("drawing") != stroke.drawing:
            pass
        assert event["type"] == "played", event
    finally:
        sender.loop_stop()
        sleeve.terminate()
        out = sleeve.communicate(timeout=WAIT_S)[0]
    assert f"connected to {cluster.nodes[0].mqtt_url}" in out, out


@pytest.mark.parametrize("listener", ["mqtts", "wss"])
def test_a_client_trusting_another_ca_is_refused_before_it_logs_in(
    cluster: NatsCluster, tmp_path: Path, listener: str
) -> None:
    other = ensure_local_ca(tmp_path / "other-ca", ["127.0.0.1"])
    node = cluster.nodes[1]
    url = node.mqtt_url if listener == "mqtts" else node.ws_url
    client = new_client(_sender(cluster, url, other.ca), client_id=f"test-{uuid.uuid4()}")
    settings = parse_broker_url(url)
    with pytest.raises(ssl.SSLCertVerificationError):
        client.connect(settings.host, settings.port)
    # The system's trusted CAs do not know the cluster's CA either.
    client = new_client(_sender(cluster, url, None), client_id=f"test-{uuid.uuid4()}")
    with pytest.raises(ssl.SSLCertVerificationError):
        client.connect(settings.host, settings.port)


def _routes(monitor_port: int) -> int:
    """How many routes the server with this monitoring port has (its /routez); -1 while it
    does not listen yet."""
    url = f"http://127.0.0.1:{monitor_port}/routez"
    try:
        with urllib.request.urlopen(url, timeout=10) as reply:
            return int(json.load(reply)["num_routes"])
    except urllib.error.URLError:
        return -1


def _until(condition: Callable[[], bool], what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < deadline, what
        time.sleep(0.2)


def test_a_server_with_a_certificate_from_another_ca_cannot_join_the_cluster(
    cluster: NatsCluster, tmp_path: Path
) -> None:
    assert cluster.tls is not None and cluster.tls.ca is not None
    free = process_.free_port
    # It trusts the cluster's CA (so only the cluster's check of its certificate stands in
    # its way), and presents a certificate for 127.0.0.1 from another CA.
    other = ensure_local_ca(tmp_path / "other-ca", ["127.0.0.1"])
    intruder_tls = replace(other, ca=cluster.tls.ca)
    leaf = x509.load_pem_x509_certificates(other.cert.read_bytes())[0]
    leaf_sha256 = leaf.fingerprint(hashes.SHA256()).hex()
    executable = nats_server_path()
    a, b = cluster.nodes[0], cluster.nodes[1]

    def server(name: str, tls: TlsFiles) -> tuple[subprocess.Popen[bytes], int]:
        # Its five ports are picked free, but another test running beside this one may take
        # one before the server binds it: then it stops at once ("address already in use"),
        # and is started again on other ports, rather than never trying to join at all.
        log = cluster.state_dir / f"{name}.log"
        for _ in range(5):
            node = NatsNode(name, free("127.0.0.1"), free("127.0.0.1"), 0, 0, tls=True)
            node = replace(node, mqtt_port=free("127.0.0.1"), ws_port=free("127.0.0.1"))
            monitor = free("127.0.0.1")
            process = cluster.spawn(executable, node, [a, b], tls, "-m", str(monitor))

            def settled(started: subprocess.Popen[bytes] = process) -> bool:
                return started.poll() is not None or "Server is ready" in log.read_text(
                    errors="replace"
                )

            _until(settled, f"{name} neither started nor stopped")
            if process.poll() is None or "address already in use" not in log.read_text(
                errors="replace"
            ):
                break
        return process, monitor

    def refused_by(node: NatsNode) -> bool:
        log = (cluster.state_dir / f"{node.name}.log").read_text(errors="replace")
        return any(
            "TLS route handshake error" in line and leaf_sha256 in line for line in log.splitlines()
        )

    intruder, intruder_monitor = server("x", intruder_tls)
    try:
        _until(lambda: refused_by(a) and refused_by(b), "a and b never refused the intruder")
        assert _routes(intruder_monitor) == 0
        assert intruder.poll() is None  # it is still trying: refused, not misconfigured
    finally:
        intruder.kill()
        intruder.wait()
    # The same server with the cluster's own certificate joins: the refusal was the CA's.
    member, member_monitor = server("y", cluster.tls)
    try:
        _until(lambda: _routes(member_monitor) >= 2, "a server with the cluster's CA never joined")
    finally:
        member.kill()
        member.wait()


def test_the_nats_client_port_takes_no_password_in_clear_text(cluster: NatsCluster) -> None:
    # Its users are the MQTT accounts: a core NATS client sending its password in the
    # clear would give it away. The server asks for TLS first, and a plain CONNECT gets
    # nothing back but the end of the connection.
    sender = cluster.credentials.sender
    with socket.create_connection(("127.0.0.1", cluster.nodes[0].client_port), WAIT_S) as plain:
        plain.settimeout(WAIT_S)
        reader = plain.makefile("rb")
        info = reader.readline()
        assert info.startswith(b"INFO ") and json.loads(info[5:]).get("tls_required") is True
        login = {"user": sender.username, "pass": sender.password, "verbose": True}
        with contextlib.suppress(OSError):  # the server may close before it reads it all
            plain.sendall(b"CONNECT " + json.dumps(login).encode() + b"\r\nPING\r\n")
        with contextlib.suppress(OSError):
            reply = reader.read()
            assert b"+OK" not in reply and b"PONG" not in reply, reply
