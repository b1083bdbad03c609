"""The wearer's stop on real sleeve processes: a drawing being sent is stopped whole.

A real ``feelmysign sleeve`` against a real Mosquitto, its chips and buttons emulated in a
state file (as in ``test_wearer_button``). A drawing is sent stroke by stroke, as a hand
draws it, while the wearer stops it: by holding the pause button (its first edge pauses at
once, the long press stops and undoes that pause) or from the wearer's page. The drawing
must end there, as a sender's Stop ends it: the stroke playing cut, and every later stroke
of that drawing, whenever it comes, ``cancelled`` by the wearer (strokes refused ``paused``
during the hold are told ``cancelled`` afterwards: the stop is what the sender hears last).
A new drawing then plays.
"""

from __future__ import annotations

import http.client
import json
import os
import queue
import re
import signal
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from lost_chip import wait_until
from sleeve_watch import SleeveWatch, exit_code_after, online, reaped
from test_wearer_button import (
    CHIP,
    PAUSE_LINE,
    _presses,
    controls_said,
    paper_with_buttons,
    start,
)

from feelmysign.backends.emulated_button import press_in, release_in
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.events import event_from_json
from feelmysign.fates import DrawingFates
from feelmysign.stroke import Stroke

pytestmark = pytest.mark.broker

STROKES = 30
STROKE_MS = 150.0
SEND_EVERY_S = 0.1  # a hand drawing: the strokes come while the first ones play
HOLD_S = 1.2  # past the long press (1 s)
WAIT_S = 60.0
WEARER_URL = re.compile(r"http://127\.0\.0\.1:(\d+)/wearer\?key=([\w-]+)")


def _draw(watcher: SleeveWatch, drawing: str) -> threading.Thread:
    """Send ``drawing``'s strokes one by one, on a thread, as a hand draws them."""

    def send() -> None:
        for seq in range(STROKES):
            watcher.send(Stroke((0.0, 1.0), (3.0, 1.0), STROKE_MS, 0.9, drawing, seq))
            time.sleep(SEND_EVERY_S)

    thread = threading.Thread(target=send, daemon=True)
    thread.start()
    return thread


def _fates(watcher: SleeveWatch, drawing: str) -> tuple[DrawingFates, list[dict[str, Any]]]:
    """Once every stroke of ``drawing`` is answered: its fates, and its events in order."""
    watcher.wait_until(
        lambda: (
            {b.get("seq") for _, b in watcher.history if b.get("drawing") == drawing}
            >= set(range(STROKES))
        ),
        f"an answer for every stroke of {drawing}",
    )
    time.sleep(0.5)  # any event still on its way (a stop told after the refusals)
    events = watcher.received("events")
    events = [b for b in events if b.get("drawing") == drawing]
    fates = DrawingFates()
    for body in events:
        fates.add(event_from_json(body))
    return fates, events


def _stopped_whole(fates: DrawingFates, events: list[dict[str, Any]]) -> None:
    """What a stopped drawing must look like: some strokes played, then at most one cut by
    the wearer, and every later stroke cancelled by the wearer; none played after."""
    found = fates.fates()
    print("fates:", found)
    played = sorted(seq for seq, fate in found.items() if fate == "played")
    assert played == list(range(len(played))), found  # played ones, then none
    after = [seq for seq in range(len(played), STROKES)]
    cut = [seq for seq in after if found[seq] == "cut"]
    assert cut in ([], [len(played)]), found
    assert all(found[seq] == "cancelled" for seq in after if seq not in cut), found
    assert len(after) > STROKES // 2, f"the stop came too late to test anything: {found}"
    # The last event of every stroke after the stop says the wearer stopped it.
    last: dict[int, dict[str, Any]] = {}
    for body in events:
        last[body["seq"]] = body
    for seq in after:
        assert (last[seq]["type"], last[seq].get("by")) == ("cancelled", "wearer"), last[seq]
    # None played (started) after the one cut.
    started = [b["seq"] for b in events if b["type"] == "played"]
    assert all(seq < len(played) or seq in cut for seq in started), started


def _the_next_drawing_plays(watcher: SleeveWatch) -> None:
    watcher.send(Stroke((0.0, 1.0), (3.0, 1.0), 300.0, 0.9, "next", 0))
    played = watcher.next(lambda n, b: b.get("drawing") == "next", "the next drawing's stroke")
    assert played["type"] == "played", played


def test_holding_the_pause_button_stops_the_drawing_being_sent(
    broker: Broker, tmp_path: Path
) -> None:
    state, layout, home = tmp_path / "bus.json", paper_with_buttons(tmp_path), tmp_path / "s"
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout, home)) as sleeve,
    ):
        watcher.next(online, "the sleeve online")
        sender = _draw(watcher, "a")
        watcher.next(lambda n, b: b.get("type") == "played", "the first stroke played")
        count = _presses(state, PAUSE_LINE)
        press_in(state, CHIP, PAUSE_LINE)
        wait_until(lambda: _presses(state, PAUSE_LINE) == count + 1, "the press taken")
        watcher.next(controls_said(paused=True), "paused at the press's first edge")
        time.sleep(HOLD_S)
        release_in(state, CHIP, PAUSE_LINE)
        # The long press undid its own pause: the sleeve plays again, for a new drawing.
        watcher.next(controls_said(paused=False), "the pause undone by the long press")
        sender.join(WAIT_S)
        fates, events = _fates(watcher, "a")
        _stopped_whole(fates, events)
        # Strokes came during the hold (refused paused) and after it (refused cancelled).
        assert any(b.get("reason") == "paused" for b in events), events
        _the_next_drawing_plays(watcher)
        assert exit_code_after(sleeve, signal.SIGTERM) == 0


def test_the_wearer_page_s_stop_stops_the_drawing_being_sent(
    broker: Broker, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    command = restart_off.sleeve_command(
        broker.credentials_path, state, "--wearer-page", "0", "--wearer-host", "127.0.0.1"
    )
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "s")}
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env
    )
    lines: queue.Queue[str] = queue.Queue()
    stdout = process.stdout
    assert stdout is not None

    def read() -> None:
        for line in stdout:
            lines.put(line)

    threading.Thread(target=read, daemon=True).start()
    with SleeveWatch(broker.credentials, "status", "events") as watcher, reaped(process):
        seen = ""
        while (found := WEARER_URL.search(seen)) is None:
            seen += lines.get(timeout=WAIT_S)
        port, key = int(found[1]), found[2]

        def stop() -> dict[str, Any]:
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=WAIT_S)
            headers = {"Cookie": f"feelmysign_wearer_key={key}", "Content-Type": "application/json"}
            connection.request("POST", "/api/wearer/stop", body=b"{}", headers=headers)
            answer = connection.getresponse()
            body = answer.read()
            connection.close()
            assert answer.status == 200, body
            return dict(json.loads(body))

        watcher.next(online, "the sleeve online")
        sender = _draw(watcher, "s")
        watcher.next(lambda n, b: b.get("type") == "played", "the first stroke played")
        assert stop()["controls"]["paused"] is False  # a stop does not pause
        sender.join(WAIT_S)
        fates, events = _fates(watcher, "s")
        _stopped_whole(fates, events)
        _the_next_drawing_plays(watcher)
        assert exit_code_after(process, signal.SIGTERM) == 0
