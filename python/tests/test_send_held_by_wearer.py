"""``feelmysign send`` stops sending once the wearer pauses: a real sleeve (its chips and its
pause button emulated), a real Mosquitto, ``send`` as its own process drawing a shape at its
own pace; the wearer presses pause part-way. The sleeve cuts the stroke playing and refuses
what arrives paused, and ``send``, told so by the first of these, sends none of the rest: it
names them as not sent, its counts add up (one fate a stroke: a stroke cut part-way is not
also played), and it exits 3.
"""

from __future__ import annotations

import json
import re
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

from sleeve_watch import SleeveWatch, online, reaped
from test_wearer_button import PAUSE_LINE, paper_with_buttons, press, start

from feelmysign.bench.restart_off import feelmysign_command
from feelmysign.broker import Broker
from feelmysign.cli.send import WEARER_HOLD_EXIT
from feelmysign.events import event_from_json
from feelmysign.fates import DrawingFates

SEGMENTS = 24
WAIT_S = 120.0


def draw_and_interrupt(
    broker: Broker, tmp_path: Path, interrupt: Callable[[Path], None]
) -> tuple[int, str, str, list[dict[str, Any]]]:
    """A real sleeve (its chips and buttons emulated) and ``send --wait`` drawing a circle of
    SEGMENTS strokes, each a process of its own; once the third stroke plays (half a second a
    stroke: long before the last one, however busy the machine), ``interrupt(bus state)``.
    The send's exit code, output and errors, and the sleeve's events."""
    state, layout, home = tmp_path / "bus.json", paper_with_buttons(tmp_path), tmp_path / "s"
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        reaped(start(broker, state, layout, home)),
    ):
        watcher.next(online, "the sleeve online")
        sender = subprocess.Popen(
            [
                *feelmysign_command(),
                *("send", "--credentials", str(broker.credentials_path)),
                *("--shape", "circle", "--segments", str(SEGMENTS), "--duration-ms", "12000"),
                "--wait",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        with reaped(sender):
            played = lambda _n, b: b.get("type") == "played" and b.get("seq") == 2  # noqa: E731
            watcher.next(played, "the third stroke playing")
            interrupt(state)
            out, err = sender.communicate(timeout=WAIT_S)
        return sender.returncode, out, err, watcher.received("events")


def test_send_stops_at_the_wearers_pause_and_says_what_it_kept(
    broker: Broker, tmp_path: Path
) -> None:
    returncode, out, err, events = draw_and_interrupt(
        broker, tmp_path, lambda state: press(state, PAUSE_LINE)
    )
    assert returncode == WEARER_HOLD_EXIT, out + err
    fates = DrawingFates()
    for body in events:
        if body.get("seq") is not None:
            fates.add(event_from_json(json.dumps(body).encode()))
    answered = fates.fates()
    error = err.strip().splitlines()[-1]
    print(out, err, sep="\n")
    # What send says it kept back is exactly what the sleeve never heard of.
    held = re.search(r"(\d+) not sent \(from stroke (\d+) on\)", error)
    assert held is not None, error
    count, first = int(held[1]), int(held[2])
    assert count >= 1 and first - 1 + count == SEGMENTS
    assert sorted(answered) == list(range(first - 1)), (answered, error)
    # The answer send stopped on: a stroke refused as paused, or cut by the wearer's pause.
    by_wearer = [b for b in events if b.get("by") == "wearer"]
    assert fates.refusals().get("paused", 0) >= 1 or by_wearer, fates.refusals()
    # Its counts are the fates': played + cut + refused + not sent = every stroke.
    counts = fates.counts()
    assert f"The sleeve played {counts['played']} of {SEGMENTS} strokes" in error, error
    assert (
        counts["played"] + counts["cut"] + counts["cancelled"] + counts["refused"] + count
        == SEGMENTS
    )
    assert f"Sent {first - 1} of a circle of {SEGMENTS} strokes" in out, out


def test_send_stops_when_its_drawing_is_stopped(broker: Broker, tmp_path: Path) -> None:
    """``feelmysign stop`` while ``send --wait`` draws: the sleeve cuts the stroke playing, and
    ``send``, told so by the ``cancelled`` event, sends none of the rest (a stop of everything
    does not refuse later strokes: without this they would play on); it says why, exit 1."""
    credentials = ("--credentials", str(broker.credentials_path))

    def stop(_state: Path) -> None:
        subprocess.run([*feelmysign_command(), "stop", *credentials], check=True, timeout=60)

    returncode, out, err, received = draw_and_interrupt(broker, tmp_path, stop)
    assert returncode == 1, out + err
    events = [b for b in received if b.get("seq") is not None]
    error = err.strip().splitlines()[-1]
    held = re.search(r"(\d+) not sent \(from stroke (\d+) on\)", error)
    assert held is not None, error
    count, first = int(held[1]), int(held[2])
    assert count >= 1 and first - 1 + count == SEGMENTS
    # Nothing of the rest reached the sleeve: every event is about a stroke that was sent.
    assert max(b["seq"] for b in events) < first - 1, (events, error)
    assert any(b["type"] == "cancelled" for b in events), events
    assert "The drawing was stopped" in error, error
    assert "(the rest not sent: the drawing was stopped)" in out, out
