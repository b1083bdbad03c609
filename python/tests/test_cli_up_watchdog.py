"""``feelmysign up`` notices its broker died, starts it again, says when the sleeve is back.

A real ``feelmysign up`` process (its own Mosquitto, the simulated sleeve); the
test kills that Mosquitto with SIGKILL, by its process id.
"""

from __future__ import annotations

import contextlib
import json
import os
import queue
import re
import select
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path
from typing import IO

import pytest
from host_header import get

from feelmysign.broker.credentials import load_login
from feelmysign.connection import connect_client
from feelmysign.protocol import format_json
from feelmysign.services.drawing_log import QUIET_S
from feelmysign.stroke import Stroke
from feelmysign.topics import sleeve_topic

WAIT_S = 60.0


def _lines(process: subprocess.Popen[str]) -> queue.Queue[str]:
    lines: queue.Queue[str] = queue.Queue()

    def read() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            lines.put(line)

    threading.Thread(target=read, daemon=True).start()
    return lines


def _wait_for(lines: queue.Queue[str], text: str, seen: list[str]) -> None:
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        try:
            line = lines.get(timeout=0.5)
        except queue.Empty:
            continue
        seen.append(line)
        if text in line:
            return
    pytest.fail(f"no line with {text!r} in {WAIT_S:g} s:\n{''.join(seen)}")


def _interrupt(process: subprocess.Popen[str]) -> int:
    """Ctrl-C to up, and its exit code; killed (and the test failed) if it does not end."""
    process.send_signal(signal.SIGINT)
    try:
        return process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        process.kill()
        raise


def _mosquitto_children(pid: int) -> list[int]:
    found = subprocess.run(["pgrep", "-P", str(pid), "mosquitto"], capture_output=True, text=True)
    return [int(p) for p in found.stdout.split()]


def _start_up(tmp_path: Path, stderr: IO[str] | int = subprocess.STDOUT) -> subprocess.Popen[str]:
    """``feelmysign up`` on free ports with a stand-in page, its output in one stream."""
    web = tmp_path / "web"
    web.mkdir()
    (web / "index.html").write_text("<!doctype html><title>test</title>")
    command = [sys.executable, "-m", "feelmysign", "up", "--state-dir", str(tmp_path / "state")]
    command += ["--http-port", "0", "--port", "0", "--ws-port", "0", "--web-dir", str(web)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=stderr, text=True, bufsize=1)
    return process


def test_up_restarts_a_killed_broker_and_says_so_once(tmp_path: Path) -> None:
    """One line for the loss (what, and what up does), one for the return; nothing twice."""
    process = _start_up(tmp_path)
    seen: list[str] = []
    try:
        lines = _lines(process)
        _wait_for(lines, "Press Ctrl-C", seen)
        (mosquitto,) = _mosquitto_children(process.pid)
        before = len(seen)
        os.kill(mosquitto, signal.SIGKILL)
        _wait_for(lines, "Back: the broker is running again on", seen)
        assert _mosquitto_children(process.pid) not in ([], [mosquitto])
    finally:
        code = _interrupt(process)
    assert code == 0, "".join(seen)
    assert _mosquitto_children(process.pid) == []
    outage = seen[before:]
    assert len(outage) == 2, "".join(outage)
    lost, back = outage
    assert lost.startswith("The broker stopped (exit code -9; its log: "), lost
    assert "starting it again on the same ports" in lost, lost
    assert back.startswith("Back: the broker is running again on mqtt://127.0.0.1:"), back
    assert "the sleeve is connected to it" in back, back


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, dead but not reaped by its new parent, does not)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_a_restarted_broker_dies_with_up_killed_with_sigkill(tmp_path: Path) -> None:
    """The broker up started again (from its watchdog's thread) must not outlive a ``kill -9``
    of up: no handler runs then, only the kernel's parent-death signal."""
    process = _start_up(tmp_path)
    seen: list[str] = []
    restarted: list[int] = []
    try:
        lines = _lines(process)
        _wait_for(lines, "Press Ctrl-C", seen)
        (mosquitto,) = _mosquitto_children(process.pid)
        os.kill(mosquitto, signal.SIGKILL)
        _wait_for(lines, "Back: the broker is running again on", seen)
        restarted = _mosquitto_children(process.pid)
        assert len(restarted) == 1 and restarted != [mosquitto], restarted
        process.kill()
        process.wait(timeout=WAIT_S)
        deadline = time.monotonic() + 10
        while _alive(restarted[0]) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(restarted[0]), "the restarted broker outlived up's kill -9"
    finally:
        if process.poll() is None:
            process.kill()
        for pid in restarted:  # left behind by a failure: not for the next test to find
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)


def test_up_says_it_is_stopping_on_ctrl_c_and_reports_no_fault(tmp_path: Path) -> None:
    process = _start_up(tmp_path)
    seen: list[str] = []
    try:
        lines = _lines(process)
        _wait_for(lines, "Press Ctrl-C", seen)
        process.send_signal(signal.SIGINT)
        _wait_for(lines, "Stopped: sleeve (every motor off)", seen)
        code = process.wait(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    output = "".join(seen)
    assert code == 0, output
    assert "Stopping: every motor off" in output
    # A stop asked for is no fault: the sleeve leaving the broker is not reported as lost.
    assert "lost the broker" not in output, output
    assert output.index("Stopping:") < output.index("Stopped:")


def _read_until(descriptor: int, text: bytes) -> None:
    """Read from ``descriptor`` in this thread (a reading thread would hold the pipe open)."""
    read = b""
    deadline = time.monotonic() + WAIT_S
    while text not in read:
        assert time.monotonic() < deadline, f"no {text!r} in {WAIT_S:g} s: {read!r}"
        ready, _, _ = select.select([descriptor], [], [], 0.5)
        if ready:
            chunk = os.read(descriptor, 4096)
            assert chunk, f"the output ended before {text!r}: {read!r}"
            read += chunk


def test_up_goes_on_watching_after_its_reader_left(tmp_path: Path) -> None:
    """``feelmysign up | head -8``: the pipe closes, and the watchdog still restarts the broker."""
    with (tmp_path / "stderr.txt").open("w+") as stderr:
        process = _start_up(tmp_path, stderr)
        try:
            assert process.stdout is not None
            _read_until(process.stdout.fileno(), b"Press Ctrl-C")
            (mosquitto,) = _mosquitto_children(process.pid)
            process.stdout.close()  # what head does once it has its lines
            os.kill(mosquitto, signal.SIGKILL)  # the watchdog now prints into the closed pipe
            deadline = time.monotonic() + WAIT_S
            while _mosquitto_children(process.pid) in ([], [mosquitto]):
                assert process.poll() is None, "up ended when its reader left"
                assert time.monotonic() < deadline, "the watchdog did not restart the broker"
                time.sleep(0.2)
        finally:
            code = _interrupt(process)
        stderr.seek(0)
        errors = stderr.read()
    assert "Traceback" not in errors and "BrokenPipe" not in errors, errors
    assert code == 0, errors
    assert _mosquitto_children(process.pid) == []


def test_up_refuses_its_config_to_a_foreign_host_header(tmp_path: Path) -> None:
    """DNS rebinding: a page on attacker.example that resolves to 127.0.0.1 gets no password."""
    process = _start_up(tmp_path)
    seen: list[str] = []
    try:
        lines = _lines(process)
        _wait_for(lines, "Draw here:", seen)
        page = seen[-1].split("Draw here:", 1)[1].strip()
        port = int(page.split("://", 1)[1].split("/", 1)[0].rsplit(":", 1)[1])
        answers = {
            host: get(port, "/config.json", host, WAIT_S)
            for host in ("attacker.example", f"127.0.0.1:{port}")
        }
    finally:
        _interrupt(process)
    password = json.loads(answers[f"127.0.0.1:{port}"][1])["password"]
    assert answers[f"127.0.0.1:{port}"][0] == 200 and password
    status, body = answers["attacker.example"]
    assert status == 403 and password.encode() not in body


def _send_line(tmp_path: Path) -> str:
    """``feelmysign send --shape line`` with up's credentials; the drawing id it sent."""
    credentials = str(tmp_path / "state" / "credentials.json")
    command = [sys.executable, "-m", "feelmysign", "send", "--credentials", credentials]
    command += ["--shape", "line", "--pace", "burst"]
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    sent = subprocess.run(
        command, capture_output=True, text=True, timeout=WAIT_S, env=env, check=True
    )
    return sent.stdout.rsplit("(drawing ", 1)[1].split(")")[0]


def test_up_prints_its_drawing_lines_again_after_a_broker_restart(tmp_path: Path) -> None:
    """The drawing log listens again on the restarted broker: a clean session forgets
    subscriptions, so a drawing sent after "Back:" still gets its "Drawing" line."""
    process = _start_up(tmp_path)
    seen: list[str] = []
    try:
        lines = _lines(process)
        _wait_for(lines, "Press Ctrl-C", seen)
        before = _send_line(tmp_path)
        _wait_for(lines, f"Drawing {before[:8]}: ", seen)
        (mosquitto,) = _mosquitto_children(process.pid)
        os.kill(mosquitto, signal.SIGKILL)
        _wait_for(lines, "Back: the broker is running again on", seen)
        after = _send_line(tmp_path)
        _wait_for(lines, f"Drawing {after[:8]}: ", seen)
    finally:
        code = _interrupt(process)
    assert code == 0, "".join(seen)
    (line,) = [line for line in seen if line.startswith(f"Drawing {after[:8]}: ")]
    assert " played" in line and "rejected" not in line, line


def test_up_prints_one_line_for_a_drawing_whose_pen_rested(tmp_path: Path) -> None:
    """A stroke, a rest longer than a quiet spell, a stroke of the same drawing, then the
    next drawing: one "Drawing" line for the first, with both strokes."""
    process = _start_up(tmp_path)
    seen: list[str] = []
    resting, following = str(uuid.uuid4()), str(uuid.uuid4())
    try:
        lines = _lines(process)
        _wait_for(lines, "Press Ctrl-C", seen)
        sender = connect_client(
            load_login(tmp_path / "state" / "credentials.json", "sender"), "test-rested-pen"
        )
        strokes_topic = sleeve_topic("sleeve1", "strokes")

        def send(drawing: str, seq: int) -> None:
            stroke = Stroke((0.0, 0.0), (0.0, 1.0), 120.0, 0.8, drawing, seq, time.time() * 1000)
            sender.publish(strokes_topic, format_json(stroke), qos=1).wait_for_publish(WAIT_S)

        try:
            send(resting, 0)
            time.sleep(QUIET_S + 1.0)  # the pen rests: longer than a quiet spell
            send(resting, 1)
            send(following, 0)
            _wait_for(lines, f"Drawing {resting[:8]}", seen)
        finally:
            sender.disconnect()
            sender.loop_stop()
    finally:
        code = _interrupt(process)
    while True:  # what up printed up to its end (Ctrl-C prints what is left)
        try:
            seen.append(lines.get(timeout=2.0))
        except queue.Empty:
            break
    assert code == 0, "".join(seen)
    (line,) = [line for line in seen if line.startswith(f"Drawing {resting[:8]}")]
    # (strokes that queued on a loaded machine are said in brackets: played faster)
    assert re.match(rf"Drawing {resting[:8]}: 2 strokes played( \([^)]*\))?;", line), line


def test_up_restarts_a_broker_that_runs_but_answers_nothing(tmp_path: Path) -> None:
    """A Mosquitto stopped with SIGSTOP keeps its process and its ports (the kernel still
    takes connections) but answers nothing: up says so, and starts it again."""
    process = _start_up(tmp_path)
    seen: list[str] = []
    mosquitto = 0
    try:
        lines = _lines(process)
        _wait_for(lines, "Press Ctrl-C", seen)
        (mosquitto,) = _mosquitto_children(process.pid)
        before = len(seen)
        os.kill(mosquitto, signal.SIGSTOP)
        _wait_for(lines, "Back: the broker is running again on", seen)
        assert _mosquitto_children(process.pid) not in ([], [mosquitto])
        with pytest.raises(ProcessLookupError):  # the stopped one is gone, not left behind
            os.kill(mosquitto, 0)
        sent = _send_line(tmp_path)  # the new broker takes a drawing, and the sleeve plays it
        _wait_for(lines, f"Drawing {sent[:8]}: ", seen)
    finally:
        if mosquitto:
            with contextlib.suppress(ProcessLookupError):
                os.kill(mosquitto, signal.SIGCONT)
        code = _interrupt(process)
    assert code == 0, "".join(seen)
    outage = seen[before:]
    hung, back = outage[0], outage[1]
    assert hung.startswith(f"The broker (pid {mosquitto}) is running but answers nothing"), hung
    assert "starting it again on the same ports" in hung, hung
    assert "The broker stopped" not in "".join(outage), "".join(outage)
    assert back.startswith("Back: the broker is running again on"), back
    (line,) = [line for line in seen if line.startswith(f"Drawing {sent[:8]}: ")]
    assert " played" in line and "rejected" not in line, line
