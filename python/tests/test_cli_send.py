"""``feelmysign send`` against a real Mosquitto, received by a client logged in as the sleeve.

Every wait is on an event (a SUBACK, a message) with a timeout. That nothing
was sent is shown with a marker: a valid stroke sent afterwards must be the
first message the sleeve receives. Also the broker options, which need no broker.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import queue
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from cli_environment import clean_cli_environment
from paho.mqtt.enums import CallbackAPIVersion
from paho.mqtt.reasoncodes import ReasonCode

from feelmysign.broker import Broker, BrokerError, Credentials
from feelmysign.cli import main
from feelmysign.cli.options.broker import add_broker_options, broker_settings_from_args
from feelmysign.connection import BrokerConnectionError, parse_broker_url
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.lifecycle import Closing
from feelmysign.protocol import Accepted, parse
from feelmysign.shapes import shape_strokes

WAIT_S = 10.0
LEGACY_TOPIC = "deviceOne/line"


@pytest.fixture(autouse=True)
def clean_environment(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """No FEELMYSIGN_* from the developer's shell, and no local broker's credentials file."""
    clean_cli_environment(monkeypatch, tmp_path)


class Sleeve(Closing):
    """A client logged in with the sleeve's account, subscribed to its strokes and legacy topics."""

    def __init__(self, credentials: Credentials) -> None:
        self.messages: queue.Queue[mqtt.MQTTMessage] = queue.Queue()
        self._events: queue.Queue[ReasonCode | list[ReasonCode]] = queue.Queue()
        self.paho = mqtt.Client(CallbackAPIVersion.VERSION2, protocol=mqtt.MQTTv5)
        self.paho.username_pw_set(credentials.sleeve.username, credentials.sleeve.password)
        self.paho.on_connect = lambda _c, _u, _f, code, _p: self._events.put(code)
        self.paho.on_subscribe = lambda _c, _u, _mid, codes, _p: self._events.put(codes)
        self.paho.on_message = lambda _c, _u, message: self.messages.put(message)
        self.paho.connect(credentials.mqtt_host, credentials.mqtt_port)
        self.paho.loop_start()
        connack = self._events.get(timeout=WAIT_S)
        assert isinstance(connack, ReasonCode) and not connack.is_failure, connack
        topics = [(f"feelmysign/{credentials.sleeve_id}/strokes", 1), (LEGACY_TOPIC, 1)]
        self.paho.subscribe(topics)
        granted = self._events.get(timeout=WAIT_S)
        assert isinstance(granted, list) and not any(code.is_failure for code in granted)

    def receive(self, count: int) -> list[tuple[str, str]]:
        """The next ``count`` messages as (topic, payload text), in arrival order."""
        received = []
        for _ in range(count):
            message = self.messages.get(timeout=WAIT_S)
            received.append((message.topic, message.payload.decode()))
        return received

    def close(self) -> None:
        self.paho.disconnect()
        self.paho.loop_stop()


@pytest.fixture
def sleeve(broker: Broker) -> Iterator[Sleeve]:
    with Sleeve(broker.credentials) as client:
        yield client


def send(broker: Broker, *argv: str) -> int:
    return main(["send", "--credentials", str(broker.credentials_path), *argv])


def _json_payloads(received: list[tuple[str, str]]) -> list[dict[str, Any]]:
    assert {topic for topic, _ in received} == {"feelmysign/sleeve1/strokes"}
    return [json.loads(payload) for _, payload in received]


@pytest.fixture
def closed_port() -> Iterator[int]:
    """A port bound but not listening: a connection is refused, and no one else can take it."""
    with socket.socket() as held:
        held.bind(("127.0.0.1", 0))
        yield held.getsockname()[1]


# --- sending to a real broker ---------------------------------------------------------------


def test_a_shape_arrives_in_order_as_json_v1(
    broker: Broker, sleeve: Sleeve, capsys: pytest.CaptureFixture[str]
) -> None:
    # --no-wait: this test's sleeve is a bare client that answers nothing.
    argv = ("--shape", "circle", "--segments", "8", "--duration-ms", "800", "--no-wait")
    assert send(broker, *argv) == 0
    payloads = _json_payloads(sleeve.receive(8))
    expected = shape_strokes("circle", layout=PAPER_SLEEVE, segments=8, duration_ms=800)
    assert [p["seq"] for p in payloads] == list(range(8))
    assert len({p["drawing"] for p in payloads}) == 1
    for payload, stroke in zip(payloads, expected, strict=True):
        assert payload["v"] == 1
        assert (tuple(payload["start"]), tuple(payload["end"])) == (stroke.start, stroke.end)
        assert payload["duration_ms"] == stroke.duration_ms
        assert "intensity" not in payload  # the sleeve's default
        assert isinstance(payload["sent_at_ms"], int)
    assert [p["sent_at_ms"] for p in payloads] == sorted(p["sent_at_ms"] for p in payloads)
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("[1/8] feelmysign/sleeve1/strokes {")
    assert "the broker acknowledged every one" in out[-1]


def test_strokes_arrive_in_order_with_one_drawing_and_the_intensity(
    broker: Broker, sleeve: Sleeve
) -> None:
    assert send(broker, "0,0,3,2,1500", "3,2,0,2,800", "--intensity", "0.4") == 0
    received = sleeve.receive(2)
    first, second = _json_payloads(received)
    assert (first["start"], first["end"], first["duration_ms"]) == ([0, 0], [3, 2], 1500)
    assert (second["start"], second["end"], second["duration_ms"]) == ([3, 2], [0, 2], 800)
    assert (first["seq"], second["seq"]) == (0, 1)
    assert first["drawing"] == second["drawing"]
    assert first["intensity"] == second["intensity"] == 0.4
    for _, payload in received:
        assert isinstance(parse(payload, PAPER_SLEEVE), Accepted)


def test_legacy_strokes_arrive_byte_for_byte_on_the_legacy_topic(
    broker: Broker, sleeve: Sleeve
) -> None:
    assert send(broker, "0,0,3,2,1500", "3,2,0.5,2,800.25", "--legacy") == 0
    assert sleeve.receive(2) == [
        (LEGACY_TOPIC, "0,0,3,2,1500"),
        (LEGACY_TOPIC, "3,2,0.5,2,800.25"),
    ]


def test_a_legacy_shape_is_rounded_to_four_decimals(broker: Broker, sleeve: Sleeve) -> None:
    assert send(broker, "--shape", "triangle", "--legacy", "--pace", "burst") == 0
    received = sleeve.receive(3)
    first = received[0][1].split(",")
    assert len(first) == 5 and all(len(field.partition(".")[2]) <= 4 for field in first)
    # Joined end to start, also after rounding.
    ends = [payload.split(",")[2:4] for _, payload in received]
    starts = [payload.split(",")[0:2] for _, payload in received]
    assert starts[1:] == ends[:-1] and starts[0] == ends[-1]


def test_strokes_from_standard_input(
    broker: Broker, sleeve: Sleeve, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO("0,0,1,1,100\n\n1,1,2,2,200\n"))
    assert send(broker, "-") == 0
    payloads = _json_payloads(sleeve.receive(2))
    assert [(p["start"], p["end"]) for p in payloads] == [([0, 0], [1, 1]), ([1, 1], [2, 2])]


def test_json_output_lists_every_message(
    broker: Broker, sleeve: Sleeve, capsys: pytest.CaptureFixture[str]
) -> None:
    assert send(broker, "--shape", "square", "--duration-ms", "200", "--json", "--no-wait") == 0
    received = sleeve.receive(4)
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(line["topic"], line["payload"]) for line in lines] == received
    assert [line["index"] for line in lines] == [0, 1, 2, 3]


def test_a_bad_stroke_sends_nothing(
    broker: Broker, sleeve: Sleeve, capsys: pytest.CaptureFixture[str]
) -> None:
    assert send(broker, "0,0,1,1,100", "0,0,5,2,1500") == 1
    error = capsys.readouterr().err
    # No sleeve status at this broker: checked against the paper's grid, and said so first.
    assert "No status from sleeve 'sleeve1'" in error and "paper's sleeve" in error
    assert "\nError: Stroke 2 '0,0,5,2,1500' would be rejected by the sleeve" in error
    assert "outside_grid" in error and "Nothing was sent." in error
    assert send(broker, "2,2,3,2,100", "--legacy") == 0  # the marker
    assert sleeve.receive(1) == [(LEGACY_TOPIC, "2,2,3,2,100")]


def test_a_stroke_too_long_for_the_sleeve_is_told_the_sleeves_own_limit(
    broker: Broker, capsys: pytest.CaptureFixture[str]
) -> None:
    assert send(broker, "0,0,1,1,700000") == 1
    error = capsys.readouterr().err
    assert "(duration_too_long)" in error and "at most 10000 ms" in error
    assert "600000" not in error


def test_a_bad_stroke_on_standard_input_names_its_line(
    broker: Broker, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO("0,0,1,1,100\n0,0,1,1\n"))
    assert send(broker, "-") == 1
    assert "Line 2 of standard input '0,0,1,1'" in capsys.readouterr().err


def test_a_wrong_password_is_an_error_naming_the_user(
    broker: Broker, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "send",
            "--broker",
            broker.credentials.mqtt_url,
            "--username",
            "sender",
            "--password",
            "not-the-password",
            "--shape",
            "line",
        ]
    )
    assert code == 1
    error = capsys.readouterr().err
    assert error.startswith(f"Error: The broker at {broker.credentials.mqtt_url} refused user")
    assert "'sender'" in error and "--credentials" in error


def test_the_sleeve_account_may_not_send(
    broker: Broker, capsys: pytest.CaptureFixture[str]
) -> None:
    account = broker.credentials.sleeve
    argv = ["--username", account.username, "--password", account.password, "0,0,1,0,100"]
    assert send(broker, *argv) == 1
    error = capsys.readouterr().err
    assert "refused stroke 1 of 1 on feelmysign/sleeve1/strokes" in error
    assert "sender account" in error


def test_websockets_work_too(broker: Broker, sleeve: Sleeve) -> None:
    assert send(broker, "--broker", broker.credentials.ws_url, "0,0,1,0,100") == 0
    assert _json_payloads(sleeve.receive(1))[0]["end"] == [1, 0]


# --- without a broker -------------------------------------------------------------------------


def test_no_broker_is_a_clear_error_without_traceback(closed_port: int) -> None:
    url = f"mqtt://127.0.0.1:{closed_port}"
    result = subprocess.run(
        [sys.executable, "-m", "feelmysign", "send", "--broker", url, "--shape", "line"],
        capture_output=True,
        text=True,
        timeout=60,
        env={k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")},
        check=False,
    )
    assert result.returncode == 1
    assert result.stderr.startswith(f"Error: Nothing accepts connections at {url}")
    assert "'feelmysign broker' or 'make up'" in result.stderr
    assert "Traceback" not in result.stderr
    assert result.stdout == ""


def test_a_server_that_never_answers_times_out_with_a_clear_error(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()  # the kernel completes the connection; nobody answers the login
        url = f"mqtt://127.0.0.1:{server.getsockname()[1]}"
        code = main(["send", "--broker", url, "0,0,1,0,100", "--timeout-s", "0.5"])
    assert code == 1
    assert capsys.readouterr().err.startswith(f"Error: No answer from {url}")


@pytest.mark.parametrize(
    ("url", "says"),
    [
        ("127.0.0.1:1883", "has no scheme: write it as mqtt://127.0.0.1:1883"),
        ("tcp://127.0.0.1:1883", "uses the scheme 'tcp': write mqtt:// instead"),
        ("http://example.org", "write ws:// instead"),
        ("mqtt://:1883", "has no host name"),
        ("mqtt://127.0.0.1:abc", "has the port 'abc': use a whole number from 1 to 65535"),
        ("mqtt://127.0.0.1:70000", "has the port '70000'"),
        ("mqtt://user:secret@127.0.0.1", "contains a user name or password"),
        ("mqtt://127.0.0.1/strokes", "has a path, query or fragment"),
        ("", "has no scheme"),
    ],
)
def test_a_bad_broker_url_says_what_is_wrong(url: str, says: str) -> None:
    with pytest.raises(BrokerConnectionError) as caught:
        parse_broker_url(url)
    assert says in str(caught.value)
    assert caught.value.reason == "bad-url"


def test_good_broker_urls() -> None:
    settings = parse_broker_url("mqtts://broker.example.org")
    assert (settings.host, settings.port, settings.transport, settings.tls) == (
        "broker.example.org",
        8883,
        "tcp",
        True,
    )
    settings = parse_broker_url("ws://[::1]:9001/mqtt", sleeve_id="arm2")
    assert (settings.host, settings.port, settings.transport, settings.path) == (
        "::1",
        9001,
        "websockets",
        "/mqtt",
    )
    assert settings.strokes_topic == "feelmysign/arm2/strokes"


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["0,0,1,0,100", "--shape", "line"], "either STROKEs or --shape, not both"),
        ([], "give STROKEs"),
        (["0,0,1,0,100", "--segments", "4"], "--segments only apply to --shape"),
        (["--shape", "line", "--legacy", "--intensity", "0.5"], "legacy format has no intensity"),
        (["--shape", "line", "--timeout-s", "0"], "--timeout-s: 0 is out of range"),
        # Nothing would be felt, and the sleeve would report it played: refused, with the range.
        (
            ["--shape", "line", "--intensity", "0"],
            "--intensity: 0 is out of range; give a number "
            "from 0.01 to 1 (at 0 the sleeve would play strokes no one feels)",
        ),
        (["--shape", "line", "--id", "a/b"], "--id: the sleeve id 'a/b' cannot be used"),
    ],
)
def test_usage_errors_exit_2(
    argv: list[str], says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as caught:
        main(["send", *argv])
    assert caught.value.code == 2
    assert says in capsys.readouterr().err


@pytest.mark.parametrize(
    ("shape", "segments", "says"),
    [
        ("circle", "2", "--segments: 2 does not fit a circle; give a whole number from 3 to 64"),
        ("square", "6", "--segments: 6 does not fit a square; give a multiple of 4 from 4 to 64"),
    ],
)
def test_shape_errors_name_the_option_and_range(
    shape: str, segments: str, says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    # A bad option value is a usage error like any other: exit 2, before any connection.
    with pytest.raises(SystemExit) as caught:
        main(["send", "--shape", shape, "--segments", segments, "--broker", "mqtt://127.0.0.1:1"])
    assert caught.value.code == 2
    assert says in capsys.readouterr().err


# --- where the settings come from --------------------------------------------------------------


def _settings_args(*argv: str, role: Any = "sender") -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_broker_options(parser, role=role)
    return parser.parse_args(list(argv))


def _write_credentials(path: Path, *, url: str = "mqtt://127.0.0.1:4321") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        json.dumps(
            {
                "mqtt_url": url,
                "ws_url": "ws://127.0.0.1:4322",
                "sleeve": {"id": "arm", "username": "sleeve-arm", "password": "sleeve-password"},
                "sender": {"username": "sender", "password": "sender-password"},
            }
        )
    )
    return path


def test_credentials_file_gives_the_role_s_account_url_and_sleeve(tmp_path: Path) -> None:
    path = str(_write_credentials(tmp_path / "credentials.json"))
    sender = broker_settings_from_args(_settings_args("--credentials", path), "sender")
    assert (sender.username, sender.password) == ("sender", "sender-password")
    assert (sender.host, sender.port, sender.sleeve_id) == ("127.0.0.1", 4321, "arm")
    args = _settings_args("--credentials", path, role="sleeve")
    sleeve = broker_settings_from_args(args, "sleeve")
    assert (sleeve.username, sleeve.password) == ("sleeve-arm", "sleeve-password")


def test_options_beat_environment_beat_credentials_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = str(_write_credentials(tmp_path / "credentials.json"))
    monkeypatch.setenv("FEELMYSIGN_CREDENTIALS", path)
    monkeypatch.setenv("FEELMYSIGN_BROKER", "ws://127.0.0.1:9999")
    monkeypatch.setenv("FEELMYSIGN_SLEEVE_ID", "from-env")
    settings = broker_settings_from_args(_settings_args(), "sender")
    assert (settings.transport, settings.port, settings.sleeve_id) == (
        "websockets",
        9999,
        "from-env",
    )
    assert settings.username == "sender"  # still from the file
    settings = broker_settings_from_args(
        _settings_args("--broker", "mqtt://10.0.0.2", "--id", "opt"), "sender"
    )
    assert (settings.host, settings.port, settings.sleeve_id) == ("10.0.0.2", 1883, "opt")


def test_the_local_broker_s_file_is_used_only_when_nothing_else_is_given(tmp_path: Path) -> None:
    _write_credentials(tmp_path / "state" / "feelmysign" / "broker" / "credentials.json")
    settings = broker_settings_from_args(_settings_args(), "sender")
    assert (settings.port, settings.username) == (4321, "sender")
    # Never sent to another broker: its passwords stay local.
    elsewhere = broker_settings_from_args(_settings_args("--broker", "mqtt://other"), "sender")
    assert (elsewhere.host, elsewhere.username, elsewhere.password) == ("other", None, None)


def test_a_user_and_password_keep_the_local_broker_s_url_and_sleeve(tmp_path: Path) -> None:
    _write_credentials(tmp_path / "state" / "feelmysign" / "broker" / "credentials.json")
    args = _settings_args("--username", "alice", "--password", "secret1")
    settings = broker_settings_from_args(args, "sender")
    # The URL and sleeve id from the file (not the default 1883), the account as given.
    assert (settings.port, settings.username, settings.password) == (4321, "alice", "secret1")
    assert (
        settings.sleeve_id
        == json.loads(
            (tmp_path / "state" / "feelmysign" / "broker" / "credentials.json").read_text()
        )["sleeve"]["id"]
    )


def test_without_anything_the_default_is_the_local_broker_anonymously() -> None:
    settings = broker_settings_from_args(_settings_args(), "sender")
    assert (settings.url, settings.username, settings.sleeve_id) == (
        "mqtt://127.0.0.1:1883",
        None,
        "sleeve1",
    )


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["--username", "u"], "without a password"),
        (["--password", "p"], "without a user name"),
        (["--credentials", "/nonexistent/credentials.json"], "No credentials file at"),
    ],
)
def test_bad_settings_say_what_to_do(argv: list[str], says: str) -> None:
    with pytest.raises(BrokerError) as caught:
        broker_settings_from_args(_settings_args(*argv), "sender")
    assert says in str(caught.value)


def test_a_bad_sleeve_id_from_the_environment_says_what_to_do(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("FEELMYSIGN_SLEEVE_ID", "a/b")
    with pytest.raises(BrokerError) as caught:
        broker_settings_from_args(_settings_args("--broker", "mqtt://127.0.0.1:1"), "sender")
    assert "Sleeve id 'a/b' cannot be used" in str(caught.value)


def test_an_answer_heard_before_its_stroke_is_said_sent_is_printed_after_it() -> None:
    # The broker's acknowledgement and the sleeve's answer arrive on different threads: a quick
    # sleeve's answer waits for its stroke's sent line; one of a stroke never said sent is
    # printed at the end.
    from feelmysign.cli.send import _InOrder

    said: list[str] = []
    lines = _InOrder()
    lines.answer(0, lambda: said.append("[1/3] played"))
    lines.sent(0, lambda: said.append("[1/3] sent"))
    lines.sent(1, lambda: said.append("[2/3] sent"))
    lines.answer(1, lambda: said.append("[2/3] played"))
    lines.answer(2, lambda: said.append("[3/3] refused"))
    assert said == ["[1/3] sent", "[1/3] played", "[2/3] sent", "[2/3] played"]
    lines.flush()
    assert said[-1] == "[3/3] refused"


def test_a_stroke_held_up_on_the_way_keeps_the_time_the_drawing_gave_it(
    broker: Broker, sleeve: Sleeve
) -> None:
    """A paced drawing whose sending is held up (here between two strokes; a broker away, whose
    acknowledgement comes late, holds it up the same way): each stroke after it is stamped with
    the time it was due, not the moment it left, so the sleeve sees how late it is."""
    import time

    from feelmysign.connection import connect_client
    from feelmysign.sending import OutgoingStroke, StrokeSender
    from feelmysign.stroke import Stroke

    credentials = broker.credentials
    settings = credentials.settings("sender")
    client = connect_client(settings, "held-up-sender")
    count, step_ms, held_s = 6, 100.0, 1.0
    topic = f"feelmysign/{credentials.sleeve_id}/strokes"
    messages = [
        OutgoingStroke(k, topic, Stroke((0, 1), (1, 1), step_ms, drawing="held", seq=k))
        for k in range(count)
    ]
    asked = [0]

    def hold_the_third() -> bool:
        asked[0] += 1
        if asked[0] == 3:
            time.sleep(held_s)
        return False

    try:
        sender = StrokeSender(client, settings, timeout_s=WAIT_S)
        assert sender.send_at(messages, [k * step_ms for k in range(count)], until=hold_the_third)
    finally:
        client.disconnect()
        client.loop_stop()
    stamps = [json.loads(payload)["sent_at_ms"] for _, payload in sleeve.receive(count)]
    for k, stamp in enumerate(stamps):
        assert abs(stamp - stamps[0] - k * step_ms) <= 1.0, (k, stamps)


def test_a_grid_given_that_is_not_the_sleeves_is_said(
    broker: Broker, capsys: pytest.CaptureFixture[str]
) -> None:
    import subprocess

    from sleeve_watch import SleeveWatch, online

    from feelmysign.bench.sleeve import sleeve_command

    with SleeveWatch(broker.credentials, "status") as watch:
        sleeve = subprocess.Popen(
            sleeve_command(broker.credentials_path, "--no-legacy"),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            watch.next(online, "the sleeve online")
            capsys.readouterr()
            assert send(broker, "--rows", "5", "--columns", "6", "--no-wait", "0,0,1,0,300") == 0
            err = capsys.readouterr().err
            assert "checked against a 5 x 6 grid" in err and "sleeve 'sleeve1' is 3 x 4" in err
            assert send(broker, "--rows", "3", "--columns", "4", "--no-wait", "0,0,1,0,300") == 0
            assert "checked against" not in capsys.readouterr().err  # the sleeve's own grid
        finally:
            sleeve.terminate()
            sleeve.wait(timeout=60)
