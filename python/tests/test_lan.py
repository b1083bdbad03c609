"""Off loopback with TLS, against real processes: a broker on a LAN address, a sleeve
joined with a token from another network namespace, the refusals that keep passwords
and topics private."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from lan import Lan, lan
from sleeve_watch import connected_client, subscribe

from feelmysign.broker import Broker
from feelmysign.broker.tls import LanOptions, ensure_local_ca
from feelmysign.connection import BrokerConnectionError, BrokerSettings, new_client
from feelmysign.connection.join_token import JoinToken, decode_join_token
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import CLOCK_TOPIC, strokes_topic, telemetry_topic

WAIT_S = 30.0

pytestmark = pytest.mark.broker


@pytest.fixture(scope="module")
def network() -> Iterator[Lan]:
    with lan() as setup:
        yield setup


@pytest.fixture
def lan_broker(tmp_path: Path, network: Lan) -> Iterator[Broker]:
    broker = Broker(
        state_dir=tmp_path / "state",
        port=0,
        ws_port=0,
        lan=LanOptions(host=network.host_address, port=0),
    )
    with broker:
        yield broker


def feelmysign(*args: str, prefix: list[str] | None = None, **kwargs: Any) -> list[str]:
    return [*(prefix or []), sys.executable, "-m", "feelmysign", *args]


def add_sleeve(broker: Broker, sleeve_id: str) -> str:
    result = subprocess.run(
        feelmysign("broker", "--state-dir", str(broker.state_dir), "add-sleeve", sleeve_id),
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        check=True,
    )
    return result.stdout.strip()


def tls_client(broker: Broker, username: str, password: str) -> mqtt.Client:
    """A client on the broker's TLS listener, trusting its local CA."""
    assert broker.lan is not None and broker.tls is not None and broker.tls.ca is not None
    settings = BrokerSettings(
        broker.lan.host,
        broker.lan.port,
        tls=True,
        username=username,
        password=password,
        ca_file=str(broker.tls.ca),
    )
    return connected_client(settings, wait_s=WAIT_S)


def test_a_sleeve_joined_by_token_plays_strokes_over_tls(
    lan_broker: Broker, network: Lan, tmp_path: Path
) -> None:
    token = add_sleeve(lan_broker, "arm2")
    assert decode_join_token(token).url == f"mqtts://{network.host_address}:{lan_broker.lan.port}"  # type: ignore[union-attr]
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "pi-state")}
    sleeve = subprocess.Popen(
        feelmysign("sleeve", "--join", token, prefix=network.run_prefix),
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    c = lan_broker.credentials
    sender = tls_client(lan_broker, c.sender.username, c.sender.password)
    try:
        statuses = subscribe(sender, telemetry_topic("arm2", "status"))
        _topic, payload = statuses.get(timeout=WAIT_S)
        assert json.loads(payload)["online"] is True
        events = subscribe(sender, telemetry_topic("arm2", "events"))
        for seq in range(3):
            stroke = Stroke((0.0, 0.0), (1.0, 0.0), 400.0, 0.8, "lan-drawing", seq)
            sender.publish(strokes_topic("arm2"), format_json(stroke), qos=1).wait_for_publish(5)
        played = [json.loads(events.get(timeout=WAIT_S)[1]) for _ in range(3)]
        assert [(e["type"], e["seq"]) for e in played] == [
            ("played", 0),
            ("played", 1),
            ("played", 2),
        ]
    finally:
        sender.loop_stop()
        sleeve.terminate()
        output = sleeve.communicate(timeout=WAIT_S)[0]
    assert f"mqtts://{network.host_address}" in output
    trusted = list((tmp_path / "pi-state" / "feelmysign" / "trusted").iterdir())
    assert [p.read_text() for p in trusted] == [lan_broker.tls.ca.read_text()]  # type: ignore[union-attr]


@pytest.mark.parametrize("given", ["option", "environment"])
def test_a_token_for_another_ca_is_refused_before_any_login(
    lan_broker: Broker, network: Lan, tmp_path: Path, given: str
) -> None:
    other_ca = ensure_local_ca(tmp_path / "other-tls", ["example.invalid"])
    genuine = decode_join_token(add_sleeve(lan_broker, "arm2"))
    forged = JoinToken(
        genuine.url, "arm2", genuine.username, genuine.password, other_ca.ca_fingerprint
    ).encode()
    # The systemd unit passes the token as FEELMYSIGN_JOIN (in sleeve.env).
    options = ("--join", forged) if given == "option" else ()
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "pi-state")}
    if given == "environment":
        env["FEELMYSIGN_JOIN"] = forged
    result = subprocess.run(
        feelmysign("sleeve", *options, prefix=network.run_prefix),
        env=env,
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert result.returncode == 1, result.stdout + result.stderr
    assert "does not show the certificate authority of the join token" in result.stderr
    assert "Traceback" not in result.stderr
    assert "sleeve-arm2" not in lan_broker.log_path.read_text()  # no login was attempted


def test_a_client_trusting_another_ca_fails_the_handshake(
    lan_broker: Broker, tmp_path: Path
) -> None:
    other_ca = ensure_local_ca(tmp_path / "other-tls", [lan_broker.lan.host])  # type: ignore[union-attr]
    settings = BrokerSettings(
        lan_broker.lan.host,  # type: ignore[union-attr]
        lan_broker.lan.port,  # type: ignore[union-attr]
        tls=True,
        username="sender",
        password=lan_broker.credentials.sender.password,
        ca_file=str(other_ca.ca),
    )
    client = new_client(settings, client_id="wrong-ca")
    with pytest.raises(ssl_error_types()) as caught:
        client.connect(settings.host, settings.port)
    assert "CERTIFICATE_VERIFY_FAILED" in str(caught.value)


def ssl_error_types() -> tuple[type[BaseException], ...]:
    import ssl

    return (ssl.SSLCertVerificationError,)


def test_a_plain_text_login_off_loopback_is_refused(lan_broker: Broker, network: Lan) -> None:
    host, tls_port = lan_broker.lan.host, lan_broker.lan.port  # type: ignore[union-attr]
    c = lan_broker.credentials
    # Our clients refuse to send it.
    result = subprocess.run(
        feelmysign(
            "send",
            "--shape",
            "line",
            "--broker",
            f"mqtt://{host}:{tls_port}",
            "--username",
            "sender",
            "--password",
            c.sender.password,
            prefix=network.run_prefix,
        ),
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert result.returncode == 1
    assert result.stderr.startswith("Error: Refusing to send the password for 'sender' in clear")
    with pytest.raises(BrokerConnectionError) as refused:
        new_client(BrokerSettings(host, tls_port, username="sender", password="x"))
    assert refused.value.reason == "plain-text"
    # The broker has no clear-text listener off loopback: its loopback ports are closed
    # there, and its TLS port answers a clear-text CONNECT with no CONNACK.
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection((host, c.mqtt_port), timeout=5).close()
    assert mqtt_connack_in_clear(host, tls_port, "sender", c.sender.password) is None


def mqtt_connack_in_clear(host: str, port: int, username: str, password: str) -> bytes | None:
    """Send an MQTT 3.1.1 CONNECT without TLS; the CONNACK bytes, or None if none came."""
    payload = b"".join(
        len(part).to_bytes(2, "big") + part
        for part in (b"clear-text-probe", username.encode(), password.encode())
    )
    variable = b"\x00\x04MQTT\x04\xc2\x00\x3c"
    body = variable + payload
    packet = b"\x10" + bytes([len(body)]) + body
    with socket.create_connection((host, port), timeout=5) as raw:
        raw.sendall(packet)
        try:
            answer = raw.recv(4)
        except (ConnectionResetError, TimeoutError):
            return None
    return answer if answer.startswith(b"\x20") else None


def test_a_second_sleeve_s_topics_are_not_readable_with_the_first_s_login(
    lan_broker: Broker,
) -> None:
    second = decode_join_token(add_sleeve(lan_broker, "arm2"))
    c = lan_broker.credentials
    first_sleeve = tls_client(lan_broker, c.sleeve.username, c.sleeve.password)
    second_sleeve = tls_client(lan_broker, second.username, second.password)
    sender = tls_client(lan_broker, c.sender.username, c.sender.password)
    try:
        # One publisher's messages reach a subscriber in order: the first sleeve's own
        # stroke, sent after the second's, arrives only after anything it could read of it.
        first_inbox = subscribe(first_sleeve, "feelmysign/#")
        second_inbox = subscribe(second_sleeve, strokes_topic("arm2"))
        private = format_json(Stroke((0.0, 0.0), (1.0, 1.0), 100.0, 0.5, "private", 0))
        own = format_json(Stroke((1.0, 1.0), (2.0, 1.0), 100.0, 0.5, "own", 0))
        sender.publish(strokes_topic("arm2"), private, qos=1).wait_for_publish(5)
        sender.publish(strokes_topic(c.sleeve_id), own, qos=1).wait_for_publish(5)
        assert second_inbox.get(timeout=WAIT_S) == (strokes_topic("arm2"), private.encode())
        # The broker's clock (retained, readable by every sleeve) may come first.
        first = first_inbox.get(timeout=WAIT_S)
        if first[0] == CLOCK_TOPIC:
            first = first_inbox.get(timeout=WAIT_S)
        assert first == (strokes_topic(c.sleeve_id), own.encode())
        # Nor can the second sleeve write the first one's telemetry (same ordering argument).
        watcher = subscribe(sender, telemetry_topic("+", "status"))
        second_sleeve.publish(telemetry_topic(c.sleeve_id, "status"), b"forged", qos=1)
        second_sleeve.publish(telemetry_topic("arm2", "status"), b"genuine", qos=1)
        assert watcher.get(timeout=WAIT_S) == (telemetry_topic("arm2", "status"), b"genuine")
    finally:
        for client in (first_sleeve, second_sleeve, sender):
            client.loop_stop()


def add_sender(broker: Broker, *options: str) -> str:
    result = subprocess.run(
        feelmysign("broker", "--state-dir", str(broker.state_dir), "add-sender", *options),
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        check=True,
    )
    assert "feelmysign send --join TOKEN" in result.stderr, result.stderr
    return result.stdout.strip()


@pytest.fixture
def local_sleeve(lan_broker: Broker) -> Iterator[subprocess.Popen[str]]:
    """The sleeve of the broker's machine (sim, 2 rows x 6 columns), online."""
    sleeve = subprocess.Popen(
        feelmysign(
            "sleeve",
            *("--credentials", str(lan_broker.credentials_path), "--no-legacy"),
            *("--rows", "2", "--columns", "6", "--spacing-cm", "2.5"),
        ),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    c = lan_broker.credentials
    watcher = tls_client(lan_broker, c.sender.username, c.sender.password)
    try:
        statuses = subscribe(watcher, telemetry_topic(c.sleeve_id, "status"))
        while not json.loads(statuses.get(timeout=WAIT_S)[1])["online"]:
            pass
        yield sleeve
    finally:
        watcher.loop_stop()
        sleeve.terminate()
        sleeve.wait(WAIT_S)


def test_a_sender_joined_by_token_sends_over_tls_and_hears_the_sleeve(
    lan_broker: Broker, network: Lan, tmp_path: Path, local_sleeve: subprocess.Popen[str]
) -> None:
    token = add_sender(lan_broker)
    assert decode_join_token(token).role == "sender"
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "laptop-state")}
    env = {k: v for k, v in env.items() if not k.startswith("FEELMYSIGN_")}
    sent = subprocess.run(
        feelmysign(
            "send",
            "--join",
            token,
            "--shape",
            "heart",
            "--segments",
            "12",
            prefix=network.run_prefix,
        ),
        env=env,
        capture_output=True,
        text=True,
        timeout=WAIT_S * 2,
    )
    assert sent.returncode == 0, sent.stdout + sent.stderr
    # (strokes that queued on a loaded machine are said in brackets: played faster)
    assert "The sleeve played 12 of 12 strokes" in sent.stdout, sent.stdout
    trusted = list((tmp_path / "laptop-state" / "feelmysign" / "trusted").iterdir())
    assert [p.read_text() for p in trusted] == [lan_broker.tls.ca.read_text()]  # type: ignore[union-attr]


def test_a_sender_token_does_not_make_a_sleeve(lan_broker: Broker, tmp_path: Path) -> None:
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "pi-state")}
    result = subprocess.run(
        feelmysign("sleeve", "--join", add_sender(lan_broker)),
        env=env,
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert result.returncode == 1, result.stdout + result.stderr
    assert "a sender's (from 'feelmysign broker add-sender')" in result.stderr, result.stderr
    assert "add-sleeve ID" in result.stderr


def test_a_sender_with_the_broker_s_ca_file_sends_over_tls(
    lan_broker: Broker, network: Lan, tmp_path: Path, local_sleeve: subprocess.Popen[str]
) -> None:
    assert lan_broker.lan is not None and lan_broker.tls is not None
    ca = tmp_path / "copied-ca.pem"
    ca.write_text(lan_broker.tls.ca.read_text())  # type: ignore[union-attr]
    url = f"mqtts://{network.host_address}:{lan_broker.lan.port}"
    c = lan_broker.credentials
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    env["FEELMYSIGN_PASSWORD"] = c.sender.password
    base = ["send", "--broker", url, "--username", c.sender.username, "0,0,5,1,400", "--wait"]
    without = subprocess.run(
        feelmysign(*base, prefix=network.run_prefix),
        env=env,
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert without.returncode == 1, without.stdout + without.stderr
    assert "this machine does not trust it" in without.stderr, without.stderr
    assert "--ca FILE" in without.stderr and "Traceback" not in without.stderr
    sent = subprocess.run(
        feelmysign(*base, "--ca", str(ca), prefix=network.run_prefix),
        env=env,
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert sent.returncode == 0, sent.stdout + sent.stderr
    assert "The sleeve played 1 of 1 strokes." in sent.stdout, sent.stdout
