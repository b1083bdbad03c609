"""Free answers coded by synonyms; unclear ones are left for the researcher."""

from __future__ import annotations

from feelmysign.study.coding import code_answer, normalise

SYNONYMS = [("circle", ("circle", "ring", "round")), ("star", ("star", "star shape"))]


def test_answers_are_coded_only_when_they_point_to_one_shape() -> None:
    assert code_answer("A RING!", False, SYNONYMS).shape == "circle"
    assert code_answer("it felt like a star i think", False, SYNONYMS).shape == "star"
    assert code_answer("Círcle", False, SYNONYMS).shape == "circle"
    assert code_answer("a round star", False, SYNONYMS).status == "unclear"
    assert code_answer("a zigzag", False, SYNONYMS).status == "unclear"
    assert code_answer("no idea", False, SYNONYMS).status == "none"
    assert code_answer("", True, SYNONYMS).rule == "felt nothing"
    assert code_answer("starfish", False, SYNONYMS).status == "unclear"  # whole words only


def test_normalise_keeps_letters_and_digits_only() -> None:
    assert normalise("  Don't  KNOW... ") == "dont know"
