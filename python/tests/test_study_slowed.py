"""A speed at which the sleeve would slow a level's strokes is allowed, but said: by name."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.study.design_file import load_design
from feelmysign.study.slowed import SPEED_STEP_CM_S, slowed_trials
from feelmysign.study.stimulus import library_strokes

DESIGN = """
[study]
name = "Fast hearts"
seed = 1
repetitions = 1
resolutions = ["coarse", "fine"]

[stimulus]
speed_cm_s = [5, 15]

[[shapes]]
name = "heart"
segments = [4, 20]

[[shapes]]
name = "square"
segments = [4, 8]

[[practice]]
shape = "heart"
segments = 20
speed_cm_s = 15

[questionnaire]
items = ["The sleeve was comfortable."]
"""


def _design(tmp_path: Path) -> Path:
    path = tmp_path / "fast.toml"
    path.write_text(DESIGN)
    return path


def test_the_fine_heart_at_15_cm_s_is_found_with_its_count_and_fastest_speed(
    tmp_path: Path,
) -> None:
    design = load_design(_design(tmp_path))
    found = slowed_trials(design, tmp_path)
    assert [(s.shape, s.level, s.speed_cm_s) for s in found] == [
        ("heart", "at resolution 'fine'", 15.0),
        ("heart", "in practice trial 1", 15.0),
    ]
    floor_ms = shortest_planned_ms(PAPER_SLEEVE.shortest_burst_ms)
    assert found[0].floor_ms == floor_ms

    def brief(speed: float) -> int:
        strokes = library_strokes("heart", 20, design.stimulus, PAPER_SLEEVE, "-", speed)
        return sum(1 for s in strokes if s.duration_ms < floor_ms)

    assert found[0].slowed == brief(15.0) > 0 and found[0].strokes == 20
    fastest = found[0].fastest_cm_s
    assert fastest is not None and fastest < 15.0
    assert brief(fastest) == 0  # unslowed at the speed it names
    assert brief(fastest + 2 * SPEED_STEP_CM_S) > 0  # and it is the fastest (to a step)
    message = found[0].message()
    for said in (
        "heart",
        "'fine'",
        "15 cm/s",
        f"{found[0].slowed} of its 20 strokes",
        f"{fastest:g}",
    ):
        assert said in message


def test_check_warns_and_new_says_so_in_one_line_both_accepting_the_design(
    tmp_path: Path,
) -> None:
    design = _design(tmp_path)
    run = [sys.executable, "-m", "feelmysign", "study"]
    check = subprocess.run(
        [*run, "check", str(design)], capture_output=True, text=True, timeout=300
    )
    assert check.returncode == 0, check.stderr
    warnings = [line for line in check.stdout.splitlines() if "warning:" in line]
    assert len(warnings) == 2 and "heart at resolution 'fine'" in warnings[0]
    new = subprocess.run(
        [*run, "new", str(design), "--out", str(tmp_path / "s.sqlite")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert new.returncode == 0, new.stderr
    said = [line for line in new.stdout.splitlines() if line.startswith("Warning:")]
    assert len(said) == 1 and "2 cases" in said[0] and "15 cm/s" in said[0]
