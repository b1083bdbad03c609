"""The local broker against a real Mosquitto over real connections.

Every wait is on an event (an acknowledgement, a message, a process exit) with a
timeout, never a fixed sleep. Absence of a message is shown with a marker: a
message sent after the forbidden one, on the same path, must arrive first.
Each test runs its own broker (the ``broker`` fixture), so topics never mix.
"""

from __future__ import annotations

import base64
import ipaddress
import json
import os
import queue
import re
import select
import signal
import socket
import stat
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import IO, Any, Literal, Protocol

import paho.mqtt.client as mqtt
import pytest
from paho.mqtt.enums import CallbackAPIVersion
from paho.mqtt.reasoncodes import ReasonCode

from feelmysign.broker import (
    Account,
    Broker,
    BrokerError,
    Credentials,
    find_mosquitto,
    hash_password,
    load_credentials,
)
from feelmysign.broker.credentials import new_password
from feelmysign.connection import probe_login

pytestmark = pytest.mark.broker

WAIT_S = 10.0
NOT_AUTHORIZED = 135  # MQTT 5 reason code, what Mosquitto 2.0 answers to a denied publish or login
PACKET_TOO_LARGE = 149  # MQTT 5 reason code of the DISCONNECT for an oversized packet
STROKE = b'{"v":1,"drawing":"d1","seq":0,"start":[0,0],"end":[3,2],"duration_ms":400,"intensity":1}'
FEELMYSIGN = Path(sys.executable).with_name("feelmysign")
Transport = Literal["tcp", "websockets"]
StartBroker = Callable[..., Broker]  # the `start_broker` fixture of conftest.py


class _Acks:
    """Acknowledgements by message id; an ack may arrive before its id is known here."""

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._by_mid: dict[int, list[ReasonCode]] = {}

    def put(self, mid: int, codes: list[ReasonCode]) -> None:
        with self._condition:
            self._by_mid[mid] = codes
            self._condition.notify_all()

    def wait(self, mid: int) -> list[ReasonCode]:
        with self._condition:
            if not self._condition.wait_for(lambda: mid in self._by_mid, WAIT_S):
                raise AssertionError(f"no acknowledgement for message id {mid} within {WAIT_S} s")
            return self._by_mid.pop(mid)


class Client:
    """An MQTT 5 client for tests: every call waits for the broker's answer."""

    def __init__(self, account: Account | None, port: int, *, transport: Transport = "tcp") -> None:
        self.connacks: queue.Queue[ReasonCode] = queue.Queue()
        self.disconnects: queue.Queue[ReasonCode] = queue.Queue()
        self.messages: queue.Queue[mqtt.MQTTMessage] = queue.Queue()
        self._acks = _Acks()
        self.paho = mqtt.Client(
            CallbackAPIVersion.VERSION2, protocol=mqtt.MQTTv5, transport=transport
        )
        if account is not None:
            self.paho.username_pw_set(account.username, account.password)
        self.paho.on_connect = lambda _c, _u, _f, code, _p: self.connacks.put(code)
        self.paho.on_disconnect = lambda _c, _u, _f, code, _p: self.disconnects.put(code)
        self.paho.on_message = lambda _c, _u, message: self.messages.put(message)
        self.paho.on_subscribe = lambda _c, _u, mid, codes, _p: self._acks.put(mid, codes)
        self.paho.on_publish = lambda _c, _u, mid, code, _p: self._acks.put(mid, [code])
        self.paho.connect("127.0.0.1", port)
        self.paho.loop_start()

    def connack(self) -> ReasonCode:
        return self.connacks.get(timeout=WAIT_S)

    def subscribe(self, topic: str) -> ReasonCode:
        _result, mid = self.paho.subscribe(topic, qos=1)
        assert mid is not None
        return self._acks.wait(mid)[0]

    def publish(self, topic: str, payload: bytes, *, retain: bool = False) -> ReasonCode:
        info = self.paho.publish(topic, payload, qos=1, retain=retain)
        return self._acks.wait(info.mid)[0]

    def next_message(self) -> mqtt.MQTTMessage:
        return self.messages.get(timeout=WAIT_S)

    def close(self) -> None:
        self.paho.disconnect()
        self.paho.loop_stop()


class Connect(Protocol):
    def __call__(self, who: str, *, transport: Transport = "tcp") -> Client: ...


@pytest.fixture
def connect(broker: Broker) -> Iterator[Connect]:
    """``connect("sleeve" or "sender", transport=...)``: a logged-in client, closed at the end."""
    clients: list[Client] = []

    def make(who: str, *, transport: Transport = "tcp") -> Client:
        credentials = broker.credentials
        account = credentials.sleeve if who == "sleeve" else credentials.sender
        port = credentials.ws_port if transport == "websockets" else credentials.mqtt_port
        client = Client(account, port, transport=transport)
        clients.append(client)
        code = client.connack()
        assert not code.is_failure, f"{who} login refused: {code}"
        return client

    yield make
    for client in clients:
        client.close()


def strokes_topic(credentials: Credentials) -> str:
    return f"feelmysign/{credentials.sleeve_id}/strokes"


def status_topic(credentials: Credentials) -> str:
    return f"feelmysign/{credentials.sleeve_id}/status"


def process_gone(pid: int, *, timeout_s: float = WAIT_S) -> bool:
    """Wait for ``pid`` to exit (a pidfd becomes readable then); True once it has."""
    try:
        descriptor = os.pidfd_open(pid)
    except ProcessLookupError:
        return True
    try:
        readable, _, _ = select.select([descriptor], [], [], timeout_s)
        return bool(readable)
    finally:
        os.close(descriptor)


def listening_addresses(port: int) -> set[ipaddress.IPv4Address | ipaddress.IPv6Address]:
    """Addresses with a listening TCP socket on ``port``, from /proc/net/tcp and tcp6."""
    found: set[ipaddress.IPv4Address | ipaddress.IPv6Address] = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            local, state = line.split()[1], line.split()[3]
            address_hex, port_hex = local.split(":")
            if state != "0A" or int(port_hex, 16) != port:  # 0A: LISTEN
                continue
            # The kernel prints each 32-bit word in host (little-endian) order.
            words = [
                bytes.fromhex(address_hex[i : i + 8])[::-1] for i in range(0, len(address_hex), 8)
            ]
            found.add(ipaddress.ip_address(b"".join(words)))
    return found


def is_loopback(address: ipaddress.IPv4Address | ipaddress.IPv6Address) -> bool:
    mapped = getattr(address, "ipv4_mapped", None)
    return address.is_loopback or (mapped is not None and mapped.is_loopback)


# --- start and stop ---------------------------------------------------------------------


def test_starts_and_stops_leaving_no_process(tmp_path: Path) -> None:
    broker = Broker(state_dir=tmp_path, port=0, ws_port=0)
    with broker:
        pid = broker.pid
        assert pid is not None and broker.running
        client = Client(broker.credentials.sender, broker.credentials.mqtt_port)
        assert client.connack() == 0
        client.close()
    assert not broker.running
    assert process_gone(pid, timeout_s=0)
    with pytest.raises(BrokerError) as caught:
        _ = broker.credentials
    assert caught.value.reason == "not-running"


@pytest.mark.skipif(not hasattr(os, "pidfd_open"), reason="needs Linux pidfds")
def test_mosquitto_dies_with_a_killed_parent(tmp_path: Path) -> None:
    script = f"""
        import time
        from feelmysign.broker import Broker
        broker = Broker(state_dir={str(tmp_path)!r}, port=0, ws_port=0)
        broker.start()
        print(broker.pid, flush=True)
        time.sleep(60)
    """
    parent = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(script)], stdout=subprocess.PIPE, text=True
    )
    assert parent.stdout is not None
    mosquitto_pid = int(parent.stdout.readline())
    parent.kill()  # SIGKILL: no atexit, no handler; only the kernel can clean up
    parent.wait(timeout=WAIT_S)
    assert process_gone(mosquitto_pid)


def test_listeners_are_on_loopback_only(broker: Broker) -> None:
    if not Path("/proc/net/tcp").exists():
        pytest.skip("needs Linux /proc/net/tcp")
    for port in (broker.credentials.mqtt_port, broker.credentials.ws_port):
        addresses = listening_addresses(port)
        assert addresses, f"nothing listens on port {port}"
        assert all(is_loopback(a) for a in addresses), f"port {port} listens on {addresses}"


# --- messages and the ACL ---------------------------------------------------------------


def test_sender_strokes_reach_the_sleeve(broker: Broker, connect: Connect) -> None:
    sleeve, sender = connect("sleeve"), connect("sender")
    assert sleeve.subscribe(strokes_topic(broker.credentials)) == 1
    assert sender.publish(strokes_topic(broker.credentials), STROKE) == 0
    message = sleeve.next_message()
    assert (message.topic, message.payload) == (strokes_topic(broker.credentials), STROKE)


def test_legacy_topic_reaches_the_sleeve(connect: Connect) -> None:
    sleeve, sender = connect("sleeve"), connect("sender")
    sleeve.subscribe("deviceOne/line")
    assert sender.publish("deviceOne/line", b"0,0,3,2,400") == 0
    assert sleeve.next_message().payload == b"0,0,3,2,400"


def test_sleeve_telemetry_reaches_the_sender(broker: Broker, connect: Connect) -> None:
    sleeve, sender = connect("sleeve"), connect("sender")
    for subtopic in ("status", "actuators", "events"):
        topic = f"feelmysign/{broker.credentials.sleeve_id}/{subtopic}"
        sender.subscribe(topic)
        assert sleeve.publish(topic, b'{"online":true}') == 0
        assert sender.next_message().topic == topic


@pytest.mark.parametrize(
    ("forger", "owner", "topic_of", "forged"),
    [
        ("sleeve", "sender", strokes_topic, b"forged"),
        ("sender", "sleeve", status_topic, b'{"online":true}'),
    ],
    ids=["sleeve-cannot-publish-strokes", "sender-cannot-publish-status"],
)
def test_only_the_owner_of_a_topic_publishes_on_it(
    broker: Broker,
    connect: Connect,
    forger: str,
    owner: str,
    topic_of: Callable[[Credentials], str],
    forged: bytes,
) -> None:
    clients = {"sleeve": connect("sleeve"), "sender": connect("sender")}
    topic = topic_of(broker.credentials)
    clients[forger].subscribe(topic)
    assert clients[forger].publish(topic, forged) == NOT_AUTHORIZED
    # The owner's message after it arrives, the forged one never did.
    clients[owner].publish(topic, b"marker")
    assert clients[forger].next_message().payload == b"marker"


def test_sleeve_cannot_read_another_sleeves_strokes(broker: Broker, connect: Connect) -> None:
    sleeve, sender = connect("sleeve"), connect("sender")
    # Mosquitto 2.0 grants any subscription and filters on delivery, so subscribe widely.
    sleeve.subscribe("feelmysign/+/strokes")
    assert sender.publish("feelmysign/other-sleeve/strokes", STROKE) == 0
    sender.publish(strokes_topic(broker.credentials), b"marker")
    assert sleeve.next_message().payload == b"marker"


def test_sender_cannot_read_strokes(broker: Broker, connect: Connect) -> None:
    sender = connect("sender")
    sender.subscribe("feelmysign/#")
    sender.publish(strokes_topic(broker.credentials), STROKE)
    connect("sleeve").publish(status_topic(broker.credentials), b"marker")
    assert sender.next_message().payload == b"marker"


@pytest.mark.parametrize(
    "account",
    [Account("sender", "wrong-password"), Account("nobody", "x" * 16), None],
    ids=["wrong-password", "unknown-user", "anonymous"],
)
def test_bad_logins_are_refused(broker: Broker, account: Account | None) -> None:
    client = Client(account, broker.credentials.mqtt_port)
    try:
        assert client.connack() == NOT_AUTHORIZED
    finally:
        client.close()


def test_a_login_probe_tells_accepted_refused_and_nobody_answering(broker: Broker) -> None:
    c = broker.credentials
    sender = c.settings("sender")
    wrong = replace(sender, password="wrong-password")
    nobody = replace(sender, port=free_port())
    answers = [probe_login(s, client_id="probe", timeout_s=WAIT_S) for s in (sender, wrong, nobody)]
    assert answers == [True, False, None]


def test_oversized_packets_are_refused(broker: Broker, connect: Connect) -> None:
    sender = connect("sender")
    sender.paho.publish(strokes_topic(broker.credentials), b"x" * 5000, qos=1)
    assert sender.disconnects.get(timeout=WAIT_S) == PACKET_TOO_LARGE


def test_websocket_listener_carries_mqtt(broker: Broker, connect: Connect) -> None:
    sleeve = connect("sleeve")
    browser = connect("sender", transport="websockets")
    sleeve.subscribe(strokes_topic(broker.credentials))
    assert browser.publish(strokes_topic(broker.credentials), STROKE) == 0
    assert sleeve.next_message().payload == STROKE


# --- state across restarts --------------------------------------------------------------


def test_retained_messages_survive_a_restart(start_broker: StartBroker, tmp_path: Path) -> None:
    first = start_broker(state_dir=tmp_path / "state")
    sleeve = Client(first.credentials.sleeve, first.credentials.mqtt_port)
    sleeve.connack()
    code = sleeve.publish(status_topic(first.credentials), b'{"online":true}', retain=True)
    assert not code.is_failure, code  # "no matching subscribers" (16): kept as retained
    sleeve.close()
    first.stop()

    second = start_broker(state_dir=tmp_path / "state")
    sender = Client(second.credentials.sender, second.credentials.mqtt_port)
    try:
        sender.connack()
        sender.subscribe(status_topic(second.credentials))
        message = sender.next_message()
        assert (message.payload, message.retain) == (b'{"online":true}', True)
    finally:
        sender.close()


def test_the_log_has_no_line_per_save(broker: Broker, connect: Connect) -> None:
    """The broker saves its database after every change (a stroke, a status): its log keeps
    the connections and errors, not a line per save, so a sleeve that runs for weeks does not
    fill its SD card with them."""
    sender = connect("sender")
    sleeve = connect("sleeve")
    database = broker.state_dir / "data" / "mosquitto.db"
    for index in range(5):
        saved_before = database.stat().st_mtime_ns if database.exists() else None
        code = sleeve.publish(status_topic(broker.credentials), b"%d" % index, retain=True)
        assert not code.is_failure, code
        # Each retained message is a change: wait until the database on disk has it.
        deadline_s = time.monotonic() + WAIT_S
        while (database.stat().st_mtime_ns if database.exists() else None) == saved_before:
            assert time.monotonic() < deadline_s, "the broker did not save its database"
            time.sleep(0.02)
    sender.close()
    log = broker.log_path.read_text()
    assert "New client connected" in log, log  # the log is written, with its notices
    assert "Saving in-memory database" not in log, log


def _page_session(credentials: Credentials, client_id: str) -> tuple[mqtt.Client, queue.Queue[Any]]:
    """The page's connection: WebSockets, MQTT 3.1.1, a persistent session under ``client_id``."""
    inbox: queue.Queue[Any] = queue.Queue()
    page = mqtt.Client(
        CallbackAPIVersion.VERSION2,
        client_id=client_id,
        clean_session=False,
        protocol=mqtt.MQTTv311,
        transport="websockets",
    )
    page.username_pw_set(credentials.sender.username, credentials.sender.password)
    page.on_connect = lambda _c, _u, flags, code, _p: inbox.put(("connack", flags.session_present))
    page.on_subscribe = lambda _c, _u, _mid, codes, _p: inbox.put(("suback", codes))
    page.on_message = lambda _c, _u, message: inbox.put(("message", message.payload))
    page.connect("127.0.0.1", credentials.ws_port)
    page.loop_start()
    return page, inbox


def test_a_pages_session_keeps_the_sleeves_events_across_a_restart_and_expires(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    first = start_broker(state_dir=tmp_path / "state")
    events = f"feelmysign/{first.credentials.sleeve_id}/events"
    page, inbox = _page_session(first.credentials, "feelmysign-web-test")
    assert inbox.get(timeout=WAIT_S) == ("connack", False)
    page.subscribe(events, qos=1)
    kind, codes = inbox.get(timeout=WAIT_S)
    assert kind == "suback" and [code.value for code in codes] == [1], codes
    page.disconnect()
    page.loop_stop()
    first.stop()

    # The broker comes back from its saved state; the sleeve's event comes before the page.
    second = start_broker(state_dir=tmp_path / "state")
    sleeve = Client(second.credentials.sleeve, second.credentials.mqtt_port)
    sleeve.connack()
    try:
        assert not sleeve.publish(events, b'{"type":"played","seq":3}').is_failure
    finally:
        sleeve.close()
    page, inbox = _page_session(second.credentials, "feelmysign-web-test")
    try:
        assert inbox.get(timeout=WAIT_S) == ("connack", True)
        assert inbox.get(timeout=WAIT_S) == ("message", b'{"type":"played","seq":3}')
    finally:
        page.disconnect()
        page.loop_stop()
    # Each page load leaves a session like this one: the broker drops any not resumed in time.
    config = (tmp_path / "state" / "mosquitto.conf").read_text()
    expirations = re.findall(r"^persistent_client_expiration (\d+)([hdwmy])$", config, re.M)
    assert expirations == [("1", "h")], config


def test_credentials_are_private_and_kept_across_restarts(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    first = start_broker(state_dir=tmp_path / "state")
    before = first.credentials
    for private in (first.credentials_path, first.state_dir / "passwd"):
        assert stat.S_IMODE(private.stat().st_mode) == 0o600, private
    assert load_credentials(first.credentials_path) == before
    first.stop()

    after = start_broker(state_dir=tmp_path / "state").credentials
    assert (after.sleeve, after.sender) == (before.sleeve, before.sender)


def test_a_new_sleeve_id_gets_a_new_sleeve_account(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    first = start_broker(state_dir=tmp_path / "state", sleeve_id="left-arm")
    before = first.credentials
    first.stop()

    after = start_broker(state_dir=tmp_path / "state", sleeve_id="right_arm").credentials
    assert after.sleeve.username == "sleeve-right_arm"
    assert after.sleeve.password != before.sleeve.password
    assert after.sender == before.sender


def test_credentials_file_has_the_documented_shape(broker: Broker) -> None:
    data = json.loads(broker.credentials_path.read_text())
    port, ws_port = broker.credentials.mqtt_port, broker.credentials.ws_port
    assert data["mqtt_url"] == f"mqtt://127.0.0.1:{port}"
    assert data["ws_url"] == f"ws://127.0.0.1:{ws_port}"
    assert data["sleeve"]["id"] == "sleeve1"
    assert data["sleeve"]["username"] == "sleeve-sleeve1"
    assert data["sender"]["username"] == "sender"
    assert len(data["sleeve"]["password"]) >= 32 and len(data["sender"]["password"]) >= 32


def test_a_broken_credentials_file_is_named(tmp_path: Path) -> None:
    path = tmp_path / "credentials.json"
    path.write_text('{"mqtt_url": "mqtt://127.0.0.1:1883"}')
    with pytest.raises(BrokerError, match=r"credentials\.json is not usable") as caught:
        Broker(state_dir=tmp_path, port=0, ws_port=0).start()
    assert caught.value.reason == "credentials-file"


# --- errors a person can act on ---------------------------------------------------------


@pytest.mark.parametrize("which", ["port", "ws_port"])
def test_a_port_in_use_is_named(tmp_path: Path, which: str) -> None:
    with socket.socket() as squatter:
        squatter.bind(("127.0.0.1", 0))
        squatter.listen()
        taken = squatter.getsockname()[1]
        options = {"port": 0, "ws_port": 0, which: taken}
        with pytest.raises(BrokerError, match=f"port {taken} is already in use") as caught:
            Broker(state_dir=tmp_path, **options).start()
    assert (caught.value.reason, caught.value.port) == ("port-in-use", taken)
    assert ("--port" if which == "port" else "--ws-port") in str(caught.value)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def fake_mosquitto(tmp_path: Path, body: str) -> Path:
    """An executable standing in for mosquitto: answers -h like 2.0.11, else runs ``body``."""
    path = tmp_path / "fake-mosquitto"
    path.write_text(
        "#!/bin/sh\n"
        'if [ "$1" = -h ]; then echo "mosquitto version 2.0.11"; exit 3; fi\n'
        f"echo run >> {tmp_path / 'runs'}\n" + body + "\n"
    )
    path.chmod(0o755)
    return path


def test_mosquitto_failing_on_a_taken_port_is_named(tmp_path: Path) -> None:
    fake = fake_mosquitto(tmp_path, 'echo "Error: Address already in use"; exit 1')
    port = free_port()
    with pytest.raises(BrokerError, match=f"port {port} is already in use") as caught:
        Broker(state_dir=tmp_path / "state", port=port, ws_port=0, mosquitto=fake).start()
    assert (caught.value.reason, caught.value.port) == ("port-in-use", port)
    assert (tmp_path / "runs").read_text().count("run") == 1  # a port the user chose: no retry


def test_ports_we_chose_are_chosen_again_when_taken(tmp_path: Path) -> None:
    fake = fake_mosquitto(tmp_path, 'echo "Error: Address already in use"; exit 1')
    with pytest.raises(BrokerError) as caught:
        Broker(state_dir=tmp_path / "state", port=0, ws_port=0, mosquitto=fake).start()
    assert caught.value.reason == "port-in-use"
    assert (tmp_path / "runs").read_text().count("run") == 3


def test_mosquitto_exiting_at_start_up_shows_its_log(tmp_path: Path) -> None:
    fake = fake_mosquitto(tmp_path, 'echo "Error: Unable to open config file."; exit 3')
    with pytest.raises(BrokerError, match=r"(?s)exit code 3.*Unable to open config") as caught:
        Broker(state_dir=tmp_path / "state", port=0, ws_port=0, mosquitto=fake).start()
    assert caught.value.reason == "start-failed"


def test_a_mosquitto_that_never_listens_is_stopped(tmp_path: Path) -> None:
    fake = fake_mosquitto(tmp_path, f"echo $$ > {tmp_path / 'pid'}; exec sleep 60")
    broker = Broker(
        state_dir=tmp_path / "state", port=0, ws_port=0, mosquitto=fake, ready_timeout_s=0.5
    )
    with pytest.raises(BrokerError, match="did not accept connections"):
        broker.start()
    assert process_gone(int((tmp_path / "pid").read_text()), timeout_s=0)


def test_missing_mosquitto_says_how_to_install_it(tmp_path: Path) -> None:
    with pytest.raises(BrokerError, match="sudo apt-get install mosquitto") as caught:
        find_mosquitto(None, [str(tmp_path)])
    assert caught.value.reason == "mosquitto-missing"
    with pytest.raises(BrokerError, match="sudo apt-get install mosquitto"):
        Broker(state_dir=tmp_path, mosquitto=tmp_path / "mosquitto").start()


@pytest.mark.parametrize("sleeve_id", ["", "a/b", "a+", "#", "x" * 65, "arm 1"])
def test_sleeve_ids_that_break_topics_are_refused(sleeve_id: str) -> None:
    with pytest.raises(BrokerError, match="letters, digits") as caught:
        Broker(sleeve_id=sleeve_id)
    assert caught.value.reason == "bad-option"


@pytest.mark.parametrize("topic", ["a/+", "#", "with space", "$SYS/x", ""])
def test_legacy_topics_that_are_not_names_are_refused(topic: str) -> None:
    with pytest.raises(BrokerError, match="Legacy topic") as caught:
        Broker(legacy_topic=topic)
    assert caught.value.reason == "bad-option"


def test_same_port_twice_is_refused() -> None:
    with pytest.raises(BrokerError, match="both 4000"):
        Broker(port=4000, ws_port=4000)


def test_python_hashes_match_mosquitto_passwd(tmp_path: Path) -> None:
    passwords = tmp_path / "passwd"
    passwords.write_text("sender:s3cret-password\n")
    subprocess.run(["mosquitto_passwd", "-U", str(passwords)], check=True)
    line = passwords.read_text().strip()
    salt = line.split("$")[3]
    assert line == "sender:" + hash_password("s3cret-password", salt=base64.b64decode(salt))


# --- the command ------------------------------------------------------------------------


def read_lines(stream: IO[str]) -> queue.Queue[str]:
    """The lines of ``stream`` as they come, so a test can wait for one with a timeout."""
    lines: queue.Queue[str] = queue.Queue()

    def pump() -> None:
        for line in stream:
            lines.put(line)

    threading.Thread(target=pump, daemon=True).start()
    return lines


def wait_for_line(lines: queue.Queue[str], prefix: str) -> list[str]:
    seen: list[str] = []
    while not (seen and seen[-1].startswith(prefix)):
        seen.append(lines.get(timeout=WAIT_S))
    return seen


@pytest.mark.parametrize("stop_signal", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_command_runs_until_interrupted(tmp_path: Path, stop_signal: signal.Signals) -> None:
    command = [str(FEELMYSIGN), "broker", "--state-dir", str(tmp_path), "--port", "0"]
    process = subprocess.Popen(
        [*command, "--ws-port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        assert process.stdout is not None
        lines = read_lines(process.stdout)
        banner = wait_for_line(lines, "Ready.")
        match = re.search(r"pid (\d+)", banner[0])
        assert match is not None, banner
        credentials = load_credentials(tmp_path / "credentials.json")
        assert any(credentials.mqtt_url in line for line in banner)
        assert any(str(tmp_path / "mosquitto.log") in line for line in banner)
        client = Client(credentials.sender, credentials.mqtt_port)
        assert client.connack() == 0
        client.close()

        process.send_signal(stop_signal)
        assert process.wait(timeout=WAIT_S) == 0, process.stderr.read() if process.stderr else ""
        assert process_gone(int(match.group(1)), timeout_s=0)
    finally:
        process.kill()
        process.wait()


def test_command_errors_are_actionable(tmp_path: Path) -> None:
    result = subprocess.run(
        [str(FEELMYSIGN), "broker", "--state-dir", str(tmp_path), "--mosquitto", "/nonexistent"],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert result.returncode == 1
    assert result.stderr.startswith("Error: Mosquitto was not found at /nonexistent")
    assert "sudo apt-get install mosquitto" in result.stderr


def test_command_rejects_a_bad_port_as_usage_error(tmp_path: Path) -> None:
    result = subprocess.run(
        [str(FEELMYSIGN), "broker", "--port", "70000"],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert result.returncode == 2
    assert "70000 is out of range" in result.stderr


def test_generated_passwords_can_follow_password_on_any_command_line() -> None:
    # A password that starts with '-' is read by argparse as an option, so
    # `feelmysign send --password <it>` would fail for about one account in 30.
    passwords = [new_password() for _ in range(2000)]
    assert all(p.isalnum() and p.isascii() for p in passwords)
    assert all(len(p) >= 32 for p in passwords)
    assert len(set(passwords)) == len(passwords)
