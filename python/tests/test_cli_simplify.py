"""``feelmysign simplify`` on recordings built from the shared angle vectors."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from simplifier_checks import simplify_flags, write_recording
from vectors import load

from feelmysign.cli import main

ANGLE = dict(load("angle"))


def _flags(params: dict[str, Any]) -> list[str]:
    numbers = ("check_frames", "max_angle_deg", "frame_max", "fps", "min_duration_ms", "min_length")
    flags = simplify_flags("angle", params, numbers)
    return flags + ([] if params["recover"] else ["--no-recover"])


@pytest.mark.parametrize(
    "name",
    [
        "circle/defaults",
        "zigzag/no-recover",
        "pause/frame-max-60",
        "two-paths/defaults",
        "tap/defaults",
        "circle/stretch",
    ],
)
def test_cli_reproduces_the_vectors(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = ANGLE[name]
    recording = write_recording(case, tmp_path / "drawing.json")
    assert main(["simplify", str(recording), "--json", *_flags(case["params"])]) == 0
    result = json.loads(capsys.readouterr().out)
    expected = case["expected"]["segments"]
    sent = [e for e in expected if e["dropped"] is None]
    dropped = [e for e in expected if e["dropped"] is not None]
    assert len(result["strokes"]) == len(sent) and len(result["dropped"]) == len(dropped)
    for got, want in zip(result["strokes"] + result["dropped"], sent + dropped, strict=True):
        assert got["path"] == want["path"]
        assert got["start"] == pytest.approx(want["start"]) and got["end"] == pytest.approx(
            want["end"]
        )
        assert got["duration_ms"] == pytest.approx(want["end_ms"] - want["start_ms"])
        assert got["emitted_at_ms"] == pytest.approx(want["emitted_at_ms"])
        assert got.get("reason") == want["dropped"]


def test_readable_summary(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    recording = write_recording(ANGLE["right-angle/defaults"], tmp_path / "r.json")
    assert main(["simplify", str(recording)]) == 0
    out = capsys.readouterr().out
    assert "stroke(s) sent" in out and "path" in out


def test_a_stroke_sent_at_the_floor_is_noted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The window vector of a line ending in a quick flick back: its last piece, drawn briefer
    # than the sleeve's floor, is sent lasting the floor; the table says so, and JSON gives both.
    case = dict(load("window"))["flick-back/chord"]
    recording = write_recording(case, tmp_path / "flick.json")
    params = {**case["params"], "algorithm": "window"}
    recording.write_text(
        json.dumps(
            {
                **json.loads(recording.read_text()),
                "simplifier": {"algorithm": "window", "params": params},
            }
        )
    )
    assert main(["simplify", str(recording)]) == 0
    out = capsys.readouterr().out
    paced = [
        e for e in case["expected"]["segments"] if e["duration_ms"] != e["end_ms"] - e["start_ms"]
    ]
    assert len(paced) == 1, paced
    drawn = paced[0]["end_ms"] - paced[0]["start_ms"]
    assert f"at the sleeve's floor (drawn in {drawn:.1f} ms)" in out, out
    assert out.count("at the sleeve's floor") == 1, out
    assert main(["simplify", str(recording), "--json"]) == 0
    strokes = json.loads(capsys.readouterr().out)["strokes"]
    assert [s["duration_ms"] for s in strokes if s["end_ms"] - s["start_ms"] < 73.701] == [73.701]


@pytest.mark.parametrize(
    ("content", "words"),
    [
        ("not json", ["not valid JSON"]),
        ('{"canvas": "\udcff"}', ["not UTF-8 text (byte 12)", "saved as UTF-8"]),
        ('{"paths": []}', ["canvas"]),
        ('{"canvas": {"width_px": 0, "height_px": 10}, "paths": []}', ["width_px", "> 0"]),
        (
            '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [[{"t_ms": 0, "x": 1}]]}',
            ["paths[0][0]"],
        ),
        (
            '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [[{"t_ms": 5, "x": 1, "y": 1},'
            ' {"t_ms": 1, "x": 1, "y": 1}]]}',
            ["back in time"],
        ),
    ],
)
def test_bad_recordings_say_what_is_wrong(
    content: str, words: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bad.json"
    path.write_bytes(content.encode("utf-8", "surrogateescape"))
    assert main(["simplify", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("Error: ") and all(w in err for w in words), err


def test_missing_file_and_bad_parameter(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simplify", str(tmp_path / "absent.json")]) == 1
    assert "cannot read recording" in capsys.readouterr().err
    recording = write_recording(ANGLE["circle/defaults"], tmp_path / "c.json")
    # A value outside a parameter's range is a usage error, named as its option, with the range.
    with pytest.raises(SystemExit) as caught:
        main(["simplify", str(recording), "--paper", "--check-frames", "1"])
    assert caught.value.code == 2
    err = capsys.readouterr().err
    assert "--check-frames: 1 is out of range; give a whole number from" in err, err


def test_a_gesture_log_given_to_simplify_is_named_and_pointed_to_evaluate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "arrow01.xml"
    log.write_text(
        '<?xml version="1.0"?>\n<Gesture Name="arrow01"><Point X="1" Y="2" T="3"/></Gesture>\n'
    )
    assert main(["simplify", str(log)]) == 1
    err = capsys.readouterr().err
    assert "XML, not a recording" in err and "feelmysign evaluate reads $1 gesture logs" in err
    assert "Traceback" not in err
