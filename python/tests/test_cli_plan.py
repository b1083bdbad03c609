"""``feelmysign plan`` as users and scripts call it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from vectors import load

from feelmysign.cli import main

FEELMYSIGN = [sys.executable, "-m", "feelmysign"]
PLANNER = dict(load("planner"))


def _legacy(case: dict[str, Any]) -> str:
    s = case["stroke"]
    return ",".join(f"{v:g}" for v in (*s["start"], *s["end"], s["duration_ms"]))


def _json_lines(capsys: pytest.CaptureFixture[str], *argv: str) -> list[dict[str, Any]]:
    assert main(["plan", *argv, "--json"]) == 0
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


def test_worked_example_from_the_issue(capsys: pytest.CaptureFixture[str]) -> None:
    (result,) = _json_lines(capsys, "0,0,2,0,1000")
    assert [round(c["start_ms"], 2) for c in result["commands"]] == [0.0, 157.05, 480.37]
    assert [round(c["duration_ms"], 2) for c in result["commands"]] == [342.95, 862.58, 519.63]
    assert result["adjusted"] is None
    assert set(result["commands"][0]) == {"row", "column", "start_ms", "duration_ms", "intensity"}


@pytest.mark.parametrize(
    "name",
    [
        n
        for n in PLANNER
        if n.startswith(("direction/", "interior/", "worked/", "feasible/too-fast"))
    ],
)
def test_cli_matches_the_vectors(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    case = PLANNER[name]
    (result,) = _json_lines(
        capsys,
        _legacy(case),
        "--intensity",
        "1",
        "--rows",
        "3",
        "--columns",
        "4",
        "--spacing-cm",
        "3",
    )
    expected = case["expected"]
    assert len(result["commands"]) == len(expected["commands"])
    for got, want in zip(result["commands"], expected["commands"], strict=True):
        assert (got["row"], got["column"]) == (want["row"], want["column"])
        for key in ("start_ms", "duration_ms", "intensity"):
            assert got[key] == pytest.approx(want[key], abs=case["tolerance"])
    assert (result["adjusted"] is None) == (expected["adjusted"] is None)


def test_too_fast_is_slowed_and_reported(capsys: pytest.CaptureFixture[str]) -> None:
    (result,) = _json_lines(capsys, "0,0,3,2,50")
    assert result["adjusted"]["reason"] == "too_fast"
    assert result["adjusted"]["duration_ms"] > 50
    assert (
        max(c["start_ms"] + c["duration_ms"] for c in result["commands"])
        >= result["adjusted"]["duration_ms"]
    )


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["0,0,5,5,1000"], ["outside", "0..3", "0..2"]),
        (["0,0,3,2,50", "--strict"], ["too fast", "73.701"]),
        (["0,0,2,0"], ["5"]),
        (["0,0,2,0,-5"], ["duration"]),
    ],
)
def test_bad_strokes_print_an_error_and_exit_1(
    argv: list[str], words: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", *argv]) == 1
    captured = capsys.readouterr()
    assert captured.err.startswith("Error: ")
    assert all(w in captured.err for w in words), captured.err


def test_readable_output_has_a_table_and_a_picture(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", "0.5,0.5,2.5,1.5,800"]) == 0
    out = capsys.readouterr().out
    assert "start ms" in out and "intensity" in out
    assert "x=0" in out and "y=2" in out and "S" in out and "E" in out


def test_strokes_from_stdin_through_the_console_script(tmp_path: Path) -> None:
    done = subprocess.run(
        [*FEELMYSIGN, "plan", "-", "--json"],
        input="0,0,2,0,1000\n\n3,2,0,0,1500\n",
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    lines = [json.loads(line) for line in done.stdout.splitlines()]
    assert [line["stroke"]["end"] for line in lines] == [[2.0, 0.0], [0.0, 0.0]]


def test_invalid_stroke_has_no_traceback() -> None:
    done = subprocess.run(
        [*FEELMYSIGN, "plan", "nonsense"], capture_output=True, text=True, check=False
    )
    assert done.returncode == 1
    assert done.stderr.startswith("Error: ") and "Traceback" not in done.stderr


def test_usage_error_exits_2() -> None:
    done = subprocess.run([*FEELMYSIGN, "plan"], capture_output=True, text=True, check=False)
    assert done.returncode == 2 and done.stderr.startswith("Error: ")
    assert "STROKE" in done.stderr and "feelmysign plan --help" in done.stderr


def test_a_thinned_stroke_says_so_and_keeps_its_time(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", "2.0429,0.1643,0.9571,0.8214,83.3333"]) == 0
    out = capsys.readouterr().out
    assert "in 83.333 ms" in out and "Adjusted" not in out
    assert "Thinned: 2 of 4 virtual actuators left out" in out


def test_the_minimum_burst_comes_from_the_layout_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    layout = tmp_path / "lra.toml"
    layout.write_text('rows = 3\ncolumns = 4\nspacing_cm = 3.0\nactuator_type = "LRA"\n')
    (result,) = _json_lines(capsys, "0,0,3,2,65", "--layout", str(layout))
    assert result["adjusted"] is None and result["duration_ms"] == 65
    (result,) = _json_lines(capsys, "0,0,3,2,65")  # the paper's ERM sleeve
    assert result["adjusted"]["duration_ms"] == 73.701


def test_the_picture_numbers_each_actuator_by_its_first_command_in_the_table(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # A long diagonal: actuators with several commands, so ranks and numbers would differ.
    assert main(["plan", "0,0,3,2,1500"]) == 0
    out = capsys.readouterr().out
    table, picture = out.split("\n\n")[1:3]
    first: dict[tuple[int, int], int] = {}
    for line in table.splitlines()[1:]:
        number, row, column = (int(v) for v in line.split()[:3])
        first.setdefault((row, column), number)
    assert len(first) < len(table.splitlines()) - 1  # some actuator has a later command too
    marks = "123456789abcdefghijklmnopqrstuvwxyz"
    shown: dict[tuple[int, int], str] = {}
    for line in picture.splitlines()[1:]:
        if line.startswith("y="):
            row = int(line[2:6])
            for column in range(4):
                shown[(row, column)] = line[6 + column * 8]
    assert shown == {
        (row, column): marks[first[(row, column)] - 1] if (row, column) in first else "."
        for row in range(3)
        for column in range(4)
    }
    assert "# of its first command in the table" in out and "x = column" in out


RECORDING = {
    "canvas": {"width_px": 400, "height_px": 300},
    "paths": [
        [
            {"t_ms": 10.0 * k, "x": 20.0 + 6 * k, "y": 20.0 + (k if k < 30 else 60 - k) * 8}
            for k in range(60)
        ]
    ],
}


@pytest.mark.parametrize("command", ["simplify", "replay"])
def test_simplify_and_replay_json_pipe_into_plan(command: str, tmp_path: Path) -> None:
    recording = tmp_path / "drawing.json"
    recording.write_text(json.dumps(RECORDING), encoding="utf-8")
    made = subprocess.run(
        [*FEELMYSIGN, command, str(recording), "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    )
    sent = json.loads(made.stdout)["strokes"]
    assert len(sent) >= 2  # a V: at least two strokes
    planned = subprocess.run(
        [*FEELMYSIGN, "plan", "-", "--json"],
        input=made.stdout,
        capture_output=True,
        text=True,
        check=False,
        timeout=60,
    )
    assert planned.returncode == 0, planned.stderr
    schedules = [json.loads(line) for line in planned.stdout.splitlines()]
    assert [s["stroke"]["start"] for s in schedules] == [s["start"] for s in sent]
    assert [s["stroke"]["end"] for s in schedules] == [s["end"] for s in sent]


def test_piped_strokes_off_the_grid_name_the_grid_they_were_made_for(tmp_path: Path) -> None:
    document = {
        "params": {"rows": 5, "columns": 6},
        "strokes": [{"start": [0, 0], "end": [5, 4], "duration_ms": 900}],
    }
    done = subprocess.run(
        [*FEELMYSIGN, "plan", "-"],
        input=json.dumps(document, indent=2),
        capture_output=True,
        text=True,
        check=False,
        timeout=60,
    )
    assert done.returncode == 1
    assert done.stderr.startswith("Error: standard input: strokes[0]")
    assert "--rows 5 --columns 6" in done.stderr


def test_the_table_shows_each_motor_as_driven_under_the_layouts_cap(
    capped_layout: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    layout = capped_layout
    for asked, driven in ((0.9, 0.5), (0.3, 0.3)):
        assert (
            main(["plan", "--layout", str(layout), "--intensity", str(asked), "0,0,3,0,600"]) == 0
        )
        out = capsys.readouterr().out
        assert ("driven at most 0.5" in out) == (asked > 0.5), out
        rows = [line.split() for line in out.splitlines() if line[:3].strip().isdigit()]
        assert len(rows) == 4 and {float(row[-1]) for row in rows} == {driven}, rows
