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

That participant (``--wearer template``, the default) recognises most shapes of the
paper's design at every tested resolution, so a dry run's needed resolutions are
mostly bounds ("at or below the lowest tested"). The **in-range wearer**
(``--wearer in-range``, ``InRangeWearer``) answers by a known psychometric curve per
shape instead, whose needed resolution lies inside the shape's tested range (the
geometric middle of its lowest and highest tested number of strokes), so that a dry run
exercises the point estimates and their intervals, and the analysis can be compared
with the truth (``in_range_truths``; ``study simulate`` prints it and the report shows
it beside the estimates).
"""

from __future__ import annotations

import json
import math
import random
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from feelmysign.layout import Layout
from feelmysign.shapes import MAX_SEGMENTS, SHAPES, shape_strokes
from feelmysign.stroke import Point, Stroke
from feelmysign.study.design import Design
from feelmysign.study.recognise import Scorer, dollar_scores, felt_path, outline
from feelmysign.study.stimulus import trial_strokes

if TYPE_CHECKING:
    from feelmysign.study.store import StudyStore

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


TEMPLATE, IN_RANGE = "template", "in-range"
WEARERS = (TEMPLATE, IN_RANGE)
# The in-range wearer's curves: steep enough that the tested levels span most of the
# curve, participants differing by a shift of their own (as in the calibration,
# docs/research.md), and the analysis's own lapse rate, so its model holds exactly.
IN_RANGE_SLOPE_PER_DOUBLING = 2.5
IN_RANGE_SPREAD_DOUBLINGS = 0.3
_WRONG_SILENT = 0.25  # of the wrong answers: felt nothing or don't know


@dataclass(frozen=True)
class ShapeTruth:
    """One shape's true curve for the in-range wearers: the average participant reaches
    the design's criterion at ``needed_strokes``; each participant's curve is
    ``midpoint_log2`` (+ their own shift of SD ``spread_doublings``), ``slope_per_doubling``,
    the design's guess rate and the analysis's lapse rate."""

    shape: str
    needed_strokes: float
    lowest_tested: int
    highest_tested: int
    midpoint_log2: float
    slope_per_doubling: float
    spread_doublings: float
    guess: float
    lapse: float


def in_range_truths(design: Design) -> dict[str, ShapeTruth]:
    """Per shape with two or more tested resolutions, the in-range wearers' curve."""
    from feelmysign.study.analysis.psychometric import LAPSE, Fit, Population

    out = {}
    for shape in design.shapes:
        levels = sorted({level.strokes for level in shape.levels})
        if len(levels) < 2:
            continue
        target_log2 = (math.log2(levels[0]) + math.log2(levels[-1])) / 2
        # The population's needed resolution moves with the midpoint one for one (in log2
        # strokes): found at midpoint 0, then shifted onto the target.
        at_zero = Population(
            Fit(0.0, IN_RANGE_SLOPE_PER_DOUBLING, design.guess_rate, LAPSE),
            IN_RANGE_SPREAD_DOUBLINGS,
        ).strokes_at(design.criterion)
        midpoint = target_log2 - math.log2(at_zero)
        out[shape.name] = ShapeTruth(
            shape.name,
            2.0**target_log2,
            levels[0],
            levels[-1],
            midpoint,
            IN_RANGE_SLOPE_PER_DOUBLING,
            IN_RANGE_SPREAD_DOUBLINGS,
            design.guess_rate,
            LAPSE,
        )
    return out


def truth_json(design: Design) -> dict[str, Any]:
    """The in-range wearers' truths as stored in the study file and written by the analysis."""
    return {
        "wearer": IN_RANGE,
        "criterion": design.criterion,
        "shapes": {name: vars(truth) for name, truth in in_range_truths(design).items()},
    }


# The study file's meta key of a dry run's known truth (``truth_json`` and the numbers of the
# participants who answered by it), for the analysis to show beside its estimates.
TRUTH_KEY = "simulated_truth"


def simulated_truth(store: StudyStore) -> dict[str, Any] | None:
    """The known truth of a dry run with in-range wearers (None: there was none)."""
    value = store.meta(TRUTH_KEY)
    return None if value is None else dict(json.loads(value))


@dataclass(frozen=True)
class InRangeWearer:
    """A simulated participant who answers by a known curve per shape (``in_range_truths``):
    right with the curve's probability at the trial's number of strokes, shifted by the
    participant's own amount; else a wrong shape (the one whose template the felt path
    resembles most, with noise), or now and then nothing felt or a don't-know."""

    seed: int
    truths: dict[str, ShapeTruth]
    noise: float = 0.04
    scorer: Scorer = dollar_scores

    def answer(
        self,
        strokes: Sequence[Stroke],
        layout: Layout,
        design: Design,
        known: dict[str, list[Point]],
        key: str,
        *,
        sent: str,
        segments: int,
    ) -> SimulatedAnswer:
        truth = self.truths.get(sent)
        rng = random.Random(f"{self.seed}:{key}")
        if truth is None:  # a shape with one resolution: no curve, always right
            return _named(design, sent, rng, 5)
        shift = random.Random(f"{self.seed}:shift").gauss(0.0, truth.spread_doublings)
        core = 1.0 / (
            1.0
            + math.exp(
                -truth.slope_per_doubling * (math.log2(segments) - truth.midpoint_log2 - shift)
            )
        )
        p_right = truth.guess + (1.0 - truth.guess - truth.lapse) * core
        if rng.random() < p_right:
            return _named(design, sent, rng, max(1, min(5, 1 + round(4 * p_right))))
        if rng.random() < _WRONG_SILENT:
            if rng.random() < 0.5:
                return SimulatedAnswer("", True, None, None)
            return SimulatedAnswer(rng.choice(_DONT_KNOW), False, 1, None)
        others = {name: path for name, path in known.items() if name != sent}
        felt = felt_path(strokes, layout)
        scores = self.scorer(felt, others) if felt and others else {}
        if not scores:
            return SimulatedAnswer("", True, None, None)
        chosen = max(scores, key=lambda name: scores[name] + rng.gauss(0.0, self.noise))
        return _named(design, chosen, rng, rng.randint(1, 3))


def _named(design: Design, shape: str, rng: random.Random, confidence: int) -> SimulatedAnswer:
    known = {s.name: s.synonyms for s in design.shapes}
    words = known.get(shape) or (shape,)  # a practice shape outside the design: its name
    word = rng.choice(words[: max(1, min(3, len(words)))])
    return SimulatedAnswer(rng.choice(_PHRASES).format(word), False, confidence, shape)
