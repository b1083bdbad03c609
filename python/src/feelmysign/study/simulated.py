"""A simulated participant: answers a trial from what the sleeve renders, with noise and lapses.

For dry runs and tests, before anyone is recruited. Per trial:

1. the felt path: the sleeve's own planner renders the trial's strokes
   (``recognise.felt_path``);
2. recognisability: the ``scorer`` ($1 template score) of that path against
   every shape of the study;
3. the choice (Thurstone's case V): each score plus Gaussian noise of SD
   ``noise``, and the highest wins, so shapes whose scores are close are
   confused (a 4-stroke circle with a heart), distinct ones are not;
4. lapses: with probability ``lapse_rate`` the answer is "felt nothing" or a
   don't-know; with ``unclear_rate`` it is a vague phrase the coder cannot
   place (so the review screen has work);
5. the words: a random synonym of the chosen shape, sometimes in a sentence,
   and a confidence 1-5 from the choice's probability.

Deterministic for a given ``seed`` and trial key.
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from feelmysign.layout import Layout
from feelmysign.shapes import MAX_SEGMENTS, SHAPES, shape_strokes
from feelmysign.stroke import Point, Stroke
from feelmysign.study.design import Design
from feelmysign.study.recognise import Scorer, dollar_scores, felt_path, outline
from feelmysign.study.stimulus import trial_strokes

_PHRASES = ("{}", "a {}", "{} I think", "it felt like a {}", "maybe a {}")
_UNCLEAR = ("something pointy", "a kind of zigzag", "hard to say, a wave?", "some loops")
_DONT_KNOW = ("no idea", "don't know")


@dataclass(frozen=True)
class SimulatedAnswer:
    answer: str
    felt_nothing: bool
    confidence: int | None
    intended: str | None  # the shape the simulated participant meant (None: no shape)


def templates(design: Design, layout: Layout, base_dir: Path) -> dict[str, list[Point]]:
    """Each shape's ideal outline: a library shape at its finest allowed count; a recorded
    drawing at its finest level (what the participant has in mind)."""
    out: dict[str, list[Point]] = {}
    for shape in design.shapes:
        spec = SHAPES.get(shape.name)
        if shape.recording is None and spec is not None:
            finest = spec.max_segments if spec.step > 1 else MAX_SEGMENTS
            out[shape.name] = outline(shape_strokes(shape.name, layout=layout, segments=finest))
        else:
            level = len(shape.levels) - 1
            strokes = trial_strokes(
                design, base_dir, shape.name, level=level, segments=None, drawing="t", layout=layout
            )
            out[shape.name] = outline(strokes)
    return out


@dataclass(frozen=True)
class SimulatedParticipant:
    seed: int
    noise: float = 0.04
    lapse_rate: float = 0.04
    unclear_rate: float = 0.03
    scorer: Scorer = dollar_scores

    def answer(
        self,
        strokes: Sequence[Stroke],
        layout: Layout,
        design: Design,
        known: dict[str, list[Point]],
        key: str,
    ) -> SimulatedAnswer:
        """The answer to one trial; ``known`` are the templates, ``key`` names the trial."""
        rng = random.Random(f"{self.seed}:{key}")
        if rng.random() < self.lapse_rate:
            if rng.random() < 0.5:
                return SimulatedAnswer("", True, None, None)
            return SimulatedAnswer(rng.choice(_DONT_KNOW), False, 1, None)
        if rng.random() < self.unclear_rate:
            return SimulatedAnswer(rng.choice(_UNCLEAR), False, 2, None)
        felt = felt_path(strokes, layout)
        scores = self.scorer(felt, known) if felt else {}
        if not scores:
            return SimulatedAnswer("", True, None, None)
        noisy = {name: s + rng.gauss(0.0, self.noise) for name, s in scores.items()}
        ranked = sorted(noisy.values(), reverse=True)
        chosen = max(noisy, key=lambda name: noisy[name])
        # Confidence grows with the margin over the runner-up, in units of the noise.
        margin = (ranked[0] - ranked[1]) / self.noise if len(ranked) > 1 else 5.0
        confidence = max(1, min(5, 1 + int(margin)))
        words = design.shape(chosen).synonyms
        word = rng.choice(words[: max(1, min(3, len(words)))])
        return SimulatedAnswer(rng.choice(_PHRASES).format(word), False, confidence, chosen)
