"""``feelmysign replay``: deterministic, exact on a browser-style recording, and sent in order."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from cli_environment import clean_cli_environment
from test_cli_send import Sleeve

from feelmysign.broker import Broker
from feelmysign.cli import main
from feelmysign.research.rerun import mismatch, rerun, run_frames
from feelmysign.simplify import AngleParams, Sample, frames_from_samples, load_recording
from feelmysign.simplify.recording import RecordedStroke

CANVAS = {"width_px": 1200, "height_px": 800}


@pytest.fixture(autouse=True)
def clean_environment(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    clean_cli_environment(monkeypatch, tmp_path)


def spiral_samples() -> list[Sample]:
    """A spiral of 1.5 turns, pointer events at uneven times (7 to 11 ms apart)."""
    samples, t_ms = [], 0.0
    for k in range(300):
        angle, radius = k / 300 * 3 * math.pi, 100 + k * 0.6
        samples.append(Sample(t_ms, 600 + radius * math.cos(angle), 400 + radius * math.sin(angle)))
        t_ms += 7.0 + (k * 37 % 5)
    return samples


def _sample(s: Sample) -> dict[str, float]:
    return {"t_ms": s.t_ms, "x": s.x, "y": s.y, "pressure": s.pressure}


def browser_recording(path: Path) -> Path:
    """What the browser downloads: samples, the frames it fed (jittered loop), the strokes sent.

    The frames are not what resampling at 60 fps gives (the loop ran at 59 Hz and its
    times wobble, as a real animation loop's do), so only replaying them reproduces
    the strokes.
    """
    samples = spiral_samples()
    loop = frames_from_samples(samples, 59.0)
    frames = [Sample(f.t_ms + (i % 4) * 1.3, f.x, f.y) for i, f in enumerate(loop)]
    params = AngleParams(canvas_width_px=1200, canvas_height_px=800)
    sent = [p for p in run_frames(params, [frames]) if p.segment.dropped is None]
    document: dict[str, Any] = {
        "canvas": CANVAS,
        "paths": [[_sample(s) for s in samples]],
        "sleeve": {"rows": 3, "columns": 4},
        "simplifier": {"algorithm": "angle", "params": {"fps": 60, "check_frames": 5}},
        "frames": [[_sample(f) for f in frames]],
        "strokes": [
            {
                "path": p.path,
                "start": list(p.segment.start),
                "end": list(p.segment.end),
                "start_ms": p.segment.start_ms,
                "end_ms": p.segment.end_ms,
                "seq": seq,
            }
            for seq, p in enumerate(sent)
        ],
    }
    path.write_text(json.dumps(document))
    return path


def replay_json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, Any]:
    assert main(["replay", *argv, "--json"]) == 0
    document: dict[str, Any] = json.loads(capsys.readouterr().out.splitlines()[-1])
    return document


def test_replaying_twice_gives_identical_strokes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recording = str(browser_recording(tmp_path / "drawing.json"))
    for flags, source in (
        (["--algorithm", "angle", "--fps", "50"], "resampled at 50 fps"),
        (["--algorithm", "window"], "every sample"),
    ):
        first = replay_json(capsys, recording, *flags)
        second = replay_json(capsys, recording, *flags)
        assert first == second
        assert first["strokes"] and first["frames"] == source


def test_the_recorded_frames_replay_to_the_recorded_strokes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = browser_recording(tmp_path / "drawing.json")
    document = replay_json(capsys, str(path))
    assert document["frames"] == "recorded"
    assert document["matches_recording"] is True and document["difference"] is None
    recorded = json.loads(path.read_text())["strokes"]
    assert [(s["start"], s["end"]) for s in document["strokes"]] == [
        (s["start"], s["end"]) for s in recorded
    ]
    assert main(["replay", str(path)]) == 0
    assert "frames: recorded; matches the" in capsys.readouterr().out


def test_resampling_instead_of_the_recorded_frames_is_noticed(tmp_path: Path) -> None:
    """The check has teeth: the same samples resampled give other strokes than the frames did."""
    recording = load_recording(browser_recording(tmp_path / "drawing.json"))
    params = AngleParams(canvas_width_px=1200, canvas_height_px=800)
    resampled = run_frames(params, [frames_from_samples(recording.paths[0], 60.0)])
    assert recording.strokes is not None
    assert mismatch(resampled, recording.strokes) is not None
    assert mismatch(rerun(recording, params).segments, recording.strokes) is None


def test_a_different_stroke_is_reported(tmp_path: Path) -> None:
    recording = load_recording(browser_recording(tmp_path / "drawing.json"))
    params = AngleParams(canvas_width_px=1200, canvas_height_px=800)
    assert recording.strokes is not None
    moved = list(recording.strokes)
    first = moved[1]
    moved[1] = RecordedStroke(first.path, first.start, (0.0, 0.0), first.start_ms, first.end_ms)
    assert (mismatch(rerun(recording, params).segments, moved) or "").startswith("stroke 2 ")
    shorter = mismatch(rerun(recording, params).segments, list(recording.strokes)[:-1])
    assert shorter is not None and "recorded" in shorter


def test_send_options_without_send_are_a_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recording = str(browser_recording(tmp_path / "drawing.json"))
    with pytest.raises(SystemExit) as exit_info:
        main(["replay", recording, "--speed", "2"])
    assert exit_info.value.code == 2
    assert "--speed only applies with --send" in capsys.readouterr().err


def test_send_publishes_the_strokes_in_order_at_their_pace(
    broker: Broker, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = browser_recording(tmp_path / "drawing.json")
    expected = replay_json(capsys, str(path))["strokes"]
    sleeve = Sleeve(broker.credentials)
    try:
        code = main(
            [
                "replay",
                str(path),
                "--send",
                "--speed",
                "20",
                "--credentials",
                str(broker.credentials_path),
            ]
        )
        assert code == 0
        received = sleeve.receive(len(expected))
    finally:
        sleeve.close()
    payloads = [json.loads(payload) for _, payload in received]
    assert {topic for topic, _ in received} == {"feelmysign/sleeve1/strokes"}
    assert [p["seq"] for p in payloads] == list(range(len(expected)))
    assert len({p["drawing"] for p in payloads}) == 1
    for payload, stroke in zip(payloads, expected, strict=True):
        assert payload["start"] == stroke["start"] and payload["end"] == stroke["end"]
        assert payload["duration_ms"] == stroke["duration_ms"]
    # Paced: at 20x, each stroke leaves at least its emitted_at / 20 after the first (a busy
    # machine only makes it later). 2 ms of slack: each sent_at_ms is rounded to a whole ms.
    first = payloads[0]["sent_at_ms"], expected[0]["emitted_at_ms"]
    for payload, stroke in zip(payloads, expected, strict=True):
        sent_ms = payload["sent_at_ms"] - first[0]
        drawn_ms = stroke["emitted_at_ms"] - first[1]
        assert sent_ms >= drawn_ms / 20 - 2, (payload["seq"], sent_ms, drawn_ms / 20)
    out = capsys.readouterr().out
    assert "feelmysign/sleeve1/strokes {" in out and "matches the" in out


def _line_across(path: Path, *, grid: tuple[int, int] | None = None) -> Path:
    """A slow line from the canvas's left edge to its right, for any grid (or the one given)."""
    samples = [{"t_ms": 20.0 * k, "x": 10.0 + 39.0 * k, "y": 300.0} for k in range(31)]
    data: dict[str, Any] = {"canvas": {"width_px": 1200, "height_px": 600}, "paths": [samples]}
    if grid is not None:
        data["sleeve"] = {"rows": grid[0], "columns": grid[1]}
    path.write_text(json.dumps(data))
    return path


def test_send_cuts_the_strokes_for_the_grid_the_sleeve_advertises(
    broker: Broker, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A recording with no grid of its own is cut for the sleeve's (its retained status); one
    whose grid differs is sent as it is, and the difference is said."""
    import subprocess

    from sleeve_watch import SleeveWatch, online

    from feelmysign.bench.sleeve import sleeve_command

    layout = tmp_path / "wide.toml"
    layout.write_text("rows = 3\ncolumns = 5\nspacing_cm = 2.2\n")
    argv = ["--send", "--speed", "20", "--credentials", str(broker.credentials_path), "--json"]
    with SleeveWatch(broker.credentials, "status") as watch:
        sleeve = subprocess.Popen(
            sleeve_command(broker.credentials_path, "--no-legacy", "--layout", str(layout)),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            watch.next(online, "the sleeve online")
            capsys.readouterr()
            assert main(["replay", str(_line_across(tmp_path / "any.json")), *argv]) == 0
            out, err = capsys.readouterr()
            assert "Cut for the 3 x 5 grid of sleeve 'sleeve1' (its status)." in err, err
            ends = [s["end"][0] for s in json.loads(out.splitlines()[-1])["strokes"]]
            assert max(ends) > 3.5  # the line reaches the fifth column
            fixed = _line_across(tmp_path / "fixed.json", grid=(3, 4))
            assert main(["replay", str(fixed), *argv]) == 0
            out, err = capsys.readouterr()
            assert "Cut for a 3 x 4 grid (the recording), but sleeve 'sleeve1' is 3 x 5" in err
            assert "--rows 3 --columns 5" in err
        finally:
            sleeve.terminate()
            sleeve.wait(timeout=60)
