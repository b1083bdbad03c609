"""Run a whole recording through a simplifier, deterministically (same input, same strokes)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from feelmysign.simplify.angle import AngleParams, AngleSimplifier
from feelmysign.simplify.frames import frames_from_samples
from feelmysign.simplify.segment import Sample, Segment


@dataclass(frozen=True)
class PathSegment:
    """A segment and the index of the path it came from."""

    path: int
    segment: Segment


def simplify_paths(params: AngleParams, paths: Sequence[Sequence[Sample]]) -> list[PathSegment]:
    """Every path resampled into frames at ``params.fps``, pushed, and ended, in order."""
    simplifier = AngleSimplifier(params)
    out: list[PathSegment] = []
    for index, samples in enumerate(paths):
        for frame in frames_from_samples(samples, params.fps):
            out += [PathSegment(index, s) for s in simplifier.push(frame)]
        out += [PathSegment(index, s) for s in simplifier.end()]
    return out
