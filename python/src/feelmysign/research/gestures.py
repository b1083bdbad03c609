"""Recorded gestures to evaluate: folders of recordings, and the $1 gesture-log XML format.

``feelmysign evaluate`` takes recording files and folders of them. A folder is
searched for ``*.json`` (feelmysign recordings) and ``*.xml`` (the gesture
logs of Wobbrock, Wilson & Li's $1 study, UIST 2007: one unistroke gesture a
file, laid out as ``s01/fast/arrow01.xml``)::

    <Gesture Name="arrow01" Subject="1" Speed="fast" Number="1" NumPts="46"
             Milliseconds="640" ...>
      <Point X="72" Y="150" T="1156372112609" /> ...
    </Gesture>

A gesture log becomes a one-path recording: screen pixels as drawn (y down),
times in ms from the first point (a time earlier than the one before is taken
at the one before), the canvas the bounding box plus a margin on every side (as
for LASA, ``lasa.recording_in_box``). A log holds pointer events alone, and a
pointer held still sends none: where ``STILL_SAMPLE_MS`` or more pass between
two points, the pointer is sampled still at the first every ``STILL_SAMPLE_MS``,
as the page does (``with_still_samples``), so that a stop is a rest.

Each recording is named by its path; its gesture (what the recogniser must
name) is the gesture's ``Name`` (else the file name) without trailing digits
(``arrow01`` -> ``arrow``); its set is the ``Speed`` (else the folder it lies
in under the folder given, else ``files``), so that a gesture log's speeds are
summarised apart.

A folder may also hold ``templates.json``: the templates the recogniser names
its drawings against (``load_templates``), which is then not a recording::

    {"templates": [[name, [[x, y], ...]], ...],
     "gesture_to_template": {"delete_mark": "delete", ...}}
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from feelmysign.research.lasa import recording_in_box
from feelmysign.simplify.recording import Recording, RecordingError, load_recording

EXTENSIONS = (".json", ".xml")
FILES_SET = "files"
TEMPLATES_FILE = "templates.json"
MAX_TEMPLATES_BYTES = 10_000_000
MAX_GESTURE_BYTES = 10_000_000
# The least a gesture log's points may span: its canvas (its box plus a twentieth of the larger
# side on every side, lasa.recording_in_box) is then at least a pixel on each side.
MIN_GESTURE_EXTENT_PX = 10.0
# How often the page samples a pointer held still, which sends no events (web/src/ui/pointer.ts,
# STILL_SAMPLE_MS): a gesture log has the events alone.
STILL_SAMPLE_MS = 32.0


@dataclass(frozen=True)
class Gesture:
    """A recording to evaluate, with its name, gesture and set."""

    name: str
    gesture: str
    set: str
    recording: Recording


def gesture_name(text: str) -> str:
    """A drawing's name without its trailing number: ``arrow01`` -> ``arrow``."""
    stripped = re.sub(r"[\s_-]*\d+$", "", text)
    return stripped or text


def expand(paths: list[str]) -> list[tuple[Path, str | None]]:
    """Every file given, and every recording under every folder given (sorted), each with
    the folder it lies in under its given folder (None for a file given by itself)."""
    found: list[tuple[Path, str | None]] = []
    for given in paths:
        path = Path(given)
        if not path.is_dir():
            found.append((path, None))
            continue
        inside = sorted(
            p
            for p in path.rglob("*")
            if p.suffix.lower() in EXTENSIONS and p.is_file() and p.name != TEMPLATES_FILE
        )
        if not inside:
            raise RecordingError(
                f"{path}: no recordings (*.json) or $1 gesture logs (*.xml) in this folder"
            )
        for item in inside:
            parent = item.parent.relative_to(path)
            found.append((item, parent.name if parent.parts else None))
    return found


def load_gesture(
    path: Path, folder: str | None, load_json: Callable[[str], Recording] = load_recording
) -> Gesture:
    """One file: a $1 gesture log (``.xml``) or a feelmysign recording (anything else)."""
    if path.suffix.lower() == ".xml":
        return load_gesture_log(path, folder)
    recording = load_json(str(path))
    return Gesture(str(path), gesture_name(path.stem), folder or FILES_SET, recording)


def load_gesture_log(path: Path, folder: str | None = None) -> Gesture:
    """A $1 gesture log as a one-path recording (see the module's notes)."""
    try:
        if path.stat().st_size > MAX_GESTURE_BYTES:
            raise RecordingError(
                f"{path}: larger than {MAX_GESTURE_BYTES} bytes; a gesture log is a few kB"
            )
        root = ElementTree.parse(path).getroot()
    except OSError as error:
        raise RecordingError(f"cannot read {path}: {error.strerror or error}") from error
    except ElementTree.ParseError as error:
        raise RecordingError(f"{path}: not valid XML ({error})") from error
    if root.tag != "Gesture":
        raise RecordingError(
            f"{path}: expected a $1 gesture log (<Gesture Name=...><Point X= Y= T=/>...), "
            f"found <{root.tag}>"
        )
    points = root.findall("Point")
    try:
        xyt = np.array([[float(p.attrib[k]) for k in ("X", "Y", "T")] for p in points])
    except (KeyError, ValueError) as error:
        raise RecordingError(
            f"{path}: every <Point> needs numeric X, Y and T attributes ({error})"
        ) from error
    if len(xyt) < 2 or not np.all(np.isfinite(xyt)):
        raise RecordingError(f"{path}: a gesture needs at least 2 points with finite X, Y and T")
    extent = float(np.ptp(xyt[:, :2], axis=0).max())
    if extent < MIN_GESTURE_EXTENT_PX:
        raise RecordingError(
            f"{path}: its points span {extent:g} px; a gesture must span at least "
            f"{MIN_GESTURE_EXTENT_PX:g} px to be mapped onto the sleeve (its canvas is its box "
            "plus a margin of a twentieth of its larger side)"
        )
    times = np.maximum.accumulate(xyt[:, 2]) - xyt[0, 2]
    x, y, times = with_still_samples(xyt[:, 0], xyt[:, 1], times)
    recording = recording_in_box(x, y, times, px_per_unit=1.0)
    name = root.attrib.get("Name") or path.stem
    speed = root.attrib.get("Speed") or folder or FILES_SET
    return Gesture(str(path), gesture_name(name), speed, recording)


def with_still_samples(
    x: np.ndarray, y: np.ndarray, t: np.ndarray, every_ms: float = STILL_SAMPLE_MS
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The points the page would give the simplifier for these pointer events: a pointer held
    still sends no events, so where ``every_ms`` or more pass without one the page samples it
    where it is, every ``every_ms`` (web/src/ui/pointer.ts), and the rest rule sees a stop."""
    gaps = np.diff(t)
    counts = np.zeros(len(t), dtype=int)  # still samples after each point
    counts[:-1] = np.ceil(gaps / every_ms).astype(int) - 1
    counts[counts < 0] = 0
    if not counts.any():
        return x, y, t
    index = np.repeat(np.arange(len(t)), counts + 1)
    # Each point, then its still samples k * every_ms after it (k = 1, 2, ...).
    within = np.arange(len(index)) - np.repeat(np.cumsum(counts + 1) - (counts + 1), counts + 1)
    return x[index], y[index], t[index] + within * every_ms


def load_all(
    paths: list[str], load_json: Callable[[str], Recording] = load_recording
) -> list[Gesture]:
    """Every recording in ``paths`` (files and folders), in the order given, folders sorted."""
    return [load_gesture(path, folder, load_json) for path, folder in expand(paths)]


@dataclass(frozen=True)
class TemplateSet:
    """Named templates to recognise drawings against, and each gesture's template name
    (a gesture not in ``gesture_to_template`` is expected to be named as itself)."""

    path: Path
    templates: list[tuple[str, list[tuple[float, float]]]]
    gesture_to_template: dict[str, str]

    def expected(self, gesture: str) -> str | None:
        """The template a drawing of ``gesture`` should be named as (None: no such template)."""
        name = self.gesture_to_template.get(gesture, gesture)
        return name if any(n == name for n, _ in self.templates) else None


def find_templates(paths: list[str]) -> Path | None:
    """The ``templates.json`` at the top of the first folder given that has one."""
    for given in paths:
        candidate = Path(given) / TEMPLATES_FILE
        if Path(given).is_dir() and candidate.is_file():
            return candidate
    return None


def load_templates(path: Path) -> TemplateSet:
    """A templates file (see the module's notes), every fault named with what was expected."""
    import json

    shape = (
        'expected {"templates": [[name, [[x, y], ...]], ...], '
        '"gesture_to_template": {gesture: name, ...}}'
    )
    try:
        if path.stat().st_size > MAX_TEMPLATES_BYTES:
            raise RecordingError(f"{path}: larger than {MAX_TEMPLATES_BYTES} bytes")
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise RecordingError(f"cannot read {path}: {error.strerror or error}") from error
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise RecordingError(f"{path}: not valid JSON ({error}); {shape}") from error
    if not isinstance(data, dict) or not isinstance(data.get("templates"), list):
        raise RecordingError(f"{path}: no 'templates' list; {shape}")
    mapping = data.get("gesture_to_template", {})
    if not isinstance(mapping, dict) or not all(
        isinstance(k, str) and isinstance(v, str) for k, v in mapping.items()
    ):
        raise RecordingError(f"{path}: 'gesture_to_template' must map names to names; {shape}")
    templates = []
    for index, item in enumerate(data["templates"]):
        try:
            name, raw = item
            points = [(float(x), float(y)) for x, y in raw]
        except (TypeError, ValueError) as error:
            raise RecordingError(f"{path}: template {index} is not [name, [[x, y], ...]]") from (
                error
            )
        if not isinstance(name, str) or len(points) < 2 or not np.all(np.isfinite(points)):
            raise RecordingError(
                f"{path}: template {index} needs a name and at least 2 finite points"
            )
        templates.append((name, points))
    if not templates:
        raise RecordingError(f"{path}: the 'templates' list is empty; {shape}")
    return TemplateSet(path, templates, dict(mapping))
