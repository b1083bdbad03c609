"""The wearer blocks a sender, against real processes: ``feelmysign up`` (its Mosquitto,
its simulated sleeve, its page server with the wearer's API), ``broker add-sender --name``
and a real ``feelmysign send --join TOKEN``.

Blocking rewrites the password file and the ACL and reloads Mosquitto: a connected client
of that account is disconnected (Mosquitto 2.0 checks every client again on SIGHUP) and
its next login refused, which ``send`` reports in words. Unblocking gives the same token
back its rights; a block outlives a restart of ``up``.
"""

from __future__ import annotations

import json
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from sleeve_watch import connected_client, stop_loop

from feelmysign.broker import Broker
from feelmysign.connection.join_token import decode_join_token
from feelmysign.connection.settings import parse_broker_url

FEELMYSIGN = str(Path(sys.executable).parent / "feelmysign")
WAIT_S = 60.0  # start-up of Mosquitto, the sleeve and the web server on a loaded machine
WEARER_URL = re.compile(r"(http://127\.0\.0\.1:\d+/)wearer\?key=([\w-]+)")

pytestmark = pytest.mark.broker


class Up:
    """A running ``feelmysign up`` and its wearer's API."""

    def __init__(self, process: subprocess.Popen[str], base: str, key: str, banner: str) -> None:
        self.process = process
        self.base = base
        self.key = key
        self.banner = banner

    def call(self, action: str, body: dict[str, object] | None = None) -> dict[str, object]:
        request = urllib.request.Request(
            f"{self.base}api/wearer/{action}",
            data=None if body is None else json.dumps(body).encode(),
            headers={
                "Cookie": f"feelmysign_wearer_key={self.key}",
                "Content-Type": "application/json",
            },
            method="GET" if body is None else "POST",
        )
        with urllib.request.urlopen(request, timeout=WAIT_S) as answer:
            result: dict[str, object] = json.load(answer)
            return result


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@contextmanager
def running_up(state_dir: Path, mqtt_port: int, *more: str) -> Iterator[Up]:
    # The same MQTT port at each start: a join token holds the broker's URL.
    process = subprocess.Popen(
        [
            *(FEELMYSIGN, "up", "--state-dir", str(state_dir)),
            *("--http-port", "0", "--port", str(mqtt_port), "--ws-port", "0", *more),
        ],
        # The sleeve's controls (a pause) of this test's own: not another test's sleeve1.
        env={**os.environ, "XDG_STATE_HOME": str(state_dir.parent / "up-xdg")},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    lines: queue.Queue[str] = queue.Queue()
    assert process.stdout is not None
    stdout = process.stdout

    def read() -> None:
        for line in stdout:
            lines.put(line)

    threading.Thread(target=read, daemon=True).start()
    try:
        seen: list[str] = []
        while not seen or "Ctrl-C" not in seen[-1]:
            seen.append(lines.get(timeout=WAIT_S))
        found = WEARER_URL.search("".join(seen))
        assert found is not None, "".join(seen)
        yield Up(process, found[1], found[2], "".join(seen))
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(WAIT_S)


def add_sender(state_dir: Path, name: str) -> str:
    added = subprocess.run(
        [FEELMYSIGN, "broker", "--state-dir", str(state_dir), "add-sender", "--name", name],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert added.returncode == 0, added.stderr
    return added.stdout.strip()


def send(token: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    env["XDG_STATE_HOME"] = str(tmp_path / "sender-state")
    return subprocess.run(
        [FEELMYSIGN, "send", "--join", token, "--shape", "line", "--timeout-s", "20"],
        capture_output=True,
        text=True,
        timeout=WAIT_S * 2,
        env=env,
    )


def test_a_blocked_sender_is_cut_off_refused_in_words_and_unblocked(tmp_path: Path) -> None:
    state_dir = tmp_path / "up"
    mqtt_port = free_port()
    with running_up(state_dir, mqtt_port) as up:
        # The banner names what the wearer's page does, blocking included.
        assert "do not disturb, block a sender" in up.banner, up.banner
        token = add_sender(state_dir, "alice")
        assert add_sender(state_dir, "alice") == token  # the same name: the same account
        login = decode_join_token(token)
        assert login.username == "sender-alice"
        senders = up.call("state")["senders"]
        assert {"name": "alice", "blocked": False, "blockable": True} in senders  # type: ignore[operator]

        sent = send(token, tmp_path)
        assert sent.returncode == 0, sent.stdout + sent.stderr
        assert "The sleeve played" in sent.stdout, sent.stdout

        # A client of alice's, connected when the wearer blocks her.
        client = connected_client(
            parse_broker_url(login.url, username=login.username, password=login.password)
        )
        gone = threading.Event()
        client.on_disconnect = lambda *_: gone.set()
        try:
            state = up.call("block", {"sender": "alice"})
            assert {"name": "alice", "blocked": True, "blockable": True} in state["senders"]  # type: ignore[operator]
            assert gone.wait(WAIT_S), "the blocked sender's connection was not cut"
        finally:
            stop_loop(client)

        refused = send(token, tmp_path)
        assert refused.returncode != 0, refused.stdout + refused.stderr
        assert "The wearer blocked this sender" in refused.stderr, refused.stderr
        assert "Traceback" not in refused.stderr
        up.call("pause", {})

    # A restart of up keeps the block, and says the wearer's pause it kept.
    with running_up(state_dir, mqtt_port) as up:
        assert "The wearer's choices kept from before: paused (by page)" in up.banner, up.banner
        up.call("resume", {})
        assert {"name": "alice", "blocked": True, "blockable": True} in up.call("state")["senders"]  # type: ignore[operator]
        refused = send(token, tmp_path)
        assert "The wearer blocked this sender" in refused.stderr, refused.stderr
        up.call("unblock", {"sender": "alice"})
        sent = send(token, tmp_path)
        assert sent.returncode == 0, sent.stdout + sent.stderr
        assert "The sleeve played" in sent.stdout, sent.stdout


def _driven(record: Path) -> list[tuple[float, float]]:
    """The simulated sleeve's record: (wall ms, intensity) of every motor change."""
    if not record.exists():
        return []
    rows = [json.loads(line) for line in record.read_text().splitlines() if line.strip()]
    return [(row["wall_ms"], row["intensity"]) for row in rows]


def _on_at(changes: list[tuple[float, float]], wall_ms: float) -> bool:
    return any(at > wall_ms and level > 0 for at, level in changes)


@pytest.mark.parametrize(
    "how",
    [
        # Two long strokes, sent at their pace: the second still to come at the block.
        ["0,1,3,1,6000", "0,2,3,2,6000"],
        # One, every stroke out already: send waits for the sleeve's answers, none can come.
        ["0,1,3,1,6000", "--wait"],
    ],
    ids=["sending", "waiting"],
)
def test_blocking_a_sender_stops_what_it_already_sent(tmp_path: Path, how: list[str]) -> None:
    """A wearer blocks a sender to make it stop: its stroke playing is cut at once, its
    strokes waiting dropped, and its own ``send`` says it was cut off by the block."""
    state_dir = tmp_path / "up"
    record = tmp_path / "felt.jsonl"
    with running_up(state_dir, free_port(), "--record", str(record)) as up:
        token = add_sender(state_dir, "alice")
        env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
        env["XDG_STATE_HOME"] = str(tmp_path / "sender-state")
        sending = subprocess.Popen(
            [FEELMYSIGN, "send", "--join", token, *how],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        try:
            deadline = time.monotonic() + WAIT_S
            while not _on_at(_driven(record), 0):
                assert time.monotonic() < deadline, "the sender's stroke never played"
                assert sending.poll() is None, sending.communicate()
                time.sleep(0.05)
            time.sleep(1.0)  # well into the 6 s stroke
            up.call("block", {"sender": "alice"})
            blocked_ms = time.time() * 1000
            out, err = sending.communicate(timeout=WAIT_S)
        finally:
            if sending.poll() is None:
                sending.kill()
        time.sleep(2.0)  # the rest of the first stroke, the start of the second
        changes = _driven(record)
        off = [at for at, _ in changes if at >= blocked_ms - 500]
        levels: dict[tuple[int, int], float] = {}
        rows = [json.loads(line) for line in record.read_text().splitlines() if line.strip()]
        for row in rows:
            levels[(row["row"], row["column"])] = row["intensity"]
        assert all(level == 0 for level in levels.values()), levels
        assert not _on_at(changes, blocked_ms + 200), "a motor was driven after the block"
        assert off, "no motor change around the block"
        assert sending.returncode != 0, out + err
        # Cut off before the wearer's stop reached it: told by the broker's refusal; else
        # (waiting, the stop's answer can come before the broker's reload cuts it off) by
        # the sleeve's answer, which names the block too.
        blocked = "The wearer blocked this sender" in err
        assert blocked or (
            "--wait" in how and "The wearer (a pause, stop or block) cut or dropped" in err
        ), err
        assert "closed the connection" not in err, err


@pytest.mark.parametrize("name", ["page", "a/b", "", "x" * 65])
def test_add_sender_refuses_a_name_it_cannot_use(broker: Broker, name: str) -> None:
    added = subprocess.run(
        [FEELMYSIGN, "broker", "--state-dir", str(broker.state_dir), "add-sender", "--name", name],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert added.returncode == 1, added.stdout + added.stderr
    assert "1 to 64 letters, digits" in added.stderr and "Traceback" not in added.stderr
    assert added.stdout == "" and not broker.files.senders.exists()
