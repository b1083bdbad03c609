"""``feelmysign evaluate``: the CSV files, plots and JSON summary, and its usage errors."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

import pytest
from test_cli_replay import browser_recording

from feelmysign.cli import main
from feelmysign.research.sweep import SweepError, parameter_sets, parse_sweep
from feelmysign.simplify import ALGORITHMS

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
OUTPUTS = ("results.csv", "frontier.csv", "summary.json")
PLOTS = ("error_vs_strokes.png", "lag.png", "per_shape.png")


def recordings(tmp_path: Path) -> list[str]:
    """A browser recording, and a plain one (no frames, no strokes) of a tap and a line."""
    first = browser_recording(tmp_path / "spiral.json")
    line = [{"t_ms": 10.0 * k, "x": 100 + 8.0 * k, "y": 300 + 2.0 * k} for k in range(60)]
    tap = [{"t_ms": 900.0, "x": 50, "y": 50}, {"t_ms": 930.0, "x": 50, "y": 50}]
    second = tmp_path / "line-and-tap.json"
    second.write_text(
        json.dumps({"canvas": {"width_px": 800, "height_px": 600}, "paths": [line, tap]})
    )
    return [str(first), str(second)]


def evaluate_json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, Any]:
    assert main(["evaluate", *argv, "--json"]) == 0
    document: dict[str, Any] = json.loads(capsys.readouterr().out)
    return document


def test_recordings_give_the_csv_plots_and_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    document = evaluate_json(
        capsys,
        *recordings(tmp_path),
        "--sweep",
        "max_angle_deg=20:30:10",
        "--sweep",
        "max_error=0.1",
        "--out",
        str(out),
    )
    for name in OUTPUTS:
        assert (out / name).stat().st_size > 0
    for name in PLOTS:
        assert (out / name).read_bytes().startswith(PNG_SIGNATURE)
    with (out / "results.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 2 * 3  # 2 recordings x (angle 20, angle 30, window 0.1)
    assert {(r["algorithm"], r["setting"]) for r in rows} == {
        ("angle", "max_angle_deg=20"),
        ("angle", "max_angle_deg=30"),
        ("window", "max_error=0.1"),
    }
    assert {r["group"] for r in rows} == {"spiral", "line-and-tap"}
    line_and_tap = [r for r in rows if r["group"] == "line-and-tap"]
    assert all(int(r["dropped"]) >= 1 for r in line_and_tap)  # the tap
    summary = {(s["algorithm"], s["setting"]): s for s in document["summary"]}
    assert set(summary) == {(r["algorithm"], r["setting"]) for r in rows}
    window = summary[("window", "max_error=0.1")]
    assert window["max_deviation_max"] <= 0.1 + 1e-9
    for entry in summary.values():
        assert entry["recordings"] == 2
        for key in ("strokes_mean", "max_deviation_mean", "frechet_mean", "lag_p95_ms"):
            assert entry[key] >= 0
        assert entry["dropped_total"] >= 1  # the tap
    assert document["references"] == {"angle": "max_angle_deg=20", "window": "max_error=0.1"}
    assert document["frontier"][0]["strokes_mean"] >= document["frontier"][-1]["strokes_mean"]
    assert json.loads((out / "summary.json").read_text()) == document


def test_lasa_subset_with_the_default_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    document = evaluate_json(
        capsys, "--lasa", "--limit", "3", "--algorithm", "angle", "--sweep", "check_frames=5"
    )
    out = Path(document["out"])
    assert out.parent == Path("evaluations") and out.name[:8].isdigit()
    assert document["recordings"] == 3 and document["source"] == "lasa"
    with (out / "results.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [r["recording"] for r in rows] == ["lasa/Angle/1", "lasa/Angle/2", "lasa/Angle/3"]
    assert all(int(r["strokes"]) >= 1 for r in rows)


def test_the_table_without_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv = [*recordings(tmp_path)[:1], "--algorithm", "window", "--sweep", "max_error=0.2"]
    assert main(["evaluate", *argv, "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "window    max_error=0.2" in out and "Wrote results.csv" in out
    assert "recognised: $1 on the drawings / strokes sent / felt path" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--lasa", "--algorithm", "wiggle"], "the algorithms available are: angle"),
        ([], "give RECORDING files to evaluate, or --lasa"),
        (["--lasa", "--sweep", "max_speed=1:2:1"], "the parameters are: "),
        (["--lasa", "--sweep", "check_frames=1:3:0.5"], "whole numbers only"),
        (["--lasa", "--limit", "0"], "--limit: 0 is out of range"),
    ],
)
def test_usage_errors_list_the_choices(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["evaluate", *argv])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err


def test_a_value_out_of_range_names_the_range(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["evaluate", "--lasa", "--sweep", "max_angle_deg=100:200:50"]) == 1
    assert "max_angle_deg = 200.0 is not allowed; it must be in [1, 179]" in capsys.readouterr().err


def test_sweep_values() -> None:
    assert parse_sweep("max-error=0.05:0.2:0.05").values == (0.05, 0.1, 0.15, 0.2)
    assert parse_sweep("max_angle_deg=10:45:10").values == (10, 20, 30, 40)
    assert parse_sweep("fps=30").values == (30,)
    for bad in ("max_error", "max_error=a:b:c", "max_error=1:0:1", "max_error=0:1:0"):
        with pytest.raises(SweepError):
            parse_sweep(bad)


def test_a_true_false_parameter_is_fixed_or_run_both_ways() -> None:
    window = ALGORITHMS["window"]
    assert parameter_sets(window, [parse_sweep("least_squares=0:1:1")]) == [
        {"least_squares": False},
        {"least_squares": True},
    ]
    assert parameter_sets(window, [parse_sweep("least-squares=false")]) == [
        {"least_squares": False}
    ]
    with pytest.raises(SweepError, match="takes 0 or 1"):
        parameter_sets(window, [parse_sweep("least_squares=0:2:1")])


def test_a_parameter_no_run_reads_is_refused() -> None:
    """The bend rule is the chord core's and the lookahead the least-squares core's: swept where
    no run uses that core, every value would give the same strokes."""
    window = ALGORITHMS["window"]
    with pytest.raises(SweepError, match="only read with least_squares false, which no run has"):
        parameter_sets(window, [parse_sweep("max_bend=0:0.2:0.1")])
    with pytest.raises(SweepError, match="--sweep lookahead_ms: only read with least_squares true"):
        parameter_sets(window, [parse_sweep("least_squares=false"), parse_sweep("lookahead_ms=30")])
    both = parameter_sets(window, [parse_sweep("least_squares=0:1:1"), parse_sweep("max_bend=0.1")])
    assert both == [
        {"least_squares": False, "max_bend": 0.1},
        {"least_squares": True, "max_bend": 0.1},
    ]
    assert len(parameter_sets(window, [parse_sweep("lookahead_ms=0:60:30")])) == 3


def test_lasa_at_three_speeds_gives_timing_and_recognition(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    document = evaluate_json(
        capsys, "--lasa", "--speeds", "--defaults", "--limit", "7", "--out", str(tmp_path)
    )
    summary = document["summary"]
    assert {(s["set"], s["algorithm"]) for s in summary} == {
        (source_set, algorithm)
        for source_set in ("lasa", "slow", "normal", "fast")
        for algorithm in ("angle", "window")
    }
    for entry in summary:
        assert entry["recordings"] == 7 and entry["setting"] == "defaults"
        assert entry["skin_ratio_mean"] > 0 and entry["skin_ratio_p95"] > 0
        assert entry["release_to_felt_end_p95_ms"] >= entry["release_to_felt_end_median_ms"]
        assert entry["pen_to_skin_p95_ms"] > 0
        assert 0 <= entry["recognised_sent_pct"] <= 100
        assert 0 <= entry["recognised_drawn_pct"] <= 100
        assert 0 <= entry["recognised_felt_pct"] <= 100
    # The drawings themselves are the same shapes at every speed.
    drawn = {s["recognised_drawn_pct"] for s in summary}
    assert len(drawn) == 1


def test_speeds_need_lasa(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["evaluate", *recordings(tmp_path), "--speeds"])
    assert "--speeds re-times the LASA drawings" in capsys.readouterr().err


def gesture_log(
    path: Path, name: str, speed: str, points: list[tuple[float, float, float]]
) -> None:
    """A $1 gesture log (Wobbrock, Wilson & Li's XML), as s01/fast/arrow01.xml holds one."""
    path.parent.mkdir(parents=True, exist_ok=True)
    body = "".join(f'<Point X="{x:.0f}" Y="{y:.0f}" T="{t:.0f}" />' for x, y, t in points)
    path.write_text(
        f'<?xml version="1.0" encoding="utf-8" standalone="yes"?>\n<Gesture Name="{name}" '
        f'Subject="1" Speed="{speed}" Number="1" NumPts="{len(points)}">{body}</Gesture>\n'
    )


def gesture_folder(root: Path) -> Path:
    """Two people's circles and carets (a V turned up), fast and slow, with epoch times."""
    start = 1_156_372_112_609.0
    for person in (1, 2):
        for speed, step_ms in (("fast", 8.0), ("slow", 24.0)):
            wobble = 3.0 * person
            circle = [
                (
                    100 + (60 + wobble) * math.cos(2 * math.pi * k / 40),
                    100 + 60 * math.sin(2 * math.pi * k / 40),
                    start + step_ms * k,
                )
                for k in range(41)
            ]
            caret = [
                (40 + 3.0 * k, 200 - (4.0 + 0.1 * person) * min(k, 40 - k), start + step_ms * k)
                for k in range(41)
            ]
            folder = root / f"s0{person}" / speed
            gesture_log(folder / "circle01.xml", "circle01", speed, circle)
            gesture_log(folder / "caret01.xml", "caret01", speed, caret)
    return root


def test_a_folder_of_gesture_logs_is_recognised_per_speed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = gesture_folder(tmp_path / "gestures")
    out = tmp_path / "out"
    document = evaluate_json(
        capsys, str(root), "--defaults", "--algorithm", "window", "--out", str(out)
    )
    assert document["recordings"] == 8
    summary = {s["set"]: s for s in document["summary"]}
    assert set(summary) == {"fast", "slow"}
    for entry in summary.values():
        assert entry["recordings"] == 4
        # Each drawing is named among the other three of its speed: the other person's.
        assert entry["recognised_drawn_pct"] == 100.0
        assert entry["recognised_sent_pct"] == 100.0
        assert entry["recognised_felt_pct"] == 100.0
        assert entry["skin_ratio_mean"] > 0
    with (out / "results.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert {r["group"] for r in rows} == {"circle", "caret"}
    assert {r["recognised_felt"] for r in rows} == {"1"}
    # Times from the first point: a fast gesture lasts 40 x 8 ms.
    fast = [r for r in rows if r["set"] == "fast"]
    assert {float(r["drawing_ms"]) for r in fast} == {320.0}


def test_a_gesture_alone_in_its_set_is_not_recognised(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    document = evaluate_json(
        capsys,
        *recordings(tmp_path),
        "--defaults",
        "--algorithm",
        "window",
        "--out",
        str(tmp_path / "o"),
    )
    assert document["summary"][0]["recognised_sent_pct"] is None
    assert document["summary"][0]["recognised_felt_pct"] is None


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "<Gesture Name='x'><Point X='1' Y='2'/><Point X='2' Y='2' T='5'/></Gesture>",
            "numeric X, Y and T",
        ),
        ("<Gesture Name='x'><Point X='1' Y='2' T='0'/></Gesture>", "at least 2 points"),
        ("<Gestures/>", "expected a $1 gesture log"),
        ("<Gesture", "not valid XML"),
        (
            "<Gesture Name='x'><Point X='1' Y='2' T='3'/><Point X='1' Y='2' T='5'/></Gesture>",
            "bad01.xml: its points span 0 px; a gesture must span at least 10 px",
        ),
    ],
)
def test_a_bad_gesture_log_says_what_is_wrong(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, message: str
) -> None:
    bad = tmp_path / "bad01.xml"
    bad.write_text(text)
    assert main(["evaluate", str(bad), "--defaults", "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("Error:") and message in err and "Traceback" not in err


def test_an_empty_folder_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "empty").mkdir()
    assert main(["evaluate", str(tmp_path / "empty"), "--out", str(tmp_path / "o")]) == 1
    assert "no recordings (*.json) or $1 gesture logs (*.xml)" in capsys.readouterr().err


def templates_file(path: Path, mapping: dict[str, str]) -> None:
    """$1 templates (a round one and an upturned V) under names unlike the gestures'."""
    round_one = [
        [100 + 50 * math.cos(2 * math.pi * k / 32), 100 + 50 * math.sin(2 * math.pi * k / 32)]
        for k in range(33)
    ]
    upturned_v = [[40 + 3.0 * k, 200 - 4.0 * min(k, 40 - k)] for k in range(41)]
    document = {"templates": [["ring", round_one], ["hat", upturned_v]]}
    path.write_text(json.dumps({**document, "gesture_to_template": mapping}))


@pytest.mark.parametrize(
    ("mapping", "expected_pct"),
    [({"circle": "ring", "caret": "hat"}, 100.0), ({"circle": "hat", "caret": "ring"}, 0.0)],
)
def test_a_templates_file_in_the_folder_is_what_drawings_are_named_against(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], mapping: dict[str, str], expected_pct: float
) -> None:
    root = gesture_folder(tmp_path / "gestures")
    templates_file(root / "templates.json", mapping)
    document = evaluate_json(
        capsys, str(root), "--defaults", "--algorithm", "window", "--out", str(tmp_path / "o")
    )
    # The templates file is not read as a recording, and every drawing is named by it:
    # a mapping to the wrong template names none of them.
    assert document["recordings"] == 8
    for entry in document["summary"]:
        assert entry["recognised_drawn_pct"] == expected_pct
        assert entry["recognised_sent_pct"] == expected_pct
        assert entry["recognised_felt_pct"] == expected_pct


def test_templates_given_elsewhere_name_a_gesture_without_its_own_template_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = gesture_folder(tmp_path / "gestures")
    templates = tmp_path / "only-ring.json"
    templates_file(templates, {"circle": "ring"})
    argv = ["evaluate", str(root), "--defaults", "--algorithm", "window"]
    assert main([*argv, "--templates", str(templates), "--out", str(tmp_path / "o")]) == 0
    table = capsys.readouterr().out
    assert f"against the 2 templates of {templates}" in table
    with (tmp_path / "o" / "results.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    # Carets have no template here: evaluated, not recognised; circles are named "ring".
    for column in ("recognised_sent", "recognised_felt"):
        assert {r[column] for r in rows if r["group"] == "caret"} == {""}
        assert {r[column] for r in rows if r["group"] == "circle"} == {"1"}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", "not valid JSON"),
        ('{"gesture_to_template": {}}', "no 'templates' list"),
        ('{"templates": [["ring", [[1, 2]]]]}', "at least 2 finite points"),
        ('{"templates": [["ring"]]}', "is not [name, [[x, y], ...]]"),
        ('{"templates": []}', "is empty"),
        ('{"templates": [["a", [[0, 0], [1, 1]]]], "gesture_to_template": [1]}', "map names"),
    ],
)
def test_a_bad_templates_file_says_what_is_wrong(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, message: str
) -> None:
    root = gesture_folder(tmp_path / "gestures")
    (root / "templates.json").write_text(text)
    assert main(["evaluate", str(root), "--defaults", "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("Error:") and message in err and "Traceback" not in err
