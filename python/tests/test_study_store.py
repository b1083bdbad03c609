"""The study file: answers stored once and at once; a killed session resumes with nothing lost."""

from __future__ import annotations

import csv
import json
import os
import random
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from study_helpers import PAPER_DESIGN, ZIGZAG_SHAPE, new_study, zigzag_recording

from feelmysign.cli import main
from feelmysign.errors import StudyError
from feelmysign.study import StudyStore
from feelmysign.study.dry_run import dry_run, run_simulated_participant
from feelmysign.study.runner import Session
from feelmysign.study.simulated_sleeve import offline_player

CHILD = textwrap.dedent(
    """
    import random, sys, time
    from feelmysign.study import StudyStore
    from feelmysign.study.dry_run import run_simulated_participant
    from feelmysign.study.runner import Session
    from feelmysign.study.simulated_sleeve import offline_player

    store = StudyStore(sys.argv[1])
    code = sys.argv[2]
    session = Session(store, None)
    player = offline_player(session.layout)

    def slow(strokes):
        time.sleep(0.02)
        return player(strokes)

    session = Session(store, slow)
    original = session.answer
    def answer(*args, **kwargs):
        result = original(*args, **kwargs)
        print("answered", flush=True)
        return result
    session.answer = answer
    run_simulated_participant(session, code, random.Random(0))
    """
)


def test_the_file_uses_write_ahead_logging(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    assert store.query("PRAGMA journal_mode")[0][0] == "wal"


def test_an_answer_is_never_overwritten_and_needs_consent(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    session = Session(store, offline_player(Session(store, None).layout))
    code = store.add_participant(simulated=True)
    with pytest.raises(StudyError, match="not given consent"):
        session.comfort(code, [True, True], adjusted=False)
    session.consent(code, True)
    session.comfort(code, [True, True], adjusted=True)
    trial = session.state(code)["trial"]
    with pytest.raises(StudyError, match="send the shape"):
        session.answer(code, trial["id"], answer="line", felt_nothing=False, confidence=None)
    session.send(code)
    with pytest.raises(StudyError, match="'felt nothing' takes no confidence"):
        session.answer(code, trial["id"], answer="", felt_nothing=True, confidence=2)
    session.answer(code, trial["id"], answer="line", felt_nothing=False, confidence=4)
    with pytest.raises(StudyError, match="not the current one"):
        session.answer(code, trial["id"], answer="circle", felt_nothing=False, confidence=None)
    assert store.trial(trial["id"])["answer"] == "line"


def test_a_killed_session_loses_no_answer_and_resumes_at_the_next_trial(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    code = store.add_participant(simulated=True)
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(store.path), code],
        stdout=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    assert child.stdout is not None
    acknowledged = 0
    while acknowledged < 12:
        line = child.stdout.readline()
        assert line, "the session ended before it could be killed"
        acknowledged += line.strip() == "answered"
    os.kill(child.pid, signal.SIGKILL)
    child.wait()
    reopened = StudyStore(store.path)
    answered = [t for t in reopened.trials(code) if t["answered_at_ms"] is not None]
    assert len(answered) >= acknowledged  # every answer the session reported is on disk
    positions = [t["position"] for t in answered]
    assert positions == list(range(len(answered)))  # in order, none skipped
    codings = reopened.latest_codings()
    assert all(t["id"] in codings for t in answered)
    current = reopened.current_trial(code)
    assert current is not None and current["position"] == len(answered)
    session = Session(reopened, offline_player(Session(reopened, None).layout))
    run_simulated_participant(session, code, random.Random(1))
    final = reopened.trials(code)
    assert all(t["answered_at_ms"] is not None for t in final)
    assert len(final) == 74
    assert reopened.participant(code)["finished_at_ms"] is not None


def test_a_dry_run_of_the_papers_design_fills_every_table(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    codes = dry_run(store, 2, seed=3)
    assert len(codes) == 2
    assert store.query("SELECT COUNT(*) FROM trials WHERE answered_at_ms IS NULL")[0][0] == 0
    events = store.query("SELECT type, COUNT(*) AS n FROM events GROUP BY type")
    assert {row["type"] for row in events} <= {"played", "adjusted"}
    assert store.query("SELECT COUNT(*) FROM questionnaire")[0][0] == 2 * 5
    assert PAPER_DESIGN.name in (store.meta("design_source") or "")


def test_pause_is_kept_and_blocks_sending(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    session = Session(store, offline_player(Session(store, None).layout))
    code = store.add_participant()
    session.consent(code, True)
    session.comfort(code, [True, True], adjusted=False)
    session.pause(code, True)
    with pytest.raises(StudyError, match="paused"):
        session.send(code)
    session.pause(code, False)
    time.sleep(0.002)
    assert session.send(code)["played"] >= 1
    pauses = store.query("SELECT * FROM pauses")
    assert len(pauses) == 1 and pauses[0]["resumed_at_ms"] is not None


def test_a_dry_run_sends_and_answers_a_recorded_drawing_too(tmp_path: Path) -> None:
    zigzag_recording(tmp_path / "zigzag.json")
    design = tmp_path / "design.toml"
    design.write_text(
        PAPER_DESIGN.read_text()
        .split("[[shapes]]")[0]
        .replace("repetitions = 3", "repetitions = 1")
        .replace('resolutions = ["coarse", "low", "medium", "fine"]', 'resolutions = ["c", "f"]')
        + ZIGZAG_SHAPE
        + '[questionnaire]\nitems = ["comfortable"]\n'
    )
    store = new_study(tmp_path, design)
    dry_run(store, 3, seed=5)
    rows = store.query("SELECT * FROM trials WHERE shape = 'zigzag'")
    assert len(rows) == 3 * 2 and all(r["answered_at_ms"] is not None for r in rows)
    strokes = store.query(
        "SELECT s.strokes_json FROM sends s JOIN trials t ON s.trial = t.id "
        "WHERE t.shape = 'zigzag'"
    )
    assert {len(json.loads(r[0])) for r in strokes} == {t["segments"] for t in rows}


def test_a_response_time_never_holds_the_time_no_runner_ran(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A runner stopped (a crash) after a shape was felt and before its answer: the answer
    recorded after the restart, without sending again, has no response time (how long the
    participant took is not known, and the time between is none of it); answers within one
    run keep theirs."""
    store = new_study(tmp_path)
    now = [1_800_000_000_000]
    store.clock = lambda: now[0]
    player = offline_player(Session(store, None).layout)
    first = Session(store, player)
    code = store.add_participant()
    first.consent(code, True)
    first.comfort(code, [True, True], adjusted=False)
    first.send(code)
    now[0] += 1_500
    first.answer(
        code, None, answer="line", felt_nothing=False, confidence=None
    )  # 1.5 s after its send, the runner running
    now[0] += 1_000
    first.send(code)
    now[0] += 600_000  # the runner dies here; another starts ten minutes later
    second = Session(store, player)
    now[0] += 2_000
    second.answer(
        code, None, answer="line", felt_nothing=False, confidence=None
    )  # the page showed the stored send: not sent again
    now[0] += 1_000
    second.send(code)
    now[0] += 2_500
    second.answer(code, None, answer="line", felt_nothing=False, confidence=None)
    store.close()
    out = tmp_path / "export"
    assert main(["study", "export", str(tmp_path / "study.sqlite"), "--out", str(out)]) == 0
    capsys.readouterr()
    with (out / "trials.csv").open(newline="") as handle:
        times = [row["response_time_s"] for row in csv.DictReader(handle)]
    assert times == ["1.5", "", "2.5"], times
