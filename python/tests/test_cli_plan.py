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
        (["0,0,2,0,1000", "--intensity", "1.5"], ["--intensity", "[0, 1]"]),
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
    assert done.returncode == 2 and "usage" in done.stderr


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
