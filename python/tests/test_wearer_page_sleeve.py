"""``feelmysign sleeve --wearer-page``, against real processes: the sleeve (on the Pi, where
no ``up`` runs) serves the wearer's page and API itself, over HTTPS off loopback with a
certificate from the local CA (as ``up --lan``), and its controls answer in-process."""

from __future__ import annotations

import http.client
import json
import os
import queue
import re
import signal
import ssl
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from feelmysign.broker import Broker

FEELMYSIGN = str(Path(sys.executable).parent / "feelmysign")
WAIT_S = 60.0
# 127.0.0.2 is this machine, but not a loopback name the page server trusts in clear text.
HOST = "127.0.0.2"
WEARER_URL = re.compile(r"https://127\.0\.0\.2:(\d+)/wearer\?key=([\w-]+)")

pytestmark = pytest.mark.broker


def test_the_sleeve_serves_the_wearer_s_page_over_tls(broker: Broker, tmp_path: Path) -> None:
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "pi-state")}
    sleeve = subprocess.Popen(
        [
            FEELMYSIGN,
            "sleeve",
            "--credentials",
            str(broker.credentials_path),
            "--wearer-page",
            "0",
            "--wearer-host",
            HOST,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
    )
    lines: queue.Queue[str] = queue.Queue()
    stdout = sleeve.stdout
    assert stdout is not None

    def read() -> None:
        for line in stdout:
            lines.put(line)

    threading.Thread(target=read, daemon=True).start()
    try:
        seen = ""
        while (found := WEARER_URL.search(seen)) is None:
            seen += lines.get(timeout=WAIT_S)
        assert "For the wearer's phone" in seen and "accept the certificate" in seen, seen
        port, key = int(found[1]), found[2]
        ca = tmp_path / "pi-state" / "feelmysign" / "wearer-page" / "tls" / "ca.pem"
        context = ssl.create_default_context(cafile=str(ca))

        def call(method: str, path: str, body: dict[str, Any] | None = None) -> tuple[int, Any]:
            connection = http.client.HTTPSConnection(HOST, port, timeout=WAIT_S, context=context)
            headers = {"Cookie": f"feelmysign_wearer_key={key}", "Content-Type": "application/json"}
            data = None if body is None else json.dumps(body).encode()
            connection.request(method, path, body=data, headers=headers)
            answer = connection.getresponse()
            result = answer.status, answer.read()
            connection.close()
            return result

        status, page = call("GET", f"/wearer?key={key}")
        assert status == 303  # the key into a Secure cookie
        status, page = call("GET", "/wearer")
        assert status == 200 and b"/src/wearer/" not in page and b"<html" in page
        # The sleeve connects to the broker shortly after the page is up.
        deadline_s = time.monotonic() + WAIT_S
        while not json.loads(call("GET", "/api/wearer/state")[1])["online"]:
            assert time.monotonic() < deadline_s, "the sleeve never came online"
            time.sleep(0.1)
        status, body = call("POST", "/api/wearer/pause", {})
        state = json.loads(body)
        assert status == 200 and state["controls"]["paused"] is True
        assert state["blocking"] is False and state["senders"] == []
        status, body = call("POST", "/api/wearer/block", {"sender": "alice"})
        assert status == 400 and "needs the broker feelmysign runs" in json.loads(body)["error"]
    finally:
        sleeve.send_signal(signal.SIGINT)
        sleeve.wait(WAIT_S)
    assert sleeve.returncode == 0


def test_wearer_host_without_wearer_page_is_refused(broker: Broker) -> None:
    result = subprocess.run(
        [
            FEELMYSIGN,
            "sleeve",
            "--credentials",
            str(broker.credentials_path),
            "--wearer-host",
            HOST,
        ],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert result.returncode == 1, result.stdout + result.stderr
    assert "needs --wearer-page" in result.stderr and "Traceback" not in result.stderr


def test_a_second_sleeve_beside_up_s_broker_blocks_senders_on_its_own_page(
    start_broker: Any, tmp_path: Path
) -> None:
    """``broker add-sleeve arm2`` and ``sleeve --join TOKEN --wearer-page`` on the machine
    whose usual state directory holds the broker: the page finds that broker and blocks."""
    xdg = tmp_path / "xdg"
    env = {**os.environ, "XDG_STATE_HOME": str(xdg)}
    state_dir = xdg / "feelmysign" / "broker"  # where up and 'feelmysign broker' keep it
    start_broker(state_dir=state_dir)

    def broker_command(*words: str) -> str:
        done = subprocess.run(
            [FEELMYSIGN, "broker", *words],
            capture_output=True,
            text=True,
            timeout=WAIT_S,
            env=env,
            check=True,
        )
        return done.stdout.strip().splitlines()[-1]

    token = broker_command("add-sleeve", "arm2")
    broker_command("add-sender", "--name", "alice")
    sleeve = subprocess.Popen(
        [FEELMYSIGN, "sleeve", "--join", token, "--wearer-page", "0", "--wearer-host", "127.0.0.1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
    )
    lines: queue.Queue[str] = queue.Queue()
    stdout = sleeve.stdout
    assert stdout is not None

    def read() -> None:
        for line in stdout:
            lines.put(line)

    threading.Thread(target=read, daemon=True).start()
    try:
        seen = ""
        url = re.compile(r"http://127\.0\.0\.1:(\d+)/wearer\?key=([\w-]+)")
        while (found := url.search(seen)) is None:
            seen += lines.get(timeout=WAIT_S)
        port, key = int(found[1]), found[2]

        def call(method: str, path: str, body: dict[str, Any] | None = None) -> tuple[int, Any]:
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=WAIT_S)
            headers = {"Cookie": f"feelmysign_wearer_key={key}", "Content-Type": "application/json"}
            data = None if body is None else json.dumps(body).encode()
            connection.request(method, path, body=data, headers=headers)
            answer = connection.getresponse()
            result = answer.status, json.loads(answer.read())
            connection.close()
            return result

        deadline_s = time.monotonic() + WAIT_S
        while not (state := call("GET", "/api/wearer/state")[1])["online"]:
            assert time.monotonic() < deadline_s, f"the sleeve never came online: {seen}"
            time.sleep(0.1)
        assert state["sleeve_id"] == "arm2", state
        assert state["blocking"] is True, state
        assert {"name": "alice", "blocked": False, "blockable": True} in state["senders"]
        status, state = call("POST", "/api/wearer/block", {"sender": "alice"})
        assert status == 200, state
        assert {"name": "alice", "blocked": True, "blockable": True} in state["senders"]
    finally:
        sleeve.send_signal(signal.SIGINT)
        sleeve.wait(WAIT_S)
    assert sleeve.returncode == 0, seen
