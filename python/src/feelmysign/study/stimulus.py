"""The strokes of one trial: a library shape at a number of segments, or a recorded drawing
simplified with one level's settings, sized and timed as the design's stimulus says.

Pure apart from reading a recording file; the same trial always gives the same strokes
(the drawing id is passed in).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from feelmysign.errors import ParameterError
from feelmysign.layout import PAPER_SLEEVE, Layout, load_layout
from feelmysign.protocol import Rejected, validate_stroke
from feelmysign.research.rerun import rerun
from feelmysign.shapes import shape_strokes
from feelmysign.simplify.recording import load_recording
from feelmysign.simplify.registry import ALGORITHMS, params_for
from feelmysign.stroke import Stroke
from feelmysign.study.design import Design, Stimulus


def stimulus_layout(stimulus: Stimulus, base_dir: Path) -> Layout:
    """The sleeve the design is drawn for: its layout file, or the paper's sleeve."""
    if stimulus.layout is None:
        return PAPER_SLEEVE
    return load_layout(base_dir / stimulus.layout)


def library_strokes(
    name: str, segments: int, stimulus: Stimulus, layout: Layout, drawing: str
) -> list[Stroke]:
    """A library shape of ``segments`` strokes, drawn at the design's speed."""
    unit = shape_strokes(name, layout=layout, segments=segments, margin=stimulus.margin)
    length_cm = sum(s.length for s in unit) * layout.spacing_cm
    duration_ms = length_cm / stimulus.speed_cm_s * 1000.0
    return shape_strokes(
        name,
        layout=layout,
        segments=segments,
        duration_ms=duration_ms,
        intensity=stimulus.intensity,
        margin=stimulus.margin,
        drawing=drawing,
    )


def recorded_strokes(
    recording_path: Path,
    simplifier: str,
    settings: dict[str, Any],
    stimulus: Stimulus,
    layout: Layout,
    drawing: str,
) -> list[Stroke]:
    """A recorded drawing through ``simplifier`` with ``settings``: the strokes it sends.

    The recording keeps its own timing (it was drawn by a hand); the stroke count is
    what the simplifier gave, which is this level's resolution.
    """
    # Drawn on the study's sleeve, whatever sleeve the recording was made for.
    recording = replace(load_recording(recording_path), rows=layout.rows, columns=layout.columns)
    params = params_for(ALGORITHMS[simplifier], recording, settings)
    result = rerun(recording, params)
    strokes: list[Stroke] = []
    for item in result.segments:
        segment = item.segment
        if segment.dropped is not None:
            continue
        stroke = Stroke(
            segment.start,
            segment.end,
            segment.duration_ms,
            intensity=stimulus.intensity,
            drawing=drawing,
            seq=len(strokes),
        )
        checked = validate_stroke(stroke, layout)
        if isinstance(checked, Rejected):
            raise checked.as_error(
                f"{recording_path}: stroke {len(strokes) + 1} with {simplifier} {settings}"
            )
        strokes.append(replace(checked, drawing=drawing, seq=len(strokes)))
    if not strokes:
        raise ParameterError(
            f"{simplifier} settings {settings}",
            "no stroke",
            "settings that leave at least one stroke of the recording",
        )
    return strokes


def trial_strokes(
    design: Design,
    base_dir: Path,
    shape_name: str,
    *,
    level: int | None,
    segments: int | None,
    drawing: str,
    layout: Layout | None = None,
) -> list[Stroke]:
    """The strokes of a trial: a design shape at ``level``, or a library shape at ``segments``
    (practice trials)."""
    sleeve = layout or stimulus_layout(design.stimulus, base_dir)
    if level is None:
        assert segments is not None
        return library_strokes(shape_name, segments, design.stimulus, sleeve, drawing)
    shape = design.shape(shape_name)
    chosen = shape.levels[level]
    if shape.recording is not None:
        assert chosen.simplifier is not None
        return recorded_strokes(
            base_dir / shape.recording,
            chosen.simplifier,
            chosen.settings,
            design.stimulus,
            sleeve,
            drawing,
        )
    assert chosen.segments is not None
    return library_strokes(shape_name, chosen.segments, design.stimulus, sleeve, drawing)
