"""Online simplifiers: pointer frames in, straight strokes (in grid units) out."""

from feelmysign.simplify.angle import AngleParams, AngleSimplifier
from feelmysign.simplify.frames import frames_from_samples
from feelmysign.simplify.mapping import CanvasMapping
from feelmysign.simplify.recording import Recording, load_recording, parse_recording
from feelmysign.simplify.replay import PathSegment, simplify_paths
from feelmysign.simplify.segment import Sample, Segment

__all__ = [
    "AngleParams",
    "AngleSimplifier",
    "CanvasMapping",
    "PathSegment",
    "Recording",
    "Sample",
    "Segment",
    "frames_from_samples",
    "load_recording",
    "parse_recording",
    "simplify_paths",
]
