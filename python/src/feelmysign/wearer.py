"""A wearer's own limits, the sleeve's floor, and what a sender makes of them.

A wearer file (JSON, written by ``feelmysign study threshold --save``, read by
``feelmysign sleeve --wearer``; docs/study.md, "From the threshold to the sleeve")::

    {"wearer": "P01", "min_length": 0.62, "min_duration_ms": 118.4}

``min_length`` (grid units) and ``min_duration_ms`` are the shortest stroke whose
direction the wearer tells (SQ2.2's thresholds); either may be absent until
measured. A separate file, not a key of the layout: the layout is the sleeve's
hardware and stays the same whoever wears it, and the study writes this file
without touching the sleeve's configuration.

The sleeve's floor (``sleeve_floor``) is the larger of its own limits and the
wearer's; it publishes it in its retained status, and a sender raises its
simplifier's minimums to it (``respect_floor``), never lowering a higher setting.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from typing import Any

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.errors import FeelMySignError
from feelmysign.events import StatusFloor
from feelmysign.input_files import loads_json, read_text
from feelmysign.layout import MAX_GRID_SIDE, Layout
from feelmysign.planner import MERGE_DISTANCE
from feelmysign.plural import plural

MAX_WEARER_BYTES = 64 * 1024  # the file is under 100 bytes
MAX_NAME_CHARS = 64
# A wearer who cannot feel a stroke shorter than this has a sleeve that cannot reach them;
# beyond it a value is a unit mistake (seconds typed for milliseconds, cm for grid units).
MAX_WEARER_DURATION_MS = 5000.0
MAX_WEARER_LENGTH = float(MAX_GRID_SIDE)
KEYS = ("wearer", "min_length", "min_duration_ms")

# The sleeve's own shortest felt length: points closer than the planner's merge distance are
# one point to the skin (planner.MERGE_DISTANCE), so a shorter stroke has no direction.
SLEEVE_MIN_LENGTH = MERGE_DISTANCE


class WearerError(FeelMySignError):
    """A wearer file that cannot be used: the message names the key, the range and the fix."""


@dataclass(frozen=True)
class Wearer:
    name: str
    min_length: float | None = None  # grid units
    min_duration_ms: float | None = None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"wearer": self.name}
        if self.min_length is not None:
            out["min_length"] = self.min_length
        if self.min_duration_ms is not None:
            out["min_duration_ms"] = self.min_duration_ms
        return out


def wearer_from_json(data: Any, source: str) -> Wearer:
    """The wearer a file's JSON value describes; WearerError naming every problem."""
    fix = "correct it, or write it again with 'feelmysign study threshold --save'"
    if not isinstance(data, dict):
        raise WearerError(f"{source}: a wearer file is a JSON object like {_EXAMPLE}; {fix}")
    problems: list[str] = []
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        problems.append(f"unknown key(s) {', '.join(unknown)}; the keys are {', '.join(KEYS)}")
    name = data.get("wearer")
    if not isinstance(name, str) or not 1 <= len(name.strip()) <= MAX_NAME_CHARS:
        problems.append(f"wearer must be the wearer's code, 1 to {MAX_NAME_CHARS} characters")
    length = _limit(problems, data, "min_length", MAX_WEARER_LENGTH, "grid units")
    duration = _limit(problems, data, "min_duration_ms", MAX_WEARER_DURATION_MS, "ms")
    if "min_length" not in data and "min_duration_ms" not in data:
        problems.append("neither min_length nor min_duration_ms is given: nothing to apply")
    if problems:
        lines = "\n".join(f"  - {p}" for p in problems)
        raise WearerError(
            f"{source}: {plural(len(problems), 'problem')} in the wearer file:\n{lines}\n{fix}"
        )
    assert isinstance(name, str)
    return Wearer(name.strip(), length, duration)


_EXAMPLE = '{"wearer": "P01", "min_length": 0.6, "min_duration_ms": 120}'


def check_wearer_fits(wearer: Wearer, layout: Layout, source: str) -> None:
    """WearerError where no stroke on ``layout`` could keep to ``wearer``'s limits: a
    ``min_length`` beyond the grid's diagonal, or a ``min_duration_ms`` beyond the longest
    stroke the sleeve accepts. With either, every sender would send nothing at all."""
    problems = []
    longest = math.hypot(layout.rows - 1, layout.columns - 1)
    if wearer.min_length is not None and wearer.min_length > longest:
        problems.append(
            f"min_length = {wearer.min_length:g} grid units, but the longest stroke on this "
            f"{layout.rows} x {layout.columns} sleeve (its diagonal) is {longest:.3g}"
        )
    slowest = layout.max_stroke_duration_ms
    if wearer.min_duration_ms is not None and wearer.min_duration_ms > slowest:
        problems.append(
            f"min_duration_ms = {wearer.min_duration_ms:g}, but the sleeve plays no stroke "
            f"longer than {slowest:g} ms (the layout's safety.max_stroke_duration_ms)"
        )
    if problems:
        lines = "\n".join(f"  - {p}" for p in problems)
        raise WearerError(
            f"{source}: no stroke on this sleeve can keep to the wearer's limits, so senders "
            f"would send nothing:\n{lines}\ncheck that the file is this wearer's and this "
            "sleeve's, or measure the limits again on it ('feelmysign study threshold --save')"
        )


def _limit(
    problems: list[str], data: dict[str, Any], key: str, high: float, unit: str
) -> float | None:
    if key not in data:
        return None
    value = data[key]
    number = isinstance(value, int | float) and not isinstance(value, bool)
    if not number or not 0 < value <= high:
        problems.append(
            f"{key} = {json.dumps(value)} must be a number above 0 and at most {high:g} {unit}"
        )
        return None
    return float(value)


def read_wearer(path: str | os.PathLike[str]) -> Wearer:
    """The wearer file at ``path``; WearerError (never a traceback) when it cannot be used."""
    source = os.fspath(path)
    try:
        text = read_text(path, max_bytes=MAX_WEARER_BYTES)
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) and error.strerror else str(error)
        raise WearerError(
            f"{source}: cannot read the wearer file ({reason}); give the file that "
            "'feelmysign study threshold --save' wrote"
        ) from None
    try:
        data = loads_json(text)
    except ValueError as error:
        raise WearerError(f"{source}: not JSON ({error}); expected e.g. {_EXAMPLE}") from None
    return wearer_from_json(data, source)


def wearer_to_update(path: str | os.PathLike[str], name: str) -> Wearer:
    """What ``path`` holds for wearer ``name`` (nothing yet when it does not exist); WearerError
    when it cannot be updated. Checked before a run, so that a run is not lost to a bad file."""
    if not os.path.exists(path):
        return Wearer(name)
    kept = read_wearer(path)
    if kept.name != name:
        raise WearerError(
            f"{os.fspath(path)} holds wearer {kept.name!r}'s limits, not {name!r}'s; "
            "give another file, or remove it first"
        )
    return kept


def save_wearer(path: str | os.PathLike[str], name: str, dimension: str, value: float) -> Wearer:
    """Write ``value`` as the wearer's ``dimension`` limit into ``path``, keeping the other one
    when the file holds the same wearer's (each threshold run measures one dimension)."""
    kept = wearer_to_update(path, name)
    if dimension == "length":
        wearer = Wearer(name, value, kept.min_duration_ms)
    else:
        wearer = Wearer(name, kept.min_length, value)
    wearer_from_json(wearer.to_json(), os.fspath(path))  # in range, or said before writing
    temporary = f"{os.fspath(path)}.tmp"  # replaced at once: never a half-written file
    try:
        with open(temporary, "w", encoding="utf-8") as file:
            json.dump(wearer.to_json(), file, indent=1)
            file.write("\n")
        os.replace(temporary, path)
    except OSError as error:
        raise WearerError(
            f"cannot write the wearer file {os.fspath(path)} ({error.strerror or error}); the "
            "threshold is in the study file: give a writable path, or write "
            f"{json.dumps(wearer.to_json())} into a file by hand"
        ) from None
    return wearer


def sleeve_floor(layout: Layout, wearer: Wearer | None = None) -> StatusFloor:
    """The least stroke the sleeve plays as sent and its wearer feels: the larger of the two."""
    duration_ms = shortest_planned_ms(layout.shortest_burst_ms)
    length = SLEEVE_MIN_LENGTH
    if wearer is not None:
        duration_ms = max(duration_ms, wearer.min_duration_ms or 0.0)
        length = max(length, wearer.min_length or 0.0)
    return StatusFloor(
        min_duration_ms=duration_ms,
        min_length=length,
        wearer=None if wearer is None else wearer.name,
    )


def respect_floor(
    min_duration_ms: float, min_length: float, floor: StatusFloor | None
) -> tuple[float, float, str | None]:
    """A simplifier's minimums raised to the sleeve's floor (never lowered), and one line that
    says what was raised (None when nothing was).

    Only a floor with a wearer's measured limits is kept to. The motors' own floor alone is
    not: the simplifier drops a stroke below its minimums rather than merging it into its
    neighbour, and on people's gestures dropping the strokes briefer than the ERM floor
    (73.7 ms) costs more recognitions than the sleeve's slowing them does (it catches up
    afterwards; docs/research.md)."""
    if floor is None or not floor.wearer:
        return min_duration_ms, min_length, None
    raised: list[str] = []
    if floor.min_duration_ms > min_duration_ms:
        min_duration_ms = floor.min_duration_ms
        raised.append(f"min duration {min_duration_ms:g} ms")
    if floor.min_length > min_length:
        min_length = floor.min_length
        raised.append(f"min length {min_length:g} grid units")
    if not raised:
        return min_duration_ms, min_length, None
    whose = (
        f"the sleeve's floor with wearer {floor.wearer}'s limits"
        if floor.wearer
        else ("the sleeve's floor")
    )
    return min_duration_ms, min_length, f"Raised {' and '.join(raised)}: {whose}."
