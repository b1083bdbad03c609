"""``feelmysign send`` and the wearer's choice, on real processes: a real Mosquitto,
``feelmysign send`` as its own process (its exit code as a shell sees it), and a client logged
in as the sleeve that publishes its retained status and answers its strokes.

The status carries ``controls`` exactly as docs/protocol.md writes it. A client stands in for
the sleeve so that each test can set any status, including ones a real sleeve would publish only
after a button press or a restart (test_send_held_by_wearer.py runs the real sleeve). Nothing
sent is shown with a marker: a stroke sent afterwards must be the first the sleeve receives.
"""

from __future__ import annotations

import json
import os
import queue
import subprocess
import time
from collections.abc import Iterator
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from sleeve_watch import connected_client, settings, stop_loop

from feelmysign.bench.restart_off import feelmysign_command
from feelmysign.broker import Broker
from feelmysign.cli.send import WEARER_HOLD_EXIT

WAIT_S = 120.0  # generous: a loaded 2-core machine
LAYOUT = {
    "rows": 3,
    "columns": 4,
    "spacing_cm": 3.0,
    "default_intensity": 0.8,
    "max_intensity": 1.0,
}
NOT_PAUSED = {"paused": False, "paused_by": None, "ceiling": None, "do_not_disturb_until_ms": None}
PAUSED = {"paused": True, "paused_by": "button", "ceiling": None, "do_not_disturb_until_ms": None}

pytestmark = pytest.mark.broker


class StandInSleeve:
    """Logged in as the sleeve: publishes its status and answers each stroke with ``answer``."""

    def __init__(self, broker: Broker) -> None:
        credentials = broker.credentials
        self.sleeve_id = credentials.sleeve_id
        self.strokes: queue.Queue[dict[str, Any]] = queue.Queue()
        self.answer: Any = None
        self.client = connected_client(settings(credentials, "sleeve"))
        subscribed: queue.Queue[object] = queue.Queue()
        self.client.on_subscribe = lambda *_: subscribed.put(True)
        self.client.on_message = self._on_stroke
        self.client.subscribe(f"feelmysign/{self.sleeve_id}/strokes", qos=1)
        subscribed.get(timeout=WAIT_S)

    def status(self, controls: dict[str, Any]) -> None:
        status = {
            "online": True,
            "sleeve_id": self.sleeve_id,
            "layout": LAYOUT,
            "at_ms": int(time.time() * 1000),
            "controls": controls,
        }
        self.client.publish(
            f"feelmysign/{self.sleeve_id}/status", json.dumps(status), qos=1, retain=True
        ).wait_for_publish(WAIT_S)

    def _on_stroke(self, _client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        stroke = json.loads(message.payload)
        self.strokes.put(stroke)
        for event in self.answer(stroke) if self.answer else []:
            self.client.publish(f"feelmysign/{self.sleeve_id}/events", json.dumps(event), qos=1)

    def next_stroke(self) -> dict[str, Any]:
        return self.strokes.get(timeout=WAIT_S)

    def close(self) -> None:
        self.client.disconnect()
        stop_loop(self.client)


@pytest.fixture
def sleeve(broker: Broker) -> Iterator[StandInSleeve]:
    stand_in = StandInSleeve(broker)
    try:
        yield stand_in
    finally:
        stand_in.close()


def send(broker: Broker, *argv: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    return subprocess.run(
        [*feelmysign_command(), "send", "--credentials", str(broker.credentials_path), *argv],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        env=env,
        check=False,
    )


def _marker_comes_first(broker: Broker, sleeve: StandInSleeve) -> None:
    """Nothing of an earlier send reached the sleeve: the marker is the first stroke it gets."""
    sleeve.status(NOT_PAUSED)
    marker = send(broker, "2,2,3,2,100", "--no-wait")
    assert marker.returncode == 0, marker.stderr
    assert sleeve.next_stroke()["start"] == [2, 2]


def test_a_paused_sleeve_gets_nothing_and_send_says_so_in_one_line(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    sleeve.status(PAUSED)
    result = send(broker, "0,0,3,2,500", "3,2,0,2,500")
    assert result.returncode == WEARER_HOLD_EXIT, result.stdout + result.stderr
    errors = [line for line in result.stderr.splitlines() if line.startswith("Error:")]
    assert len(errors) == 1, result.stderr
    assert errors[0].startswith("Error: The wearer paused sleeve 'sleeve1'")
    assert "Nothing was sent" in errors[0] and "once the wearer has resumed" in errors[0]
    assert "Traceback" not in result.stderr
    _marker_comes_first(broker, sleeve)


def test_a_sleeve_that_paused_itself_is_not_said_as_the_wearer_s_pause(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    """Started paused because its settings file could not be read (``paused_by: "sleeve"``):
    the sender is not told that the wearer paused it."""
    sleeve.status({**PAUSED, "paused_by": "sleeve"})
    result = send(broker, "0,0,3,2,500")
    assert result.returncode == WEARER_HOLD_EXIT, result.stdout + result.stderr
    errors = [line for line in result.stderr.splitlines() if line.startswith("Error:")]
    assert len(errors) == 1, result.stderr
    assert errors[0].startswith("Error: Sleeve 'sleeve1' paused itself: it could not read"), errors
    assert "The wearer paused" not in result.stderr
    _marker_comes_first(broker, sleeve)


def test_do_not_disturb_names_its_end_and_sends_nothing(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    until_ms = int(time.time() * 1000) + 45 * 60_000
    sleeve.status({**NOT_PAUSED, "do_not_disturb_until_ms": until_ms})
    result = send(broker, "--shape", "square")
    assert result.returncode == WEARER_HOLD_EXIT, result.stdout + result.stderr
    until = time.strftime("%H:%M", time.localtime(until_ms / 1000))
    assert f"asked not to be disturbed until {until}" in result.stderr
    _marker_comes_first(broker, sleeve)


def test_a_do_not_disturb_whose_time_has_passed_holds_nothing(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    sleeve.status({**NOT_PAUSED, "do_not_disturb_until_ms": int(time.time() * 1000) - 60_000})
    result = send(broker, "0,0,3,2,100", "--no-wait")
    assert result.returncode == 0, result.stderr
    assert sleeve.next_stroke()["start"] == [0, 0]


def test_the_wearer_s_ceiling_is_said_in_one_line_and_the_strokes_go(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    sleeve.status({**NOT_PAUSED, "ceiling": 0.6})
    result = send(broker, "0,0,3,2,100", "3,2,0,2,100", "--intensity", "0.9", "--no-wait")
    assert result.returncode == 0, result.stderr
    assert (
        "The wearer set a ceiling of 60 % (intensity 0.6): it caps every stroke's intensity; "
        "2 of the 2 strokes ask for more and play at 0.6." in result.stderr.splitlines()
    )
    assert [sleeve.next_stroke()["seq"], sleeve.next_stroke()["seq"]] == [0, 1]


def test_controls_not_understood_are_said_and_the_sleeve_is_left_to_refuse(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    sleeve.status({"paused": "yes"})
    result = send(broker, "0,0,3,2,100", "--no-wait")
    assert result.returncode == 0, result.stderr
    assert "wearer controls this command does not understand" in result.stderr
    assert "controls.paused" in result.stderr
    assert sleeve.next_stroke()["start"] == [0, 0]


def _answers_as_a_pause_mid_drawing(stroke: dict[str, Any]) -> list[dict[str, Any]]:
    """Stroke 0 played; stroke 1 played, then cut by the wearer's pause; the rest refused."""
    ref = {
        "topic": "feelmysign/sleeve1/strokes",
        "drawing": stroke["drawing"],
        "seq": stroke["seq"],
        "received_at_ms": time.time() * 1000,
    }
    played = {
        "type": "played",
        **ref,
        "start_at_ms": ref["received_at_ms"],
        "first_command_at_ms": ref["received_at_ms"],
        "latency_ms": 0.5,
        "start_error_ms": 0.0,
        "queued_ms": 0,
        "duration_ms": stroke["duration_ms"],
        "commands": 3,
    }
    if stroke["seq"] == 0:
        return [played]
    if stroke["seq"] == 1:
        cut = {
            "type": "cancelled",
            "reason": "cancelled",
            "message": "The wearer paused the sleeve.",
            **ref,
            "cancelled_at_ms": ref["received_at_ms"] + 20,
            "started": True,
            "by": "wearer",
        }
        return [played, cut]
    return [
        {
            "type": "rejected",
            "reason": "paused",
            "message": "The wearer paused the sleeve; it plays again when the wearer resumes.",
            **ref,
        }
    ]


def test_a_pause_during_a_send_names_the_strokes_it_kept_from_the_skin(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    sleeve.status(NOT_PAUSED)
    sleeve.answer = _answers_as_a_pause_mid_drawing
    strokes = ["0,0,1,0,100", "1,0,2,0,100", "2,0,3,0,100", "3,0,3,1,100"]
    result = send(broker, *strokes, "--wait", "--pace", "burst", "--timeout-s", "20")
    assert result.returncode == WEARER_HOLD_EXIT, result.stdout + result.stderr
    assert "refused (paused)" in result.stdout
    error = result.stderr.strip().splitlines()[-1]
    assert error.startswith(
        "Error: The sleeve played 1 of 4 strokes, refused 2 (paused x2), cut 1 part-way (cancelled)"
    )
    assert "The wearer paused the sleeve: stroke(s) 3, 4 refused" in error
    assert "the wearer (a pause, stop or block) cut or dropped stroke(s) 2" in error
    assert error.endswith("Send again once the wearer has resumed.")


def _answers_as_a_stop_mid_drawing(stroke: dict[str, Any]) -> list[dict[str, Any]]:
    """Stroke 2 cut by the wearer's stop, the rest dropped by it: no pause anywhere."""
    answers = _answers_as_a_pause_mid_drawing(stroke)
    if stroke["seq"] < 2:
        return answers
    (refused,) = answers
    ref: dict[str, Any] = {
        k: refused[k] for k in ("topic", "drawing", "seq", "received_at_ms") if k in refused
    }
    return [
        {
            "type": "cancelled",
            "reason": "cancelled",
            "message": "dropped by the wearer before it played",
            **ref,
            "cancelled_at_ms": ref["received_at_ms"],
            "started": False,
            "by": "wearer",
        }
    ]


def test_a_stop_by_the_wearer_is_not_said_as_a_pause_to_resume(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    sleeve.status(NOT_PAUSED)
    sleeve.answer = _answers_as_a_stop_mid_drawing
    strokes = ["0,0,1,0,100", "1,0,2,0,100", "2,0,3,0,100", "3,0,3,1,100"]
    result = send(broker, *strokes, "--wait", "--pace", "burst", "--timeout-s", "20")
    assert result.returncode == WEARER_HOLD_EXIT, result.stdout + result.stderr
    error = result.stderr.strip().splitlines()[-1]
    assert "The wearer (a pause, stop or block) cut or dropped stroke(s) 2 to 4" in error, error
    assert "resumed" not in error, error
    assert error.endswith("send again only when they want it."), error


def test_a_refusal_of_the_sender_s_own_making_keeps_exit_1(
    broker: Broker, sleeve: StandInSleeve
) -> None:
    sleeve.status(NOT_PAUSED)

    def refuse(stroke: dict[str, Any]) -> list[dict[str, Any]]:
        return [
            {
                "type": "rejected",
                "reason": "duration_too_long",
                "message": "too long",
                "drawing": stroke["drawing"],
                "seq": stroke["seq"],
                "received_at_ms": time.time() * 1000,
            }
        ]

    sleeve.answer = refuse
    result = send(broker, "0,0,1,0,100", "--wait", "--timeout-s", "20")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "wearer" not in result.stderr
