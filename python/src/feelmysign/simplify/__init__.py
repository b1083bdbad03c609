"""Online simplifiers: pointer frames in, straight strokes (in grid units) out."""

from feelmysign.simplify.angle import AngleParams, AngleSimplifier
from feelmysign.simplify.frames import frames_from_samples
from feelmysign.simplify.mapping import CanvasMapping
from feelmysign.simplify.recording import Recording, load_recording, parse_recording
from feelmysign.simplify.registry import ALGORITHMS, Algorithm, PathSegment, simplify_paths
from feelmysign.simplify.segment import Sample, Segment
from feelmysign.simplify.window import WindowParams, WindowSimplifier

__all__ = [
    "ALGORITHMS",
    "Algorithm",
    "AngleParams",
    "AngleSimplifier",
    "CanvasMapping",
    "PathSegment",
    "Recording",
    "Sample",
    "Segment",
    "WindowParams",
    "WindowSimplifier",
    "frames_from_samples",
    "load_recording",
    "parse_recording",
    "simplify_paths",
]
