"""Recordings: the pointer samples of a drawing, as JSON, for exact replay.

Format (also in docs/research.md)::

    {"canvas": {"width_px": W, "height_px": H},
     "paths": [[{"t_ms": t, "x": x, "y": y, "pressure": p}, ...], ...],
     "sleeve": {"rows": R, "columns": C},                # optional
     "simplifier": {"algorithm": "angle", "params": {}}, # optional: what the sender used
     "frames": [[{"t_ms": t, "x": x, "y": y}, ...], ...], # optional: the exact animation frames
     "strokes": [{"path": i, "start": [x, y], "end": [x, y],
                  "start_ms": t, "end_ms": t}, ...]}     # optional: the strokes the sender sent

The browser's recordings carry ``frames`` and ``strokes``, so that a replay can
feed the simplifier exactly what the browser fed it and check that it gives
the same strokes (``feelmysign replay``).

Times in ms (any origin, non-decreasing within a path), canvas pixels with the
origin top-left and y down, pressure 0..1 (optional, 0.5 when absent).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeGuard

from feelmysign.errors import FeelMySignError
from feelmysign.input_files import MAX_RECORDING_BYTES, loads_json, read_text
from feelmysign.protocol import json_kind
from feelmysign.simplify.segment import Sample
from feelmysign.stroke import Point


class RecordingError(FeelMySignError):
    """A recording file that cannot be read; says where and what is wrong."""


@dataclass(frozen=True)
class RecordedStroke:
    """A stroke the sender sent, as its recording keeps it (grid units, ms)."""

    path: int
    start: Point
    end: Point
    start_ms: float
    end_ms: float


@dataclass(frozen=True)
class Recording:
    width_px: float
    height_px: float
    paths: tuple[tuple[Sample, ...], ...]
    rows: int | None = None
    columns: int | None = None
    simplifier: dict[str, Any] = field(default_factory=dict)
    frames: tuple[tuple[Sample, ...], ...] | None = None
    strokes: tuple[RecordedStroke, ...] | None = None


def load_recording(path: str | Path) -> Recording:
    try:
        text = read_text(path, max_bytes=MAX_RECORDING_BYTES)
    except OSError as error:
        raise RecordingError(f"cannot read recording {path}: {error.strerror or error}") from error
    except UnicodeDecodeError as error:
        raise RecordingError(
            f"{path}: not UTF-8 text (byte {error.start}); a recording is JSON saved as UTF-8"
        ) from None
    return parse_recording(text, source=str(path))


def parse_recording(text: str, *, source: str = "<recording>") -> Recording:
    try:
        data = loads_json(text, parse_constant=_reject_constant)
    except ValueError as error:
        if text.lstrip().startswith("<"):
            raise RecordingError(
                f"{source}: XML, not a recording; simplify and replay read recording JSON (the"
                " page's Save), and feelmysign evaluate reads $1 gesture logs (.xml)"
            ) from None
        raise RecordingError(f"{source}: not valid JSON ({error})") from error
    if not isinstance(data, dict):
        raise RecordingError(f"{source}: the recording must be a JSON object with canvas and paths")
    canvas = _field(data, "canvas", dict, source)
    width = _positive(canvas, "width_px", source)
    height = _positive(canvas, "height_px", source)
    raw_paths = _field(data, "paths", list, source)
    paths = tuple(_path(raw, i, source) for i, raw in enumerate(raw_paths))
    sleeve = data.get("sleeve") or {}
    simplifier = data.get("simplifier") or {}
    if not isinstance(sleeve, dict) or not isinstance(simplifier, dict):
        raise RecordingError(f"{source}: sleeve and simplifier, when given, must be objects")
    rows, columns = sleeve.get("rows"), sleeve.get("columns")
    frames = None
    if data.get("frames") is not None:
        raw_frames = _field(data, "frames", list, source)
        frames = tuple(_path(raw, i, source, key="frames") for i, raw in enumerate(raw_frames))
    strokes = None
    if data.get("strokes") is not None:
        raw_strokes = _field(data, "strokes", list, source)
        strokes = tuple(_stroke(raw, i, source) for i, raw in enumerate(raw_strokes))
    return Recording(
        width,
        height,
        paths,
        _grid_side(rows, "rows", source),
        _grid_side(columns, "columns", source),
        simplifier,
        frames,
        strokes,
    )


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number")


def _field(data: dict[str, Any], key: str, kind: type, source: str) -> Any:
    value = data.get(key)
    if not isinstance(value, kind):
        wanted = "an object" if kind is dict else "an array"
        found = "is missing" if key not in data else f"is {json_kind(value)}"
        raise RecordingError(
            f"{source}: '{key}' must be {wanted} but {found}; a recording is the JSON file the "
            "drawing page's Save button downloads (its format: docs/research.md, Recordings)"
        )
    return value


def _positive(data: dict[str, Any], key: str, source: str) -> float:
    value = data.get(key)
    if not _is_number(value) or value <= 0:
        raise RecordingError(f"{source}: canvas.{key} must be a number > 0, got {value!r}")
    return float(value)


def _path(raw: object, index: int, source: str, *, key: str = "paths") -> tuple[Sample, ...]:
    if not isinstance(raw, list) or not raw:
        raise RecordingError(f"{source}: {key}[{index}] must be a non-empty list of samples")
    samples: list[Sample] = []
    for k, item in enumerate(raw):
        where = f"{source}: {key}[{index}][{k}]"
        if not isinstance(item, dict):
            raise RecordingError(f"{where} must be an object with t_ms, x, y")
        values = [item.get(key) for key in ("t_ms", "x", "y")]
        if not all(_is_number(v) for v in values):
            raise RecordingError(f"{where} needs finite numbers t_ms, x, y; got {item!r}")
        pressure = item.get("pressure", 0.5)
        if not _is_number(pressure) or not 0 <= pressure <= 1:
            raise RecordingError(f"{where}: pressure must be in [0, 1], got {pressure!r}")
        t_ms, x, y = (float(v) for v in values)  # type: ignore[arg-type]
        if samples and t_ms < samples[-1].t_ms:
            raise RecordingError(
                f"{where}: t_ms {t_ms:g} goes back in time (samples must be in order)"
            )
        samples.append(Sample(t_ms, x, y, float(pressure)))
    return tuple(samples)


def _stroke(raw: object, index: int, source: str) -> RecordedStroke:
    where = f"{source}: strokes[{index}]"
    if not isinstance(raw, dict):
        raise RecordingError(f"{where} must be an object with path, start, end, start_ms, end_ms")
    path, start_ms, end_ms = raw.get("path"), raw.get("start_ms"), raw.get("end_ms")
    if not isinstance(path, int) or isinstance(path, bool) or path < 0:
        raise RecordingError(f"{where}: path must be a path index (0 or more), got {path!r}")
    if not _is_number(start_ms) or not _is_number(end_ms):
        raise RecordingError(f"{where} needs finite numbers start_ms, end_ms; got {raw!r}")
    return RecordedStroke(
        path,
        _point(raw.get("start"), where),
        _point(raw.get("end"), where),
        float(start_ms),
        float(end_ms),
    )


def _point(value: object, where: str) -> Point:
    if not (isinstance(value, list) and len(value) == 2 and all(_is_number(v) for v in value)):
        raise RecordingError(f"{where}: start and end must be [x, y] numbers, got {value!r}")
    return (float(value[0]), float(value[1]))


def _is_number(value: object) -> TypeGuard[int | float]:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _grid_side(value: object, key: str, source: str) -> int | None:
    """sleeve.rows or sleeve.columns: absent, or a whole number from 1 to 64, as in a layout."""
    if value is None:
        return None
    if not isinstance(value, int) or isinstance(value, bool) or not 1 <= value <= 64:
        raise RecordingError(
            f"{source}: sleeve.{key} must be a whole number from 1 to 64, got {value!r}; "
            f"fix it or remove it (then --{key} or the default applies)"
        )
    return value
