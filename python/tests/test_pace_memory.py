"""The pace's time lines across a restart (feelmysign.sleeve.pace_memory, PacePolicy.remember):
kept while strokes play, taken back at start within max_age_ms, and what they change: strokes
the broker held while the sleeve was down are late, not a new time line."""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import pytest

from feelmysign.events import Played, StrokeRef
from feelmysign.pace import LATE, PacePolicy
from feelmysign.sleeve.pace_memory import END_NOTE_MS, PACE_FORMAT, SAVE_EVERY_MS, PaceMemory
from feelmysign.sleeve.queue import REMEMBERED_DRAWINGS


def played(drawing: str | None, age_ms: float | None) -> Played:
    return Played(
        stroke=StrokeRef("feelmysign/sleeve/s/strokes", drawing, 0, 0.0, age_ms),
        start_at_ms=0.0,
        first_command_at_ms=0.0,
        latency_ms=0.3,
        start_error_ms=0.0,
        queued_ms=0.0,
        duration_ms=100.0,
        commands=2,
    )


class Clock:
    def __init__(self, now_ms: float = 1_000_000.0) -> None:
        self.now_ms = now_ms

    def __call__(self) -> float:
        return self.now_ms


def test_held_strokes_are_late_against_the_remembered_time_line() -> None:
    # A drawing whose strokes took 4 ms to arrive before the restart; after it, the broker
    # delivers one held 3 s, to an idle sleeve.
    sent_ms, held_ms = 1_000_000.0, 3000.0
    received_ms = sent_ms + held_ms
    fresh = PacePolicy()
    assert fresh.check("d", sent_ms, received_ms, received_ms, 100.0, 7).reason is None
    remembering = PacePolicy()
    remembering.remember([("d", 4.0)])
    verdict = remembering.check("d", sent_ms, received_ms, received_ms, 100.0, 7)
    assert verdict.reason == LATE
    assert verdict.lag_ms == pytest.approx(held_ms - 4.0)
    assert "held on the way" in verdict.message
    # A stroke drawn after the restart, in time: played, the sleeve back in real time.
    live = remembering.check("d", received_ms, received_ms + 5.0, received_ms + 5.0, 100.0, 30)
    assert live.reason is None and live.lag_ms == pytest.approx(1.0)
    # Another drawing is not touched by it.
    assert remembering.check("e", sent_ms, received_ms, received_ms, 100.0, 0).reason is None


def test_time_lines_are_kept_and_taken_back(tmp_path: Path) -> None:
    path = str(tmp_path / "pace" / "s.json")
    clock = Clock()
    memory = PaceMemory(path, clock_ms=clock)
    memory.played(played("a", 12.0))
    memory.played(played("b", 30.0))
    memory.played(played("a", 5.0))  # a smaller delay
    memory.played(played(None, 1.0))  # a stroke of no drawing: no time line
    memory.played(played("c", None))  # no sent_at_ms: none either
    # The first stroke is written at once; the others when the sleeve is quiet.
    assert [d for d, _, _ in json.loads(Path(path).read_text())["drawings"]] == ["a"]
    memory.save()
    document = json.loads(Path(path).read_text())
    assert document["format"] == PACE_FORMAT
    assert [d for d, _, _ in document["drawings"]] == ["b", "a"]
    clock.now_ms += 1000.0
    assert PaceMemory(path, clock_ms=clock).load(max_age_ms=10_000) == [("b", 30.0), ("a", 5.0)]
    # Drawings that played nothing within max_age_ms are over: not taken back.
    clock.now_ms += 9500.0
    assert PaceMemory(path, clock_ms=clock).load(max_age_ms=10_000) == []


def test_a_drawing_still_playing_is_brought_up_to_date_now_and_then(tmp_path: Path) -> None:
    path = str(tmp_path / "s.json")
    clock = Clock()
    memory = PaceMemory(path, clock_ms=clock)
    memory.played(played("a", 5.0))
    writes = []
    for _ in range(40):  # 4 s of strokes, 100 ms apart, none quicker than the first
        clock.now_ms += 100.0
        memory.played(played("a", 6.0))
        writes.append(json.loads(Path(path).read_text())["drawings"][0][2])
    assert 3 <= len(set(writes)) <= 4000 / SAVE_EVERY_MS + 1
    # So after 4 s of drawing the drawing is still taken back (its last write under 1 s old).
    assert PaceMemory(path, clock_ms=clock).load(max_age_ms=1500) == [("a", 5.0)]


def test_at_most_the_drawings_a_sleeve_remembers(tmp_path: Path) -> None:
    path = str(tmp_path / "s.json")
    clock = Clock()
    memory = PaceMemory(path, clock_ms=clock)
    for k in range(REMEMBERED_DRAWINGS + 10):
        memory.played(played(f"d{k}", 3.0))
    memory.save()
    loaded = PaceMemory(path, clock_ms=clock).load(max_age_ms=10_000)
    assert len(loaded) == REMEMBERED_DRAWINGS
    assert loaded[-1][0] == f"d{REMEMBERED_DRAWINGS + 9}" and loaded[0][0] == "d10"


@pytest.mark.parametrize(
    "text",
    [
        "not json",
        json.dumps({"format": "feelmysign-pace/0", "drawings": []}),
        json.dumps({"format": PACE_FORMAT, "drawings": [["a", 1.0]]}),
        json.dumps({"format": PACE_FORMAT, "drawings": [["a", True, 1.0]]}),
        '{"format": "feelmysign-pace/1", "drawings": [["a", NaN, 1.0]]}',
        json.dumps({"format": PACE_FORMAT, "drawings": [["a", 1.0, 2.0]], "pad": "x" * 70_000}),
    ],
)
def test_a_file_that_cannot_be_used_is_said_and_left_out(
    tmp_path: Path, text: str, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "s.json"
    path.write_text(text)
    with caplog.at_level(logging.WARNING):
        assert PaceMemory(str(path)).load(max_age_ms=10_000) == []
    assert "cannot be used" in caplog.text and str(path) in caplog.text


def test_a_state_folder_that_cannot_be_written_is_said_once(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    memory = PaceMemory(str(blocker / "pace" / "s.json"))  # a folder under a file
    with caplog.at_level(logging.WARNING):
        memory.played(played("a", 5.0))
        memory.played(played("b", 5.0))
    assert caplog.text.count("could not be kept") == 1


# --- the strokes playing, noted for the process started after a crash ------------------------


def started(clock: Clock, duration_ms: float, seq: int = 0, drawing: str | None = "a") -> Played:
    """The played event of a stroke whose first command went out now, by ``clock``."""
    now_ms = clock.now_ms
    return Played(
        stroke=StrokeRef("feelmysign/s/strokes", drawing, seq, now_ms - 9.0, 4.0, 0.0, now_ms - 5),
        start_at_ms=now_ms - 0.2,
        first_command_at_ms=now_ms,
        latency_ms=5.0,
        start_error_ms=0.2,
        queued_ms=0.0,
        duration_ms=duration_ms,
        commands=4,
    )


def test_a_stroke_playing_when_the_process_ends_is_reported_once(tmp_path: Path) -> None:
    path = str(tmp_path / "s.json")
    clock = Clock()
    memory = PaceMemory(path, clock_ms=clock)
    event = started(clock, 3000.0, seq=4)
    memory.playing(event)  # written at once: its played event goes out after this
    [note] = json.loads(Path(path).read_text())["playing"]
    assert (note["drawing"], note["seq"], note["received_at_ms"]) == ("a", 4, event.received_at_ms)
    # A heartbeat while it plays: the process ran a second into it.
    clock.now_ms += 400.0
    assert memory.keep_up() == pytest.approx(0.6)
    clock.now_ms += 600.0
    memory.keep_up()
    clock.now_ms += 700.0  # ... and died here, 1.7 s into the stroke
    restarted = PaceMemory(path, clock_ms=clock)
    restarted.load(max_age_ms=10_000)
    [interrupted] = restarted.interrupted()
    assert interrupted.playing.ref() == StrokeRef(
        "feelmysign/s/strokes", "a", 4, event.sent_at_ms, received_at_ms=event.received_at_ms
    )
    assert interrupted.played_at_least_ms == pytest.approx(1000.0)
    assert interrupted.duration_ms == pytest.approx(3000.0 - 0.2)
    # Reported by this process: its next write leaves the note out.
    restarted.save()
    again = PaceMemory(path, clock_ms=clock)
    again.load(max_age_ms=10_000)
    assert again.interrupted() == []


def test_a_stroke_that_ended_before_the_process_ended_is_not_reported(tmp_path: Path) -> None:
    path = str(tmp_path / "s.json")
    clock = Clock()
    memory = PaceMemory(path, clock_ms=clock)
    memory.playing(started(clock, 500.0))
    assert memory.keep_up() == pytest.approx((500.0 - 0.2 + END_NOTE_MS) / 1000)
    clock.now_ms += 500.0 - 0.2 + END_NOTE_MS  # the publishing thread wakes after its end
    assert memory.keep_up() == math.inf  # written: nothing plays now
    assert "playing" not in json.loads(Path(path).read_text())
    clock.now_ms += 3000.0  # the process dies later
    restarted = PaceMemory(path, clock_ms=clock)
    restarted.load(max_age_ms=10_000)
    assert restarted.interrupted() == []
    # Back to back: the next stroke's note drops the one that ended as it started.
    memory.playing(started(clock, 500.0, seq=1))
    clock.now_ms += 500.0 - 0.2
    memory.playing(started(clock, 500.0, seq=2))
    restarted = PaceMemory(path, clock_ms=clock)
    restarted.load(max_age_ms=10_000)
    assert [i.playing.seq for i in restarted.interrupted()] == [2]


def test_a_stroke_said_cut_while_the_process_ran_is_not_reported_again(tmp_path: Path) -> None:
    path = str(tmp_path / "s.json")
    clock = Clock()
    memory = PaceMemory(path, clock_ms=clock)
    event = started(clock, 3000.0, drawing=None)  # a legacy stroke: named by its receipt
    memory.playing(event)
    clock.now_ms += 100.0
    memory.settled(event.stroke)  # cancelled, or a chip lost: its event says cut already
    memory.save()  # a clean stop writes the file
    restarted = PaceMemory(path, clock_ms=clock)
    restarted.load(max_age_ms=10_000)
    assert restarted.interrupted() == []


@pytest.mark.parametrize(
    "playing",
    [
        "not a list",
        [{"drawing": "a"}],
        [{"received_at_ms": 1.0, "started_at_ms": 1.0, "ends_at_ms": "later"}],
        [{"received_at_ms": 1.0, "started_at_ms": 1.0, "ends_at_ms": 9e9, "seq": -1}],
    ],
)
def test_a_note_that_is_not_one_is_left_out(tmp_path: Path, playing: object) -> None:
    path = tmp_path / "s.json"
    document = {"format": PACE_FORMAT, "drawings": [], "playing": playing, "alive_at_ms": 0.0}
    path.write_text(json.dumps(document))
    memory = PaceMemory(str(path))
    assert memory.load(max_age_ms=10_000) == []
    assert memory.interrupted() == []
