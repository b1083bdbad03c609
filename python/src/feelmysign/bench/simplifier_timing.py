"""Does the felt drawing keep pace with the pen? The timing ratios behind the defaults.

The 210 LASA drawings as drawn, and re-timed to three drawing speeds (slow
2.4 s, normal 1.2 s, fast 0.6 s a shape, at 125 Hz), go through the project's
default simplifier and the paper's settings; each stroke is planned as the
sleeve plans it and played back to back as the sleeve plays them
(``feelmysign.research.playback``). Printed per set: time on the skin divided
by drawing time (mean and 95th percentile over the drawings), release to felt
end (95th percentile), pen to skin (95th percentile), and the share of
drawings the $1 recogniser names from the strokes sent, against the drawings
themselves. The same figures come from
``feelmysign evaluate --lasa --speeds --defaults``.

The simulated gesture recordings in ``research/gestures`` follow, as ratios
only. ``python -m feelmysign.bench.simplifier_timing`` prints this group alone.

Nothing here is timed (playback is simulated), so its parts run in two processes at once:
the default simplifier in one, the paper's and the gestures in the other.
"""

from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from feelmysign.research.dollar import Templates
from feelmysign.research.evaluate import (
    Recogniser,
    Run,
    Source,
    evaluate,
    file_sources,
    summarize,
)
from feelmysign.research.gestures import load_all
from feelmysign.research.lasa import load_lasa
from feelmysign.research.speeds import SPEEDS_MS, retimed
from feelmysign.simplify.registry import ALGORITHMS, DEFAULT_ALGORITHM, PAPER_ALGORITHM


def sources() -> tuple[list[Source], Recogniser]:
    demos = load_lasa()
    templates = Templates.of(
        [(d.shape, np.array([(s.x, s.y) for s in d.recording.paths[0]])) for d in demos]
    )
    found = [Source(d.name, d.shape, d.recording, "lasa", i) for i, d in enumerate(demos)]
    for speed, total_ms in SPEEDS_MS.items():
        found += [
            Source(f"{d.name}@{speed}", d.shape, retimed(d.recording, total_ms), speed, i)
            for i, d in enumerate(demos)
        ]
    return found, Recogniser(templates)


def report() -> list[str]:
    lines = [
        "Felt drawing against the pen (210 LASA drawings as drawn and at three speeds; "
        "skin = time on the skin / drawing time)"
    ]
    # Two processes, about as much work in each (the window simplifier costs the most).
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        default = pool.submit(lasa_lines, "default", DEFAULT_ALGORITHM)
        paper_and_gestures = pool.submit(_paper_and_gestures)
        lines += default.result() + paper_and_gestures.result()
    return lines


def lasa_lines(label: str, name: str) -> list[str]:
    """The LASA figures of simplifier ``name`` at its defaults, labelled ``label``."""
    found, recogniser = sources()
    rows = evaluate(found, [Run(ALGORITHMS[name], {})], recogniser=recogniser, shape_metrics=False)
    return [
        f"  {label} ({name}) {entry['set']:<6}: skin mean {entry['skin_ratio_mean']:.3f}, "
        f"p95 {entry['skin_ratio_p95']:.3f}; release to felt end p95 "
        f"{entry['release_to_felt_end_p95_ms']:.0f} ms; pen to skin p95 "
        f"{entry['pen_to_skin_p95_ms']:.0f} ms; recognised "
        f"{entry['recognised_sent_pct']:.1f} % sent / "
        f"{entry['recognised_drawn_pct']:.1f} % drawn; {entry['strokes_mean']:.2f} strokes"
        for entry in summarize(rows)
    ]


def _paper_and_gestures() -> list[str]:
    return lasa_lines("paper", PAPER_ALGORITHM) + gesture_report()


# The simulated gesture recordings (research/gestures), when run from the repository.
GESTURES = Path(__file__).resolve().parents[4] / "research" / "gestures"


def gesture_report() -> list[str]:
    """The same at the default settings on the simulated gestures, as ratios only."""
    if not GESTURES.is_dir():
        return []
    found, recogniser = file_sources(load_all([str(GESTURES)]))
    rows = evaluate(
        found, [Run(ALGORITHMS[DEFAULT_ALGORITHM], {})], recogniser=recogniser, shape_metrics=False
    )
    lines = [
        "Simulated gestures (research/gestures, 16 gestures x 10 people x 3 speeds) at the "
        "defaults: skin = time on the skin / drawing time; recognised = sent / drawn"
    ]
    for entry in summarize(rows):
        lines.append(
            f"  default ({DEFAULT_ALGORITHM}) {entry['set']:<6}: skin mean "
            f"{entry['skin_ratio_mean']:.3f}, p95 {entry['skin_ratio_p95']:.3f}; recognised "
            f"{entry['recognised_sent_pct'] / entry['recognised_drawn_pct']:.3f}"
        )
    return lines


if __name__ == "__main__":
    for line in report():
        print(line)
