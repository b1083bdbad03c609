"""Re-run a recording through a simplifier, exactly: the frames it saw, the segments it gave.

A browser recording carries the animation frames its simplifier was fed
(``frames``); they are replayed as they are, so the replay gives the strokes
the browser sent. Without them, or when another frame rate is asked for, the
pointer samples are resampled into frames (``frames_from_samples``), as
``feelmysign simplify`` does. Pure: the same recording and parameters always
give the same segments.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from feelmysign.simplify.frames import frames_from_samples
from feelmysign.simplify.recording import RecordedStroke, Recording
from feelmysign.simplify.registry import Params, PathSegment, algorithm_of
from feelmysign.simplify.segment import Sample

DEFAULT_FPS = 60.0  # a recording that names no fps was drawn in a 60 Hz loop (AngleParams)
# Browser and Python compute the same doubles in the same order, but allow for
# a last-bit difference in a library function (hypot, cos) between the two.
MATCH_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Rerun:
    """What was fed to the simplifier (per path), where it came from, and its segments.

    ``frames`` are animation frames for a simplifier fed frames (angle), the
    pointer samples themselves for one fed every sample (window).
    """

    frames: tuple[tuple[Sample, ...], ...]
    frames_source: str  # "recorded", "resampled at F fps" or "every sample"
    segments: list[PathSegment]


def recorded_fps(recording: Recording) -> float:
    fps = recording.simplifier.get("params", {}).get("fps", DEFAULT_FPS)
    return float(fps) if isinstance(fps, (int, float)) and not isinstance(fps, bool) else 0.0


def frames_for(recording: Recording, fps: float) -> tuple[tuple[tuple[Sample, ...], ...], str]:
    """The recording's own frames if it has them and ``fps`` is its rate; else resampled ones."""
    if recording.frames is not None and fps == recorded_fps(recording):
        return recording.frames, "recorded"
    resampled = tuple(tuple(frames_from_samples(path, fps)) for path in recording.paths)
    return resampled, f"resampled at {fps:g} fps"


def inputs_for(recording: Recording, params: Params) -> tuple[tuple[tuple[Sample, ...], ...], str]:
    """What the simplifier ``params`` is for is fed, per path: frames, or every sample."""
    fps = getattr(params, "fps", None)
    if algorithm_of(params).input == "samples" or not isinstance(fps, (int, float)):
        return recording.paths, "every sample"
    return frames_for(recording, fps)


def run_frames(params: Params, frames: Sequence[Sequence[Sample]]) -> list[PathSegment]:
    """Every path's inputs pushed in order and ended, through the simplifier ``params`` is for."""
    simplifier = algorithm_of(params).make(params)
    out: list[PathSegment] = []
    for index, path in enumerate(frames):
        for frame in path:
            out += [PathSegment(index, s) for s in simplifier.push(frame)]
        out += [PathSegment(index, s) for s in simplifier.end()]
    return out


def rerun(recording: Recording, params: Params) -> Rerun:
    frames, source = inputs_for(recording, params)
    return Rerun(frames, source, run_frames(params, frames))


def mismatch(segments: Sequence[PathSegment], recorded: Sequence[RecordedStroke]) -> str | None:
    """None when the sent segments are the recorded strokes; else the first difference."""
    sent = [s for s in segments if s.segment.dropped is None]
    for number, (ours, theirs) in enumerate(zip(sent, recorded, strict=False), start=1):
        s = ours.segment
        ours_values = (ours.path, *s.start, *s.end, s.start_ms, s.end_ms)
        theirs_values = (theirs.path, *theirs.start, *theirs.end, theirs.start_ms, theirs.end_ms)
        if any(
            abs(a - b) > MATCH_TOLERANCE for a, b in zip(ours_values, theirs_values, strict=True)
        ):
            return (
                f"stroke {number} differs: replayed {_show(ours_values)}, "
                f"recorded {_show(theirs_values)} (path, start, end, start_ms, end_ms)"
            )
    if len(sent) != len(recorded):
        return f"{len(sent)} strokes replayed, {len(recorded)} recorded"
    return None


def _show(values: tuple[float, ...]) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in values) + ")"
