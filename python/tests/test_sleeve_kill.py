"""``kill -9`` of a real sleeve mid-stroke, then a restart: every motor it can reach is off.

The sleeve runs as its own process (``feelmysign sleeve --backend drv2605
--emulate-state FILE``) against a real Mosquitto. The state file is the
chips' registers, which outlive the process as real chips' do, so the test
sees what a crash leaves on the skin and what the restart does about it.
Timings are not asserted (``make bench`` reports the restart-to-all-off time);
the order is: the restarted sleeve switches every motor off before it says it
is online, and before it would refuse to start for a missing chip.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt
import pytest

from feelmysign.backends.emulated_state import drive_levels
from feelmysign.broker import Broker
from feelmysign.connection import BrokerSettings, new_client
from feelmysign.daemon import sleeve_client_id
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

REPO = Path(__file__).resolve().parents[2]
PAPER = str(REPO / "deploy" / "layouts" / "paper-sleeve.toml")
WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly
LONG_STROKE = Stroke((0.0, 1.0), (3.0, 1.0), 8000.0, 0.9, "kill", 0)  # row 1, 8 s


def sleeve_command(broker: Broker, state: Path) -> list[str]:
    return [
        sys.executable,
        "-m",
        "feelmysign",
        "sleeve",
        "--backend",
        "drv2605",
        "--emulate-state",
        str(state),
        "--layout",
        PAPER,
        "--credentials",
        str(broker.credentials_path),
        "--no-legacy",
    ]


def start_sleeve(broker: Broker, state: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        sleeve_command(broker, state),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


class Watcher:
    """The sleeve's retained status and its events, as a sender sees them."""

    def __init__(self, broker: Broker) -> None:
        c = broker.credentials
        settings = BrokerSettings(
            c.mqtt_host, c.mqtt_port, username=c.sender.username, password=c.sender.password
        )
        self.client = new_client(settings, client_id=f"watch-{uuid.uuid4()}")
        self.messages: list[tuple[str, dict[str, Any]]] = []
        self._changed = threading.Condition()
        sid = c.sleeve_id
        self.client.on_connect = lambda client, *_: client.subscribe(
            [(telemetry_topic(sid, "status"), 1), (telemetry_topic(sid, "events"), 1)]
        )
        self.client.on_message = self._on_message
        self.client.connect(c.mqtt_host, c.mqtt_port)
        self.client.loop_start()
        self.sleeve_id = sid

    def _on_message(self, client: mqtt.Client, userdata: Any, message: mqtt.MQTTMessage) -> None:
        with self._changed:
            name = message.topic.rsplit("/", 1)[-1]
            self.messages.append((name, json.loads(message.payload)))
            self._changed.notify_all()

    def wait_for(self, check: Callable[[str, dict[str, Any]], bool]) -> dict[str, Any]:
        with self._changed:
            found: list[dict[str, Any]] = []

            def seen() -> bool:
                found.extend(body for name, body in self.messages if check(name, body))
                self.messages.clear()
                return bool(found)

            assert self._changed.wait_for(seen, WAIT_S), "the sleeve never said it"
            return found[0]

    def send(self, stroke: Stroke) -> None:
        self.client.publish(strokes_topic(self.sleeve_id), format_json(stroke), qos=1)

    def close(self) -> None:
        self.client.loop_stop()
        self.client.disconnect()


@pytest.fixture
def watcher(broker: Broker) -> Iterator[Watcher]:
    watching = Watcher(broker)
    yield watching
    watching.close()


def online(name: str, body: dict[str, Any]) -> bool:
    return name == "status" and body.get("online") is True


def wait_until(condition: Callable[[], bool]) -> None:
    event = threading.Event()
    for _ in range(int(WAIT_S / 0.005)):
        if condition():
            return
        event.wait(0.005)
    raise AssertionError("the state file never got there")


def kill_mid_stroke(broker: Broker, watcher: Watcher, state: Path) -> dict[str, float]:
    """Start a sleeve, send it a long stroke, SIGKILL it while a motor is on; what it left."""
    sleeve = start_sleeve(broker, state)
    try:
        watcher.wait_for(online)
        watcher.send(LONG_STROKE)
        wait_until(lambda: any(level > 0 for level in drive_levels(state).values()))
        sleeve.send_signal(signal.SIGKILL)
        assert sleeve.wait(WAIT_S) == -signal.SIGKILL
    finally:
        sleeve.kill()
        sleeve.wait(WAIT_S)
    left = drive_levels(state)
    # Nothing ran after SIGKILL: the chips still drive what they drove. Without
    # this the rest of the test would prove nothing.
    assert any(level > 0 for level in left.values()), left
    return left


def forget_sleeve_session(broker: Broker) -> None:
    """Drop the killed sleeve's session: the stroke cut by the kill was never acknowledged,
    so the broker would deliver it again at once (docs/protocol.md, Delivery) and drive a
    motor right after the restart; here only what comes before going online counts."""
    c = broker.credentials
    settings = BrokerSettings(
        c.mqtt_host, c.mqtt_port, username=c.sleeve.username, password=c.sleeve.password
    )
    client_id = sleeve_client_id(c.sleeve_id, c.sleeve.password)
    client = new_client(settings, client_id=client_id)  # a clean session replaces it
    connected = threading.Event()
    client.on_connect = lambda *args: connected.set()
    client.connect(c.mqtt_host, c.mqtt_port)
    client.loop_start()
    assert connected.wait(WAIT_S)
    client.disconnect()
    client.loop_stop()


def test_a_restart_after_sigkill_mid_stroke_switches_every_motor_off_before_going_online(
    broker: Broker, watcher: Watcher, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    kill_mid_stroke(broker, watcher, state)
    forget_sleeve_session(broker)

    restarted = start_sleeve(broker, state)
    try:
        status = watcher.wait_for(online)
        # Online is said only after the backend opened, so the off came first.
        assert status["backend"] == "drv2605 (emulated bus)"
        assert set(drive_levels(state).values()) == {0.0}
        # And the restarted sleeve plays again.
        watcher.send(Stroke((0.0, 0.0), (3.0, 0.0), 300.0, 0.9, "after", 0))
        # (The stroke cut by the kill was never acknowledged: the broker may deliver it again.)
        played = watcher.wait_for(
            lambda name, body: body.get("type") == "played" and body.get("drawing") == "after"
        )
        assert played["seq"] == 0
        restarted.send_signal(signal.SIGTERM)
        assert restarted.wait(WAIT_S) == 0
    finally:
        restarted.kill()
        restarted.wait(WAIT_S)
    assert set(drive_levels(state).values()) == {0.0}


@pytest.mark.parametrize("fault", ["missing", "wrong_id"])
def test_a_restart_with_one_bad_chip_refuses_to_start_but_switches_the_others_off(
    broker: Broker, watcher: Watcher, tmp_path: Path, fault: str
) -> None:
    state = tmp_path / "bus.json"
    left = kill_mid_stroke(broker, watcher, state)
    # A chip that is off fails (the one that plays could not be reached by anyone).
    bad = next(key for key, level in sorted(left.items()) if level == 0.0)
    saved = json.loads(state.read_text())
    if fault == "missing":
        del saved["chips"][bad]
    else:
        saved["chips"][bad]["device_id"] = 4  # a DRV2604
    state.write_text(json.dumps(saved))
    before = drive_levels(state)
    assert any(level > 0 for level in before.values())

    restarted = subprocess.run(
        sleeve_command(broker, state), capture_output=True, text=True, timeout=WAIT_S
    )
    assert restarted.returncode == 1
    multiplexer, channel = bad.split("/")
    assert f"multiplexer {multiplexer} channel {channel}" in restarted.stderr
    assert restarted.stderr.startswith("Error: ")
    assert "Traceback" not in restarted.stderr
    assert set(drive_levels(state).values()) == {0.0}
    # The same again, as systemd would restart it: still off, still the same error.
    again = subprocess.run(
        sleeve_command(broker, state), capture_output=True, text=True, timeout=WAIT_S
    )
    assert (again.returncode, again.stderr) == (1, restarted.stderr)
    assert set(drive_levels(state).values()) == {0.0}
