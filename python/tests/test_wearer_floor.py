"""The wearer's measured limits become the sleeve's floor, and senders keep strokes above it.

The loop end to end: ``study threshold`` with a simulated wearer of known threshold,
``--save``; ``feelmysign sleeve --wearer`` (a real process, on a real Mosquitto); its
retained status; ``replay --send`` reads it, and every stroke it sends is at or above the
limits measured.
"""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path
from typing import Any

import pytest
from sleeve_watch import SleeveWatch, online
from study_helpers import new_study

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.bench.sleeve import sleeve_command
from feelmysign.broker import Broker
from feelmysign.cli import main
from feelmysign.cli.send import _say_floor
from feelmysign.events import StatusFloor
from feelmysign.layout import Layout, load_layout
from feelmysign.stroke import Stroke
from feelmysign.study.store import StudyStore
from feelmysign.wearer import (
    SLEEVE_MIN_LENGTH,
    Wearer,
    WearerError,
    check_wearer_fits,
    read_wearer,
    respect_floor,
    save_wearer,
    sleeve_floor,
)

WAIT_S = 60.0
PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
# The simulated wearer: what QUEST+ is to find (grid units, ms).
WEARER_LENGTH = 0.5
WEARER_DURATION_MS = 100.0


def varied_recording(path: Path) -> Path:
    """A zigzag whose legs run from brief and short to long and slow (on the 3 x 4 grid:
    0.36 to 1.12 grid units, 32 to 256 ms at the default settings)."""
    legs = [(30, 60, 3), (60, -120, 12), (20, 50, 2), (80, -140, 16)]
    legs += [(30, 70, 4), (60, -100, 10), (15, 30, 2), (60, 120, 14)]
    x, y, t_ms = 20.0, 200.0, 0.0
    samples = [{"t_ms": t_ms, "x": x, "y": y}]
    for dx, dy, count in legs:
        for _ in range(count):
            x, y, t_ms = x + dx / count, y + dy / count, t_ms + 16.0
            samples.append({"t_ms": t_ms, "x": x, "y": y})
    canvas = {"width_px": 400, "height_px": 300}
    path.write_text(json.dumps({"canvas": canvas, "paths": [samples]}))
    return path


def _strokes(document: dict[str, Any]) -> list[tuple[float, float]]:
    """(length in grid units, duration in ms) of every stroke of a replay's JSON."""
    return [(math.dist(s["start"], s["end"]), s["duration_ms"]) for s in document["strokes"]]


# ---- the wearer file ---------------------------------------------------------------------


def test_save_keeps_the_other_dimension_and_reads_back(tmp_path: Path) -> None:
    path = tmp_path / "wearer.json"
    save_wearer(path, "P01", "length", 0.62)
    save_wearer(path, "P01", "duration", 118.4)
    assert read_wearer(path) == Wearer("P01", 0.62, 118.4)
    save_wearer(path, "P01", "length", 0.7)  # a second run replaces its own dimension only
    assert read_wearer(path) == Wearer("P01", 0.7, 118.4)


def test_save_says_when_it_cannot_write(tmp_path: Path) -> None:
    with pytest.raises(WearerError, match=r"cannot write the wearer file .*give a writable path"):
        save_wearer(tmp_path / "missing-folder" / "wearer.json", "P01", "length", 0.62)


def test_the_file_to_write_by_hand_is_given_as_a_wearer_file_reads_it(tmp_path: Path) -> None:
    with pytest.raises(WearerError) as raised:
        save_wearer(tmp_path / "missing-folder" / "wearer.json", "P01", "length", 0.62)
    said = str(raised.value)
    by_hand = said[said.index("or write ") + len("or write ") : said.index(" into a file by hand")]
    path = tmp_path / "by-hand.json"
    path.write_text(by_hand)  # what the researcher would copy
    assert read_wearer(path) == Wearer("P01", 0.62, None)


def test_save_refuses_another_wearers_file(tmp_path: Path) -> None:
    path = tmp_path / "wearer.json"
    save_wearer(path, "P01", "length", 0.62)
    with pytest.raises(WearerError, match="holds wearer 'P01'"):
        save_wearer(path, "P02", "length", 0.5)
    assert read_wearer(path) == Wearer("P01", 0.62, None)


@pytest.mark.parametrize(
    ("content", "says"),
    [
        ("{", "not JSON"),
        ("[1]", "a wearer file is a JSON object"),
        ('{"wearer": "P01"}', "neither min_length nor min_duration_ms"),
        ('{"wearer": "P01", "min_length": 0}', "min_length = 0 must be a number above 0"),
        ('{"wearer": "P01", "min_duration_ms": 90000}', "at most 5000 ms"),
        ('{"wearer": "P01", "min_length": "0.6"}', 'min_length = "0.6" must be a number'),
        ('{"wearer": "P01", "min_length": true}', "min_length = true must be a number"),
        ('{"wearer": "", "min_length": 0.6}', "wearer must be the wearer's code"),
        ('{"wearer": "P01", "min_lenght": 0.6}', "unknown key(s) min_lenght"),
    ],
)
def test_a_bad_wearer_file_says_what_is_wrong(tmp_path: Path, content: str, says: str) -> None:
    path = tmp_path / "wearer.json"
    path.write_text(content)
    with pytest.raises(WearerError) as raised:
        read_wearer(path)
    assert says in str(raised.value)
    assert "wearer.json" in str(raised.value)


def test_the_sleeve_will_not_start_with_a_bad_wearer_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "wearer.json"
    path.write_text('{"wearer": "P01", "min_length": -1}')
    assert main(["sleeve", "--wearer", str(path), "--broker", "mqtt://127.0.0.1:1"]) == 1
    err = capsys.readouterr().err
    assert "min_length = -1 must be a number above 0" in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("content", "says"),
    [
        ('{"wearer": "P01", "min_length": 10}', "the longest stroke on this 3 x 4 sleeve"),
        ('{"wearer": "P01", "min_duration_ms": 4000}', "no stroke longer than 3000 ms"),
    ],
)
def test_the_sleeve_will_not_start_with_limits_no_stroke_on_it_can_keep(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str, says: str
) -> None:
    layout = tmp_path / "layout.toml"
    layout.write_text(
        "rows = 3\ncolumns = 4\nspacing_cm = 3.0\n\n[safety]\nmax_stroke_duration_ms = 3000\n"
    )
    path = tmp_path / "wearer.json"
    path.write_text(content)
    argv = ["sleeve", "--layout", str(layout), "--wearer", str(path)]
    assert main([*argv, "--broker", "mqtt://127.0.0.1:1"]) == 1
    err = capsys.readouterr().err
    assert says in err and "senders would send nothing" in err and "Traceback" not in err, err
    # Limits the grid can keep start it (up to the broker it cannot reach).
    path.write_text('{"wearer": "P01", "min_length": 3.6, "min_duration_ms": 2999}')
    wearer = read_wearer(path)
    check_wearer_fits(wearer, load_layout(layout), str(path))


# ---- the floor ---------------------------------------------------------------------------


def test_the_floor_is_the_larger_of_the_sleeves_and_the_wearers() -> None:
    own = sleeve_floor(PAPER)
    assert own == StatusFloor(
        min_duration_ms=shortest_planned_ms(PAPER.shortest_burst_ms), min_length=SLEEVE_MIN_LENGTH
    )
    assert own.min_duration_ms == pytest.approx(73.7, abs=0.01)  # two 20 ms ERM bursts
    brief = sleeve_floor(PAPER, Wearer("P01", 0.62, 40.0))  # feels briefer than the motors play
    assert (brief.min_duration_ms, brief.min_length, brief.wearer) == (
        own.min_duration_ms,
        0.62,
        "P01",
    )


def test_a_sender_raises_its_minimums_and_never_lowers_them() -> None:
    floor = StatusFloor(min_duration_ms=118.4, min_length=0.62, wearer="P01")
    duration_ms, length, note = respect_floor(6.1, 0.1, floor)
    assert (duration_ms, length) == (118.4, 0.62)
    assert note is not None and "118.4 ms" in note and "wearer P01" in note
    assert respect_floor(200.0, 1.0, floor) == (200.0, 1.0, None)
    assert respect_floor(6.1, 0.1, None) == (6.1, 0.1, None)


def test_the_motors_floor_alone_leaves_a_senders_minimums_alone() -> None:
    # Without a wearer's limits the simplifier would drop the brief strokes the sleeve can
    # slow and catch up after; only a wearer's measured limits are kept to.
    floor = StatusFloor(min_duration_ms=73.701, min_length=0.05, wearer=None)
    assert respect_floor(6.1, 0.01, floor) == (6.1, 0.01, None)


def test_a_dry_run_is_not_saved_as_a_real_participants_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    store = new_study(tmp_path)
    study, participant = str(store.path), store.add_participant()  # a real participant
    store.set_consent(participant, True)
    store.close()
    wearer = tmp_path / "wearer.json"
    argv = ["study", "threshold", study, "--participant", participant, "--dimension", "length"]
    code = main([*argv, "--simulated-observer", str(WEARER_LENGTH), "--save", str(wearer)])
    err = capsys.readouterr().err
    assert code == 1 and "Error: --save with --simulated-observer" in err, err
    assert f"as {participant}'s measured limit" in err and "Traceback" not in err
    assert not wearer.exists()
    # Refused before the run: no dry run was stored either.
    assert StudyStore(tmp_path / "study.sqlite").query("SELECT * FROM threshold_runs") == []
    # Without --save the dry run goes ahead, stored as one.
    assert main([*argv, "--simulated-observer", str(WEARER_LENGTH)]) == 0
    assert not wearer.exists()


def test_send_says_a_wearers_floor_is_kept_by_senders_not_by_the_sleeve(
    capsys: pytest.CaptureFixture[str],
) -> None:
    below_wearer = [Stroke((0.0, 1.0), (2.0, 1.0), 150.0)]  # played as sent: above 73.7 ms
    _say_floor(StatusFloor(min_duration_ms=283.5, min_length=0.63, wearer="P01"), below_wearer)
    err = capsys.readouterr().err
    assert "the stroke is below it (sent as given: the wearer may not feel" in err, err
    assert "slows" not in err
    too_brief = [Stroke((0.0, 1.0), (2.0, 1.0), 50.0)]
    _say_floor(StatusFloor(min_duration_ms=73.701, min_length=0.05, wearer=None), too_brief)
    assert "(the sleeve slows a briefer one; " in capsys.readouterr().err


def test_replay_says_a_wearers_limits_leave_nothing_and_not_to_lower_the_options(
    tmp_path: Path,
) -> None:
    from dataclasses import replace

    from feelmysign.cli.replay import strokes_to_send
    from feelmysign.cli.simplify import load
    from feelmysign.errors import StrokeError
    from feelmysign.research.rerun import rerun
    from feelmysign.simplify.window import WindowParams

    recording = load(str(varied_recording(tmp_path / "zigzag.json")))
    # Longer than any stroke of the 3 x 4 grid: nothing is left of the drawing.
    params = replace(WindowParams(), min_length=10.0, strict_minimums=True)
    result = rerun(recording, params)
    with pytest.raises(StrokeError) as raised:
        strokes_to_send(result, params, "P01")
    said = str(raised.value)
    assert "wearer P01's limits" in said and "10 grid units" in said, said
    assert "draw it larger or slower" in said and "try a lower" not in said
    with pytest.raises(StrokeError, match="try a lower --min-length"):
        strokes_to_send(result, params)  # a sender's own minimums: lowering them helps


# ---- the loop ----------------------------------------------------------------------------


def test_the_calibration_loop_closes(
    broker: Broker, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    store = new_study(tmp_path)
    study, participant = str(store.path), store.add_participant(simulated=True)
    store.set_consent(participant, True)
    store.close()
    wearer = tmp_path / "wearer.json"
    for dimension, threshold in (("length", WEARER_LENGTH), ("duration", WEARER_DURATION_MS)):
        code = main(
            [
                "study",
                "threshold",
                study,
                "--participant",
                participant,
                "--dimension",
                dimension,
                "--simulated-observer",
                str(threshold),
                "--save",
                str(wearer),
            ]
        )
        assert code == 0
        # The line names what was written, as JSON (the file's own text, to copy by hand).
        said = capsys.readouterr().out.split(f"Saved to {wearer}: ", 1)[1]
        assert json.loads(said.split("; run the sleeve", 1)[0]) == json.loads(wearer.read_text())
    measured = read_wearer(wearer)
    assert measured.min_length is not None and measured.min_duration_ms is not None
    recording = varied_recording(tmp_path / "drawing.json")
    capsys.readouterr()
    assert main(["replay", str(recording), "--json"]) == 0
    unfloored = _strokes(json.loads(capsys.readouterr().out))
    # Without the floor, some strokes are below what the wearer was measured to feel.
    assert any(
        length < measured.min_length or duration_ms < measured.min_duration_ms
        for length, duration_ms in unfloored
    ), (unfloored, measured)

    with SleeveWatch(broker.credentials, "status") as watch:
        sleeve = subprocess.Popen(
            sleeve_command(broker.credentials_path, "--no-legacy", "--wearer", str(wearer)),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            status = watch.next(online, "the sleeve online")
            floor = StatusFloor.from_json(status["floor"])
            assert floor.wearer == participant
            assert floor.min_length == max(measured.min_length, SLEEVE_MIN_LENGTH)
            assert floor.min_duration_ms == max(
                measured.min_duration_ms, shortest_planned_ms(PAPER.shortest_burst_ms)
            )
            capsys.readouterr()
            code = main(
                [
                    "replay",
                    str(recording),
                    "--send",
                    "--speed",
                    "20",
                    "--json",
                    "--credentials",
                    str(broker.credentials_path),
                ]
            )
            assert code == 0
        finally:
            sleeve.terminate()
            sleeve.communicate(timeout=WAIT_S)
    out, err = capsys.readouterr()
    assert f"the sleeve's floor with wearer {participant}'s limits" in err
    lines = [json.loads(line) for line in out.splitlines() if line.strip()]
    sent = [json.loads(line["payload"]) for line in lines if "payload" in line]
    assert sent, out
    for stroke in sent:
        length = math.dist(stroke["start"], stroke["end"])
        assert length >= measured.min_length, (stroke, measured)
        assert stroke["duration_ms"] >= measured.min_duration_ms, (stroke, measured)
    # What was sent is what the floored simplifier gave: none was lost on the way.
    assert len(sent) == len(_strokes(lines[-1]))
