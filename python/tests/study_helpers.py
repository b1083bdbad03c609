"""Helpers of the study tests: the paper's design, and a fresh study file from it."""

from __future__ import annotations

import json
from pathlib import Path

from feelmysign.study import StudyStore, load_design

REPO = Path(__file__).resolve().parents[2]
PAPER_DESIGN = REPO / "deploy" / "studies" / "paper.toml"


def new_study(tmp_path: Path, design_path: Path = PAPER_DESIGN) -> StudyStore:
    return StudyStore.create(tmp_path / "study.sqlite", design_path, load_design(design_path))


def zigzag_recording(path: Path) -> Path:
    """A drawn zigzag (three teeth), as the page's Save button writes it."""
    samples = []
    for i in range(48):
        up = (i // 8) % 2 == 0
        y = 60.0 + (i % 8) * (10 if up else -10) + (0 if up else 70)
        samples.append({"t_ms": i * 16.0, "x": 20.0 + i * 7.5, "y": y})
    path.write_text(json.dumps({"canvas": {"width_px": 400, "height_px": 300}, "paths": [samples]}))
    return path


ZIGZAG_SHAPE = """
[[shapes]]
name = "zigzag"
recording = "zigzag.json"
simplifier = "window"
settings = [{max_error = 1.5, max_stroke_ms = 400}, {max_error = 0.05}]
synonyms = ["zig zag", "lightning"]
"""


# A pilot a new user might design: four shapes at two resolutions, two repetitions.
PILOT_DESIGN = """
[study]
name = "Pilot"
seed = 1
repetitions = 2
resolutions = ["coarse", "fine"]

[[shapes]]
name = "circle"
segments = [4, 8]

[[shapes]]
name = "square"
segments = [4, 8]

[[shapes]]
name = "triangle"
segments = [3, 6]

[[shapes]]
name = "star"
segments = [5, 10]

[comfort]
questions = ["Does the sleeve sit comfortably?", "Can you feel every motor?"]

[questionnaire]
items = ["The sleeve was comfortable."]
"""


def pilot_study(tmp_path: Path, name: str = "pilot.sqlite") -> StudyStore:
    design = tmp_path / "pilot.toml"
    design.write_text(PILOT_DESIGN)
    return StudyStore.create(tmp_path / name, design, load_design(design))
