"""Parameter grids: ``NAME=FROM:TO:STEP`` (or ``NAME=VALUE``) per parameter, crossed.

Each algorithm is run on the product of the sweeps of its own parameters; a
parameter it does not have is not its concern (``max_error`` is the window
simplifier's). An algorithm none of whose parameters is swept runs once, with
its defaults. Without any ``--sweep``, ``DEFAULT_SWEEPS`` applies.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from feelmysign.errors import FeelMySignError
from feelmysign.simplify.registry import ALGORITHMS, PAPER_ALGORITHM, PARAMETERS, Algorithm

# Each algorithm's own (see ``Algorithm.sweeps``).
DEFAULT_SWEEPS: dict[str, tuple[str, ...]] = {a.name: a.sweeps for a in ALGORITHMS.values()}
# The swept parameters as plots name them, to fit a legend.
SHORT_NAMES: dict[str, str] = {s.name: s.short for s in PARAMETERS.values() if s.short}
MAX_VALUES = 1000  # a typo in STEP should not start a week of work
# Only decimal noise of FROM + k * STEP is rounded away.
DIGITS = 9


class SweepError(FeelMySignError):
    """A --sweep that cannot be read or names no parameter of the chosen algorithms."""


@dataclass(frozen=True)
class Sweep:
    name: str
    values: tuple[float, ...]


def parse_sweep(text: str) -> Sweep:
    """``NAME=FROM:TO:STEP`` (TO included when the steps land on it) or ``NAME=VALUE``."""
    name, sep, spec = text.partition("=")
    name = name.strip().replace("-", "_")
    if not sep or not name:
        raise SweepError(
            f"--sweep {text!r}: write NAME=FROM:TO:STEP, e.g. {DEFAULT_SWEEPS[PAPER_ALGORITHM][0]}"
        )
    words = {"true": "1", "false": "0"}  # a true/false parameter: NAME=true, or 0:1:1 for both
    parts = [words.get(p.strip().lower(), p) for p in spec.split(":")]
    try:
        numbers = [float(p) for p in parts]
    except ValueError:
        raise SweepError(
            f"--sweep {text!r}: FROM, TO and STEP must be numbers (a true/false parameter takes"
            " true, false or 0:1:1)"
        ) from None
    if len(numbers) == 1:
        return Sweep(name, (numbers[0],))
    if len(numbers) != 3:
        raise SweepError(f"--sweep {text!r}: write NAME=FROM:TO:STEP or NAME=VALUE")
    start, stop, step = numbers
    if not all(math.isfinite(v) for v in numbers) or step <= 0 or stop < start:
        raise SweepError(f"--sweep {text!r}: need FROM <= TO and a STEP above 0")
    count = math.floor((stop - start) / step + 1e-9) + 1
    if count > MAX_VALUES:
        raise SweepError(f"--sweep {text!r} gives {count} values; at most {MAX_VALUES}")
    return Sweep(name, tuple(round(start + k * step, DIGITS) for k in range(count)))


def parameter_sets(algorithm: Algorithm, sweeps: Sequence[Sweep]) -> list[dict[str, Any]]:
    """The overrides of every point of ``algorithm``'s grid, in sweep order (one: {})."""
    own = [s for s in sweeps if s.name in algorithm.specs]
    axes: list[list[tuple[str, Any]]] = []
    for sweep in own:
        kind = algorithm.specs[sweep.name].kind
        if kind is bool:
            if not all(v in (0.0, 1.0) for v in sweep.values):
                raise SweepError(
                    f"--sweep {sweep.name}: a true/false parameter takes 0 or 1 (false or true),"
                    f" got {sweep.values}; e.g. {sweep.name}=0:1:1 for both"
                )
            axes.append([(sweep.name, v == 1.0) for v in sweep.values])
            continue
        if kind is int and not all(float(v).is_integer() for v in sweep.values):
            raise SweepError(f"--sweep {sweep.name}: whole numbers only, got {sweep.values}")
        axes.append([(sweep.name, int(v) if kind is int else v) for v in sweep.values])
    points = [dict(point) for point in itertools.product(*axes)]
    _check_read(algorithm, own, points)
    return points


def _check_read(
    algorithm: Algorithm, sweeps: Sequence[Sweep], points: Sequence[dict[str, Any]]
) -> None:
    """SweepError for a swept parameter that one core reads (``only_when``) and no point of the
    grid runs: its values would all give the same strokes."""
    defaults = {name: spec.default for name, spec in algorithm.specs.items()}
    for sweep in sweeps:
        spec = algorithm.specs[sweep.name]
        if spec.only_when is None:
            continue
        if not any(spec.applies({**defaults, **point}) for point in points):
            switch, value = spec.only_when
            word = "true" if value else "false"
            raise SweepError(
                f"--sweep {sweep.name}: only read with {switch} {word}, which no run has; "
                f"sweep it too: {switch}={word}, or {switch}=0:1:1 for both"
            )


def check_names(sweeps: Sequence[Sweep], algorithms: Sequence[Algorithm]) -> None:
    """SweepError for a swept name no chosen algorithm has, listing the ones they have."""
    known = {name for a in algorithms for name in a.specs}
    for sweep in sweeps:
        if sweep.name not in known:
            names = ", ".join(sorted(known))
            chosen = ", ".join(a.name for a in algorithms)
            raise SweepError(
                f"--sweep {sweep.name}: no parameter of that name in {chosen}; "
                f"the parameters are: {names}"
            )


def label(overrides: dict[str, Any]) -> str:
    """A short name for a parameter set: ``check_frames=5 fps=60``, or ``defaults``."""
    return " ".join(f"{k}={v:g}" for k, v in overrides.items()) or "defaults"
