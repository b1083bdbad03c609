"""A second sleeve on the machine of the broker, against real processes: ``broker
add-sleeve`` gives it a token for the plain loopback listener (no TLS needed on this
machine, as ``up`` itself connects), and ``sleeve --join`` refuses options it would
overrule."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from sleeve_watch import connected_client, reaped, settings, stop_loop, subscribe

from feelmysign.broker import Broker
from feelmysign.connection.join_token import decode_join_token
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic, telemetry_topic

WAIT_S = 60.0

pytestmark = pytest.mark.broker


def feelmysign(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "feelmysign", *args],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        env=env,
    )


def test_a_second_sleeve_joins_a_broker_without_tls_on_its_machine(
    broker: Broker, tmp_path: Path
) -> None:
    added = feelmysign("broker", "--state-dir", str(broker.state_dir), "add-sleeve", "arm2")
    assert added.returncode == 0, added.stderr
    token = added.stdout.strip()
    assert decode_join_token(token).url == broker.credentials.mqtt_url
    assert "on this machine only" in added.stderr, added.stderr
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "second-state")}
    command = [sys.executable, "-m", "feelmysign", "sleeve", "--join", token]
    sleeve = subprocess.Popen(
        command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    sender = connected_client(settings(broker.credentials, "sender"), wait_s=WAIT_S)
    with reaped(sleeve):
        try:
            statuses = subscribe(sender, telemetry_topic("arm2", "status"))
            assert json.loads(statuses.get(timeout=WAIT_S)[1])["online"] is True
            events = subscribe(sender, telemetry_topic("arm2", "events"))
            stroke = Stroke((0.0, 0.0), (1.0, 0.0), 200.0, 0.8, "second-sleeve", 0)
            sender.publish(strokes_topic("arm2"), format_json(stroke), qos=1).wait_for_publish(5)
            played = json.loads(events.get(timeout=WAIT_S)[1])
        finally:
            stop_loop(sender)
    assert (played["type"], played["drawing"], played["seq"]) == ("played", "second-sleeve", 0)


@pytest.mark.parametrize("url", ["mqtt://192.0.2.7:1883", "ws://192.0.2.7:9001"])
def test_add_sleeve_refuses_a_plain_url_to_another_machine(broker: Broker, url: str) -> None:
    added = feelmysign(
        "broker", "--state-dir", str(broker.state_dir), "add-sleeve", "arm2", "--url", url
    )
    assert added.returncode == 1, added.stdout + added.stderr
    assert f"--url {url} is plain" in added.stderr and "--lan" in added.stderr, added.stderr
    assert added.stdout == "" and "Traceback" not in added.stderr


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--broker", "mqtt://127.0.0.1:1"], "--broker"),
        (["--id", "arm3"], "--id"),
        (["--username", "u", "--password", "p"], "--username and --password"),
    ],
)
@pytest.mark.parametrize("given", ["option", "environment"])
def test_join_refuses_an_option_it_would_overrule(
    broker: Broker, tmp_path: Path, options: list[str], named: str, given: str
) -> None:
    added = feelmysign("broker", "--state-dir", str(broker.state_dir), "add-sleeve", "arm2")
    token = added.stdout.strip()
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    env["XDG_STATE_HOME"] = str(tmp_path / "second-state")
    join = ["--join", token] if given == "option" else []
    if given == "environment":
        env["FEELMYSIGN_JOIN"] = token
    refused = feelmysign("sleeve", *join, *options, env=env)
    assert refused.returncode == 1, refused.stdout + refused.stderr
    source = "--join" if given == "option" else "$FEELMYSIGN_JOIN"
    assert f"{source} (a join token)" in refused.stderr, refused.stderr
    assert f"would win over {named}: give one or the other" in refused.stderr, refused.stderr
    assert "Traceback" not in refused.stderr
    assert "sleeve-arm2" not in broker.log_path.read_text()  # no login was attempted
