"""A gesture log holds pointer events alone, and a pointer held still sends none: the loader
gives the simplifier what the page would, the still pointer sampled where it is every
STILL_SAMPLE_MS (web/src/ui/pointer.ts), so that a stop is a rest and is not played."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from test_cli_evaluate import gesture_log

from feelmysign.research.gestures import STILL_SAMPLE_MS, load_gesture_log, with_still_samples
from feelmysign.simplify.window import WindowParams, WindowSimplifier

POINTER_TS = Path(__file__).parents[2] / "web" / "src" / "ui" / "pointer.ts"


def test_the_page_and_the_loader_sample_a_still_pointer_as_often() -> None:
    found = re.search(r"export const STILL_SAMPLE_MS = (\d+);", POINTER_TS.read_text())
    assert found is not None, f"no STILL_SAMPLE_MS in {POINTER_TS}"
    assert float(found.group(1)) == STILL_SAMPLE_MS


def test_a_gap_gets_the_still_pointer_every_period_and_a_short_one_nothing() -> None:
    x = np.array([5.0, 6.0, 9.0, 10.0])
    y = np.array([1.0, 2.0, 3.0, 4.0])
    t = np.array([0.0, 20.0, 20.0 + 3.5 * STILL_SAMPLE_MS, 21.0 + 3.5 * STILL_SAMPLE_MS])
    sx, sy, st = with_still_samples(x, y, t)
    # Three samples held at the point before the gap, one period apart; the others as given.
    assert list(sx) == [5.0, 6.0, 6.0, 6.0, 6.0, 9.0, 10.0]
    assert list(sy) == [1.0, 2.0, 2.0, 2.0, 2.0, 3.0, 4.0]
    assert list(st) == [0.0, 20.0, *(20.0 + k * STILL_SAMPLE_MS for k in (1, 2, 3)), *t[2:]]
    regular = np.arange(10) * (STILL_SAMPLE_MS - 1)
    assert all(
        np.array_equal(a, b)
        for a, b in zip(with_still_samples(regular, regular, regular), (regular,) * 3, strict=True)
    )


def test_a_stop_in_a_gesture_log_is_a_rest_and_not_played(tmp_path: Path) -> None:
    """A line, the pen held 600 ms (no event), a move of a few pixels, then on: drawn as a
    person drew arrow heads in the $1 study. Without the still samples the stop was one stroke
    as long as the stop, felt as a buzz that held every later stroke back."""
    out = [(100.0 + 4 * k, 100.0, 16.0 * k) for k in range(30)]  # to (216, 100) at 464 ms
    stop_ms = out[-1][2]
    back = [(219.0 + 4 * k, 104.0 + 3 * k, stop_ms + 600 + 16.0 * k) for k in range(30)]
    path = tmp_path / "s01" / "slow" / "arrow01.xml"
    gesture_log(path, "arrow01", "slow", out + back)
    recording = load_gesture_log(path).recording
    simplifier = WindowSimplifier(
        WindowParams(canvas_width_px=recording.width_px, canvas_height_px=recording.height_px)
    )
    strokes = [s for sample in recording.paths[0] for s in simplifier.push(sample)]
    strokes += simplifier.end()
    sent = [s for s in strokes if s.dropped is None]
    assert sent, strokes
    # No stroke plays the stop: none starts before it and ends after it, none lasts half of it.
    assert [s for s in sent if s.start_ms < stop_ms + 1 and s.end_ms > stop_ms + 599] == []
    assert max(s.end_ms - s.start_ms for s in sent) < 300, sent
