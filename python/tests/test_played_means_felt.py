"""``played`` means felt: a real sleeve process, strokes paced in real time, its record read back.

Each stroke gets an intensity of its own, so the record (``--record``, every
actuator change) shows which strokes were felt: a stroke is felt when every
level its plan drives an actuator to (played alone) shows in the record.
Strokes are sent one after the other at the pace they play (each once the
previous one's last burst is over on the sleeve), as a person draws: the duty-cycle cap
must leave such use alone, and a stroke it does refuse must be reported as
``safety``/``duty_cycle``, never as ``played``.
"""

from __future__ import annotations

import json
import random
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

from sleeve_watch import SleeveWatch, online

from feelmysign.bench.sleeve import sleeve_command
from feelmysign.broker import Broker
from feelmysign.layout import Layout, load_layout
from feelmysign.planner import plan
from feelmysign.stroke import Stroke
from feelmysign.timeline import Timeline

REPO = Path(__file__).resolve().parents[2]
PAPER = REPO / "deploy" / "layouts" / "paper-sleeve.toml"
WAIT_S = 120.0
MARGIN_S = 0.06  # after a stroke's last burst, before the next stroke is sent
# A cap reached within seconds: a 2 s window, half of it at full drive.
TIGHT_SAFETY = (
    "[safety]\nmax_stroke_duration_ms = 1000\nmax_on_time_ms = 1000\n"
    "duty_cycle_window_ms = 2000\nmax_duty_cycle = 0.5\n"
)


def _strokes(count: int, seed: int, *, spot: bool) -> list[Stroke]:
    """Strokes with an intensity each: short all over the grid, from soft to strong (0.3 up
    to 0.9, whatever their count), or long and strong around one spot (0.85, 0.853, ...), so
    that one motor works hard."""
    rng = random.Random(seed)
    strokes = []
    for seq in range(count):
        if spot:
            start = (1.0 + rng.uniform(-0.2, 0.2), 1.0)
            end = (start[0] + 0.5, 1.0 + rng.uniform(-0.2, 0.2))
            duration_ms, intensity = rng.uniform(400, 600), 0.85 + 0.003 * seq
        else:
            start = (rng.uniform(0, 3), rng.uniform(0, 2))
            end = (rng.uniform(0, 3), rng.uniform(0, 2))
            duration_ms, intensity = rng.uniform(80, 120), 0.3 + 0.6 * seq / count
        strokes.append(Stroke(start, end, duration_ms, round(intensity, 3), "felt", seq))
    return strokes


def _levels(stroke: Stroke, layout: Layout) -> set[tuple[int, int, float]]:
    """What playing ``stroke`` alone drives: (row, column, intensity) of each "on" change."""
    timeline = Timeline(layout)
    timeline.add(plan(stroke, layout), 0.0)
    levels = set()
    while (t := timeline.next_ms()) is not None:
        for change in timeline.pop_due(t).changes:
            if change.intensity > 0:
                levels.add((change.row, change.column, round(change.intensity, 6)))
    return levels


def _felt(record: Path, strokes: list[Stroke], layout: Layout) -> set[int]:
    """The strokes whose every planned level shows in the record (intensities are unique)."""
    recorded = set()
    for line in record.read_text().splitlines():
        change = json.loads(line)
        recorded.add((change["row"], change["column"], round(change["intensity"], 6)))
    return {
        stroke.seq
        for stroke in strokes
        if stroke.seq is not None and _levels(stroke, layout) <= recorded
    }


def _started_at_s(events: SleeveWatch, stroke: Stroke, sent_at_s: float) -> float:
    """When the sleeve started ``stroke`` by the wall clock (its planned start), once its event
    is in; ``sent_at_s`` for a stroke that did not play (nothing of it runs on)."""
    found: list[dict[str, Any]] = []

    def told() -> bool:
        found[:] = [
            e
            for e in events.received("events")
            if e.get("drawing") == stroke.drawing and e.get("seq") == stroke.seq
        ]
        return bool(found)

    events.wait_until(told, f"an event about stroke {stroke.seq}", WAIT_S)
    start_at_ms = found[0].get("start_at_ms")
    return sent_at_s if start_at_ms is None else float(start_at_ms) / 1000


def _play_paced(
    broker: Broker, tmp_path: Path, layout_file: Path, strokes: list[Stroke]
) -> tuple[list[dict[str, Any]], set[int]]:
    layout = load_layout(layout_file)
    record = tmp_path / "record.jsonl"
    events = SleeveWatch(broker.credentials, "events", "status")
    sleeve = subprocess.Popen(
        sleeve_command(
            broker.credentials_path,
            "--layout",
            str(layout_file),
            "--record",
            str(record),
            "--no-legacy",
        ),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        events.next(online, "the sleeve online")
        for stroke in strokes:
            sent_at_s = time.time()
            events.send(stroke)
            last_burst_ms = max(c.end_ms for c in plan(stroke, layout).commands)
            # Paced by when the sleeve started the stroke, not by when it was sent: a message
            # held up on a busy machine would start late, and the next one, sent on time, would
            # then arrive while its last bursts still run (their levels add) or even while it
            # plays (it is played faster to catch up): neither plays as planned alone.
            started_at_s = _started_at_s(events, stroke, sent_at_s)
            time.sleep(max(0.0, started_at_s + last_burst_ms / 1000 + MARGIN_S - time.time()))
        events.wait_until(
            lambda: (
                len([e for e in events.received("events") if e.get("drawing") == "felt"])
                >= len(strokes)
            ),
            "an event about every stroke",
            WAIT_S,
        )
        told = [e for e in events.received("events") if e.get("drawing") == "felt"]
    finally:
        sleeve.send_signal(signal.SIGTERM)
        _, errors = sleeve.communicate(timeout=WAIT_S)
        events.close()
    assert sleeve.returncode == 0, errors
    return told, _felt(record, strokes, layout)


def test_strokes_paced_in_real_time_are_played_exactly_when_felt(
    broker: Broker, tmp_path: Path
) -> None:
    # Tens of strokes over the grid, a dozen seconds of drawing: each one a check of the
    # played event against the record.
    strokes = _strokes(80, seed=8, spot=False)
    told, felt = _play_paced(broker, tmp_path, PAPER, strokes)
    played = {e["seq"] for e in told if e["type"] in ("played", "adjusted")}
    assert played == felt
    # A pace a person draws at: the cap leaves every stroke alone.
    assert len(played) == len(strokes), [e for e in told if e["type"] != "played"][:3]


def test_strokes_the_duty_cycle_cap_refuses_are_reported_and_never_called_played(
    broker: Broker, tmp_path: Path
) -> None:
    layout_file = tmp_path / "tight.toml"
    paper = PAPER.read_text()
    safety = paper[paper.index("[safety]") : paper.index("[i2c]")]
    layout_file.write_text(paper.replace(safety, TIGHT_SAFETY + "\n"))
    # Ten seconds on one spot: the 2 s window fills, refuses, empties and plays again.
    strokes = _strokes(20, seed=9, spot=True)
    told, felt = _play_paced(broker, tmp_path, layout_file, strokes)
    played = {e["seq"] for e in told if e["type"] in ("played", "adjusted")}
    capped = [e for e in told if e["type"] == "safety"]
    assert played == felt
    assert capped, "the spot was never hot enough: the test proves nothing"
    assert played | {e["seq"] for e in capped} == set(range(len(strokes)))
    for event in capped:
        assert event["reason"] == "duty_cycle"
        assert event["duty_cycle"] > event["max_duty_cycle"] == 0.5
        assert event["window_ms"] == 2000
        planned = plan(strokes[event["seq"]], load_layout(layout_file)).commands
        assert (event["row"], event["column"]) in {(c.row, c.column) for c in planned}
