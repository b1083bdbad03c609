"""The simplifiers by name, and a whole recording through one, deterministically.

``ALGORITHMS`` is the registry every caller (CLI, vectors, research tools)
chooses from by name: each algorithm's parameter class, its streaming
simplifier and its parameter table. ``ONLY_FOR`` follows from the tables: the
parameters that only one algorithm has (giving one to the other is an error).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from feelmysign.simplify.angle import ANGLE_PARAMS, AngleParams, AngleSimplifier
from feelmysign.simplify.frames import frames_from_samples
from feelmysign.simplify.params import ParamSpec
from feelmysign.simplify.segment import Sample, Segment
from feelmysign.simplify.window import WINDOW_PARAMS, WindowParams, WindowSimplifier

Params = AngleParams | WindowParams


class Simplifier(Protocol):
    def push(self, item: Sample) -> list[Segment]: ...

    def end(self) -> list[Segment]: ...


@dataclass(frozen=True)
class Algorithm:
    """A simplifier by name: its parameters (with defaults), how to make one, its table.

    ``input`` is what it is fed: ``"frames"`` (animation frames, resampled from
    the samples at ``params.fps``) or ``"samples"`` (every pointer sample).
    """

    name: str
    params: type[Any]
    make: Callable[[Any], Simplifier]
    specs: dict[str, ParamSpec]
    summary: str
    input: str

    def inputs(self, params: Any, samples: Sequence[Sample]) -> list[Sample]:
        """What this simplifier is fed for one path drawn as ``samples``."""
        if self.input == "frames":
            return frames_from_samples(samples, params.fps)
        return list(samples)


ALGORITHMS: dict[str, Algorithm] = {
    "angle": Algorithm(
        "angle",
        AngleParams,
        AngleSimplifier,
        ANGLE_PARAMS,
        "the paper's turn-angle rule",
        "frames",
    ),
    "window": Algorithm(
        "window",
        WindowParams,
        WindowSimplifier,
        WINDOW_PARAMS,
        "error-bounded, cut at features",
        "samples",
    ),
}


def _only_for() -> dict[str, str]:
    owners: dict[str, list[str]] = {}
    for algorithm in ALGORITHMS.values():
        for name in algorithm.specs:
            owners.setdefault(name, []).append(algorithm.name)
    return {name: names[0] for name, names in owners.items() if len(names) == 1}


# The project's choice (see docs/research.md, "Default settings"), and the paper's.
DEFAULT_ALGORITHM = "window"
PAPER_ALGORITHM = "angle"

# Parameter name -> the one algorithm that has it.
ONLY_FOR: dict[str, str] = _only_for()


def algorithm_of(params: Params) -> Algorithm:
    """The registry entry whose parameter class ``params`` is."""
    for algorithm in ALGORITHMS.values():
        if type(params) is algorithm.params:
            return algorithm
    raise TypeError(f"no simplifier takes {type(params).__name__}")


@dataclass(frozen=True)
class PathSegment:
    """A segment and the index of the path it came from."""

    path: int
    segment: Segment


def simplify_paths(params: Params, paths: Sequence[Sequence[Sample]]) -> list[PathSegment]:
    """Every path fed to the simplifier (as frames or samples, see ``Algorithm``) and ended.

    The simplifier is the one ``params`` belongs to (``AngleParams`` -> angle).
    """
    algorithm = algorithm_of(params)
    simplifier = algorithm.make(params)
    out: list[PathSegment] = []
    for index, samples in enumerate(paths):
        for item in algorithm.inputs(params, samples):
            out += [PathSegment(index, s) for s in simplifier.push(item)]
        out += [PathSegment(index, s) for s in simplifier.end()]
    return out
