"""results.json says what the report says: a number the report calls not estimable is null
there, with the report's reason beside it."""

from __future__ import annotations

import json
from pathlib import Path

from study_helpers import new_study, pilot_study

from feelmysign.study.analysis import analyse_study
from feelmysign.study.analysis.psychometric import SLOPE_BOUNDS
from feelmysign.study.dry_run import dry_run

# Five shapes at three resolutions and three speeds: with two in-range simulated wearers
# (seed 1) the triangle at 2 cm/s jumps from wrong to right, a slope at the fit's limit.
DESIGN = """\
[study]
name = "Five shapes, three resolutions, three speeds"
seed = 4242
randomisation = "latin-square"
repetitions = 2
resolutions = ["coarse", "medium", "fine"]
criterion = 0.75
guess_rate = 0.0

[stimulus]
speed_cm_s = [2.0, 5.0, 15.0]

[[shapes]]
name = "circle"
segments = [3, 6, 12]
synonyms = ["ring", "round"]

[[shapes]]
name = "heart"
segments = [4, 8, 20]
synonyms = ["love"]

[[shapes]]
name = "star"
segments = [5, 10, 20]
synonyms = ["pentagram"]

[[shapes]]
name = "triangle"
segments = [3, 6, 9]
synonyms = ["pyramid"]

[[shapes]]
name = "square"
segments = [4, 8, 12]
synonyms = ["box"]

[[practice]]
shape = "line"
segments = 2

[[practice]]
shape = "circle"
segments = 16
speed_cm_s = 15.0

[comfort]
questions = ["Is the sleeve comfortable?"]

[questionnaire]
points = 5
labels = ["strongly disagree", "disagree", "neutral", "agree", "strongly agree"]
items = ["Fast shapes were harder."]
"""


def test_a_two_participant_pilot_has_no_cluster_interval_and_no_slope_at_the_limit(
    tmp_path: Path,
) -> None:
    design = tmp_path / "design.toml"
    design.write_text(DESIGN)
    store = new_study(tmp_path, design)
    dry_run(store, 2, seed=1, wearer="in-range")
    analyse_study(store, tmp_path / "out", samples=50)
    report = (tmp_path / "out" / "report.md").read_text()
    needed = json.loads((tmp_path / "out" / "results.json").read_text())["needed_strokes"]
    assert needed
    for shape, entry in needed.items():
        # Two participants: resampling them says nothing, as the report says.
        why = entry["cluster_bootstrap_not_estimable"]
        assert why is not None and why in report, shape
        assert entry["cluster_bootstrap_low"] is None and entry["cluster_bootstrap_high"] is None
        # A slope is either a measured one, or null with the report's reason.
        slope, why_not = entry["slope_per_doubling"], entry["slope_per_doubling_not_estimable"]
        if why_not is None:
            assert slope is not None and slope < SLOPE_BOUNDS[1] * 0.999, shape
            assert f"{slope:.2f}" in report
        else:
            assert slope is None and why_not in report, shape
        for name in ("dispersion", "participant_sd_doublings"):
            reason = entry[f"{name}_not_estimable"]
            assert (entry[name] is None) == (reason is not None), (shape, name)
            if reason is not None:
                assert reason in report
    # The case in question is met: some slope of this pilot is at the fit's limit.
    assert any(e["slope_per_doubling_not_estimable"] for e in needed.values()), needed


def test_three_participants_keep_their_cluster_interval(tmp_path: Path) -> None:
    store = pilot_study(tmp_path)
    dry_run(store, 3, seed=3)
    analyse_study(store, tmp_path / "out", samples=50)
    needed = json.loads((tmp_path / "out" / "results.json").read_text())["needed_strokes"]
    for shape, entry in needed.items():
        assert entry["cluster_bootstrap_not_estimable"] is None, shape
        assert entry["cluster_bootstrap_low"] is not None, shape


def test_one_participant_has_no_spread_in_the_shape_model(tmp_path: Path) -> None:
    store = pilot_study(tmp_path)
    dry_run(store, 1, seed=3)
    analyse_study(store, tmp_path / "out", samples=50)
    report = (tmp_path / "out" / "report.md").read_text()
    model = json.loads((tmp_path / "out" / "results.json").read_text())["shape_model"]
    assert model is not None
    if model["mixed"]:  # the report names the SD only for the mixed model
        assert model["participant_sd"] is None
        assert model["participant_sd_not_estimable"] in report
    else:
        assert model["participant_sd_not_estimable"] is not None
