"""Code a free answer ("a ring, I think") as one of the design's shapes, using its synonyms.

The participant answers without options (section 6.1 step 3), so answers are
words, not choices. An answer is coded automatically only when it is clear:
it is a synonym, or it contains the synonyms of exactly one shape as whole
words. "Felt nothing" and don't-know answers are coded as no shape. Anything
else is ``unclear`` and waits for the researcher's decision (review), which is
stored beside the automatic one; nothing is overwritten.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal

Status = Literal["shape", "none", "unclear"]

# Said by people who felt something but cannot name it; coded as no shape (an error).
DONT_KNOW = ("dont know", "do not know", "no idea", "not sure", "unknown", "nothing", "none")
# Words that carry no shape: dropped before matching a whole answer to a synonym.
_FILLER = {
    "a",
    "an",
    "the",
    "like",
    "i",
    "think",
    "it",
    "was",
    "maybe",
    "perhaps",
    "some",
    "kind",
    "of",
    "sort",
}


@dataclass(frozen=True)
class Coding:
    status: Status
    shape: str | None  # the coded shape when status is "shape"
    rule: str  # why: "synonym 'ring'", "felt nothing", "two shapes: circle, star"


def normalise(text: str) -> str:
    """Lower case, accents and punctuation removed, single spaces: 'Círcle!' -> 'circle'."""
    decomposed = unicodedata.normalize("NFKD", text)
    plain = "".join(c for c in decomposed if not unicodedata.combining(c))
    plain = plain.replace("'", "").replace("\u2019", "")
    return " ".join(re.sub(r"[^a-z0-9]+", " ", plain.lower()).split())


def _contains(words: list[str], phrase: str) -> bool:
    target = phrase.split()
    return any(words[i : i + len(target)] == target for i in range(len(words) - len(target) + 1))


def code_answer(
    answer: str, felt_nothing: bool, synonyms: Iterable[tuple[str, Iterable[str]]]
) -> Coding:
    """Code ``answer`` given ``(shape, synonyms)`` pairs (synonyms already normalised)."""
    if felt_nothing:
        return Coding("none", None, "felt nothing")
    text = normalise(answer)
    if not text:
        return Coding("unclear", None, "empty answer")
    core = " ".join(w for w in text.split() if w not in _FILLER)
    table = [(shape, tuple(words)) for shape, words in synonyms]
    for shape, words in table:
        if text in words or core in words:
            return Coding("shape", shape, f"synonym {core if core in words else text!r}")
    if text in DONT_KNOW or core in DONT_KNOW:
        return Coding("none", None, f"no shape named ({text!r})")
    tokens = text.split()
    found = {shape: w for shape, words in table for w in words if _contains(tokens, w)}
    if len(found) == 1:
        shape, word = next(iter(found.items()))
        return Coding("shape", shape, f"contains synonym {word!r}")
    if len(found) > 1:
        return Coding("unclear", None, f"names {len(found)} shapes: {', '.join(sorted(found))}")
    return Coding("unclear", None, "no synonym of any shape")
