"""The simplifiers by name, and a whole recording through one, deterministically.

``ALGORITHMS`` is the registry every caller (CLI, vectors, research tools)
chooses from by name: each algorithm's parameter class, its streaming
simplifier and its parameter table. ``PARAMETERS``, ``OWNERS`` and ``ONLY_FOR``
follow from the tables: every parameter once, the algorithms that have it, and
the parameters that only one algorithm has (giving one to the other is an error).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Any, Protocol

from feelmysign.simplify.angle import ANGLE_PARAMS, AngleParams, AngleSimplifier
from feelmysign.simplify.angle import SWEEPS as ANGLE_SWEEPS
from feelmysign.simplify.angle import describe as describe_angle
from feelmysign.simplify.frames import frames_from_samples
from feelmysign.simplify.params import ParamSpec
from feelmysign.simplify.segment import Sample, Segment
from feelmysign.simplify.window import SWEEPS as WINDOW_SWEEPS
from feelmysign.simplify.window import WINDOW_PARAMS, WindowParams, WindowSimplifier
from feelmysign.simplify.window import describe as describe_window

if TYPE_CHECKING:
    from feelmysign.simplify.recording import Recording

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
    # The settings that shape the strokes, in a few words (``feelmysign simplify``'s summary).
    describe: Callable[[Any], str]
    # The parameter grid ``feelmysign evaluate`` sweeps without --sweep (NAME=FROM:TO:STEP).
    sweeps: tuple[str, ...]

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
        describe_angle,
        ANGLE_SWEEPS,
    ),
    "window": Algorithm(
        "window",
        WindowParams,
        WindowSimplifier,
        WINDOW_PARAMS,
        "error-bounded, cut at features",
        "samples",
        describe_window,
        WINDOW_SWEEPS,
    ),
}


# The project's choice (see docs/research.md, "Default settings"), and the paper's.
DEFAULT_ALGORITHM = "window"
PAPER_ALGORITHM = "angle"


def _owners() -> dict[str, list[str]]:
    """Every parameter -> the algorithms that have it: the default algorithm's own first, then
    the others' own, then the shared ones (the order of the CLI's options and the page's panel).
    """
    order = [DEFAULT_ALGORITHM, *(name for name in ALGORITHMS if name != DEFAULT_ALGORITHM)]
    owners: dict[str, list[str]] = {}
    for algorithm in (ALGORITHMS[name] for name in order):
        for name in algorithm.specs:
            owners.setdefault(name, [])
    for algorithm in ALGORITHMS.values():
        for name in algorithm.specs:
            owners[name].append(algorithm.name)
    shared = [name for name, names in owners.items() if len(names) > 1]
    return {name: owners[name] for name in [*(n for n in owners if n not in shared), *shared]}


# Parameter name -> the algorithms that have it, in the order above.
OWNERS: dict[str, list[str]] = _owners()

# Every parameter of every algorithm, by name, in the order above.
PARAMETERS: dict[str, ParamSpec] = {
    name: ALGORITHMS[names[0]].specs[name] for name, names in OWNERS.items()
}

# Parameter name -> the one algorithm that has it.
ONLY_FOR: dict[str, str] = {name: names[0] for name, names in OWNERS.items() if len(names) == 1}


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


def params_for(algorithm: Algorithm, recording: Recording, overrides: dict[str, Any]) -> Params:
    """The algorithm's defaults on the recording's canvas and sleeve, then ``overrides``."""
    base = algorithm.params()
    names = {f.name for f in fields(base)}
    canvas = {
        "canvas_width_px": recording.width_px,
        "canvas_height_px": recording.height_px,
        "rows": recording.rows or base.rows,
        "columns": recording.columns or base.columns,
    }
    params: Params = replace(base, **{k: v for k, v in canvas.items() if k in names}, **overrides)
    return params
