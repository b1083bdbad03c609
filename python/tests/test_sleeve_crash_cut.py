"""``kill -9`` of a real sleeve process in the middle of a stroke: the stroke it was playing
is not left recorded as played whole. The sleeve notes what plays in its state directory
(feelmysign.sleeve.pace_memory) before the stroke's ``played`` event leaves; the process
started next finds the note and reports that stroke cut short (a ``safety`` event
``crashed``, after its ``played``), which every reader counts as cut (feelmysign.fates). A
stroke that had ended before the kill is not reported."""

from __future__ import annotations

import json
import time
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import pytest
from conftest import StartBroker
from delivery import SleeveProcess, by_seq, delivery, played, stroke, wait_for

from feelmysign.events import event_from_json
from feelmysign.fates import DrawingFates
from feelmysign.protocol import CRASHED

SHORT_MS = 300.0
LONG_MS = 4000.0
KILL_INTO_S = 1.0  # how far into the long stroke the sleeve is killed
AFTER_END_S = 1.0  # how long after a stroke's end the sleeve is killed, in the second case


def crashed(events: list[dict[str, Any]], drawing: str) -> list[dict[str, Any]]:
    return [
        e
        for e in events
        if e["type"] == "safety" and e.get("reason") == CRASHED and e.get("drawing") == drawing
    ]


def fates(events: list[dict[str, Any]], drawing: str) -> dict[int, str]:
    """Each stroke's fate by the rule the page, ``up``, ``send`` and the study count by."""
    kept = DrawingFates()
    for event in events:
        if event.get("drawing") == drawing:
            kept.add(event_from_json(event))
    return dict(kept.fates())


def test_a_stroke_cut_by_kill_9_is_reported_cut_short(
    start_broker: StartBroker, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "sleeve-state"))  # the processes' own
    with (
        delivery(start_broker, tmp_path, sleeve_login=True) as (broker, watcher, first, sender),
        ExitStack() as later,
    ):
        # Sent at once, back to back: a short stroke that ends, then a long one killed midway.
        sender.publish(0, stroke(sender.drawing, 0, SHORT_MS, sent_at_ms=None))
        sender.publish(1, stroke(sender.drawing, 1, LONG_MS, sent_at_ms=None))
        wait_for(
            lambda: {1} <= {e["seq"] for e in played(watcher.snapshot())}, "the long stroke played"
        )
        long_played = next(e for e in played(watcher.snapshot()) if e["seq"] == 1)
        time.sleep(KILL_INTO_S)
        killed_ms = time.time() * 1000
        first.kill()
        assert killed_ms < long_played["first_command_at_ms"] + LONG_MS - 500, (
            "the machine was too slow: the long stroke was nearly over at the kill"
        )
        # The record so far, as the first process left it: both strokes played.
        assert fates(watcher.snapshot(), sender.drawing) == {0: "played", 1: "played"}

        later.enter_context(
            SleeveProcess(broker.sleeve_credentials_path, tmp_path / "second.jsonl")
        )
        wait_for(lambda: bool(crashed(watcher.snapshot(), sender.drawing)), "the cut-short event")
        time.sleep(0.5)  # any further event about the drawing would be out by now
        events = watcher.snapshot()

    [cut] = crashed(events, sender.drawing)
    assert cut["seq"] == 1, cut
    assert cut["received_at_ms"] == long_played["received_at_ms"], (cut, long_played)
    assert "cut short" in cut["message"] and "process ended" in cut["message"], cut
    # Played at least up to the first process's last sign of life, not all of it (it played
    # faster to catch up with its drawing: its played event says how long it was to last).
    seconds = [float(word) for word in cut["message"].replace(" s", " ").split() if _float(word)]
    assert len(seconds) == 2, cut["message"]
    assert seconds[0] <= KILL_INTO_S + 0.1 < seconds[1], cut["message"]
    assert seconds[1] == pytest.approx(long_played["duration_ms"] / 1000, abs=0.051), cut
    # After its played event, so every reader counts it cut short; the short one stays played.
    mine = [e for e in events if e.get("drawing") == sender.drawing]
    assert mine.index(cut) > mine.index(long_played)
    assert fates(events, sender.drawing) == {0: "played", 1: "cut"}
    assert [e["seq"] for e in by_seq(events, sender.drawing)[1] if e["type"] == "played"] == [1]


def test_a_stroke_that_ended_before_the_kill_is_not_reported_cut(
    start_broker: StartBroker, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "sleeve-state"))
    with (
        delivery(start_broker, tmp_path, sleeve_login=True) as (broker, watcher, first, sender),
        ExitStack() as later,
    ):
        sender.publish(0, stroke(sender.drawing, 0, SHORT_MS, sent_at_ms=None))
        wait_for(lambda: bool(played(watcher.snapshot())), "the stroke played")
        time.sleep(SHORT_MS / 1000 + AFTER_END_S)
        first.kill()
        state = tmp_path / "sleeve-state" / "feelmysign" / "pace"
        [kept] = list(state.glob("*.json"))
        # The note the first process left: nothing playing, written after the stroke's end.
        document = json.loads(kept.read_text())
        assert "playing" not in document, document
        assert document["alive_at_ms"] >= played(watcher.snapshot())[0]["start_at_ms"] + SHORT_MS

        later.enter_context(
            SleeveProcess(broker.sleeve_credentials_path, tmp_path / "second.jsonl")
        )
        # A stroke after the restart: an event about the first would have gone out before it.
        sender.publish(1, stroke(sender.drawing, 1, SHORT_MS, sent_at_ms=None))
        wait_for(lambda: len(played(watcher.snapshot())) == 2, "the second stroke played")
        time.sleep(0.3)
        events = watcher.snapshot()

    assert crashed(events, sender.drawing) == [], events
    assert fates(events, sender.drawing) == {0: "played", 1: "played"}


def _float(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def test_a_stroke_cut_by_a_clean_stop_is_reported_cut_short_at_once(
    start_broker: StartBroker, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGTERM (the service stopped or restarted) switches every motor off: the stroke playing
    is said cut short by the stopping sleeve itself (``safety`` ``stopped``), and the sleeve
    started next does not say it again."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "sleeve-state"))
    with (
        delivery(start_broker, tmp_path, sleeve_login=True) as (broker, watcher, first, sender),
        ExitStack() as later,
    ):
        sender.publish(0, stroke(sender.drawing, 0, LONG_MS, sent_at_ms=None))
        wait_for(lambda: bool(played(watcher.snapshot())), "the stroke played")
        time.sleep(KILL_INTO_S)
        first.stop()
        wait_for(
            lambda: any(e.get("reason") == "stopped" for e in watcher.snapshot()),
            "the stopped sleeve's last events",
        )
        events = watcher.snapshot()
        later.enter_context(
            SleeveProcess(broker.sleeve_credentials_path, tmp_path / "second.jsonl")
        )
        sender.publish(1, stroke(sender.drawing, 1, SHORT_MS, sent_at_ms=None))
        wait_for(lambda: len(played(watcher.snapshot())) == 2, "a stroke after the restart")
        time.sleep(0.3)
        after = watcher.snapshot()

    mine = [e for e in events if e.get("drawing") == sender.drawing]
    assert [(e["type"], e.get("reason")) for e in mine] == [("played", None), ("safety", "stopped")]
    assert fates(events, sender.drawing) == {0: "cut"}
    assert crashed(after, sender.drawing) == []
    assert fates(after, sender.drawing) == {0: "cut", 1: "played"}
