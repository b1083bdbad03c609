"""The simulated participant's recogniser: the research $1 with the orientation fixed."""

from __future__ import annotations

import math

import numpy as np

from feelmysign.layout import PAPER_SLEEVE
from feelmysign.research import dollar
from feelmysign.shapes import shape_strokes
from feelmysign.study.recognise import dollar_scores, felt_path, outline

SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)]


def _turned(points: list[tuple[float, float]], degrees: float) -> list[tuple[float, float]]:
    a = math.radians(degrees)
    return [
        (x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)) for x, y in points
    ]


def test_a_diamond_is_not_a_square_on_the_arm_but_is_one_to_the_rotation_free_recogniser() -> None:
    diamond = _turned(SQUARE, 45.0)
    fixed = dollar_scores(diamond, {"square": SQUARE})["square"]
    assert dollar_scores(SQUARE, {"square": SQUARE})["square"] > 0.999
    assert fixed < 0.9
    free = dollar.Templates.of([("square", np.array(SQUARE))])
    assert dollar.scores(np.array(diamond), free)[0] > fixed


def test_a_line_stays_a_line_and_keeps_its_direction() -> None:
    across, down = [(0.0, 0.0), (3.0, 0.0)], [(0.0, 0.0), (0.0, 3.0)]
    scores = dollar_scores(across, {"across": across, "down": down})
    assert scores["across"] > 0.999 > scores["down"]


def test_the_felt_path_of_a_fine_circle_scores_highest_as_the_circle() -> None:
    known = {
        name: outline(shape_strokes(name, layout=PAPER_SLEEVE, segments=segments))
        for name, segments in (("circle", 32), ("square", 16), ("triangle", 15))
    }
    felt = felt_path(shape_strokes("circle", layout=PAPER_SLEEVE, segments=16), PAPER_SLEEVE)
    scores = dollar_scores(felt, known)
    assert max(scores, key=lambda name: scores[name]) == "circle"
    assert all(0.0 <= s <= 1.0 for s in scores.values())
