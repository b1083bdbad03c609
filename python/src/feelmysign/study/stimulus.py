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
    name: str,
    segments: int,
    stimulus: Stimulus,
    layout: Layout,
    drawing: str,
    speed_cm_s: float | None = None,
) -> list[Stroke]:
    """A library shape of ``segments`` strokes, drawn at ``speed_cm_s`` (default: the
    design's first speed)."""
    speed = stimulus.speed_cm_s if speed_cm_s is None else speed_cm_s
    unit = shape_strokes(name, layout=layout, segments=segments, margin=stimulus.margin)
    length_cm = sum(s.length for s in unit) * layout.spacing_cm
    duration_ms = length_cm / speed * 1000.0
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


def at_speed(
    strokes: list[Stroke], speed_cm_s: float, layout: Layout, where: str = "stroke"
) -> list[Stroke]:
    """A recorded drawing's strokes redrawn at ``speed_cm_s``: the same path, each stroke
    lasting its length at that speed (a stroke of no length, a point, keeps its duration:
    it has no speed). ParameterError when the sleeve could not play one at that speed."""
    out: list[Stroke] = []
    for stroke in strokes:
        length_cm = stroke.length * layout.spacing_cm
        if length_cm > 0:
            stroke = replace(stroke, duration_ms=round(length_cm / speed_cm_s * 1000.0, 3))
        checked = validate_stroke(stroke, layout)
        if isinstance(checked, Rejected):
            raise checked.as_error(f"{where} {len(out) + 1} at {speed_cm_s:g} cm/s")
        out.append(checked)
    return out


def trial_strokes(
    design: Design,
    base_dir: Path,
    shape_name: str,
    *,
    level: int | None,
    segments: int | None,
    drawing: str,
    layout: Layout | None = None,
    speed_cm_s: float | None = None,
) -> list[Stroke]:
    """The strokes of a trial: a design shape at ``level``, or a library shape at ``segments``
    (practice trials), at the trial's speed.

    ``speed_cm_s`` None: a library shape at the design's first speed, a recorded drawing at
    its own (the hand's) timing, as a design of one speed plays it. A recorded drawing with a
    speed (speed a factor of the design, or a practice trial's own) is redrawn at it.
    """
    sleeve = layout or stimulus_layout(design.stimulus, base_dir)
    if level is None:
        assert segments is not None
        return library_strokes(shape_name, segments, design.stimulus, sleeve, drawing, speed_cm_s)
    shape = design.shape(shape_name)
    chosen = shape.levels[level]
    if shape.recording is not None:
        assert chosen.simplifier is not None
        strokes = recorded_strokes(
            base_dir / shape.recording,
            chosen.simplifier,
            chosen.settings,
            design.stimulus,
            sleeve,
            drawing,
        )
        if speed_cm_s is None:
            return strokes
        return at_speed(strokes, speed_cm_s, sleeve, f"{shape.recording}: stroke")
    assert chosen.segments is not None
    return library_strokes(
        shape_name, chosen.segments, design.stimulus, sleeve, drawing, speed_cm_s
    )
