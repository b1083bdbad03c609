"""The committed simulated gesture recordings are what their generator writes."""

from __future__ import annotations

from pathlib import Path

from feelmysign.research.gestures import load_all
from feelmysign.research.synthetic import PEOPLE, SHAPES, SPEEDS_MS, generate

COMMITTED = Path(__file__).resolve().parents[2] / "research" / "gestures"


def test_the_committed_set_is_the_generators(tmp_path: Path) -> None:
    written = generate(tmp_path)
    assert len(written) == len(SHAPES) * PEOPLE * len(SPEEDS_MS)
    committed = sorted(p.relative_to(COMMITTED) for p in COMMITTED.rglob("*.xml"))
    assert committed == sorted(p.relative_to(tmp_path) for p in written)
    for path in written:
        assert path.read_text() == (COMMITTED / path.relative_to(tmp_path)).read_text(), path


def test_faster_drawings_are_shorter_and_every_gesture_is_named() -> None:
    gestures = load_all([str(COMMITTED)])
    assert {g.gesture for g in gestures} == set(SHAPES)
    mean_ms = {
        speed: sum(g.recording.paths[0][-1].t_ms for g in gestures if g.set == speed)
        / (len(SHAPES) * PEOPLE)
        for speed in SPEEDS_MS
    }
    assert mean_ms["fast"] < mean_ms["medium"] < mean_ms["slow"]
    for g in gestures:
        times = [s.t_ms for s in g.recording.paths[0]]
        assert times[0] == 0 and times == sorted(times)
