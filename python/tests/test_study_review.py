"""``feelmysign study review``: blind, asks again on a reply it does not know, stops cleanly."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from study_helpers import pilot_study

from feelmysign.study import StudyStore
from feelmysign.study.runner import Session
from feelmysign.study.simulated_sleeve import offline_player

VAGUE = ("something pointy", "a kind of zigzag", "some loops")


def _study_with_unclear_answers(tmp_path: Path) -> tuple[Path, list[int]]:
    store = pilot_study(tmp_path)
    session = Session(store, None)
    session = Session(store, offline_player(session.layout))
    code = store.add_participant()
    session.consent(code, True)
    session.comfort(code, [True, True], adjusted=False)
    ids = []
    for answer in VAGUE:
        trial = session.state(code)["trial"]
        session.send(code)
        session.answer(code, trial["id"], answer=answer, felt_nothing=False, confidence=2)
        ids.append(trial["id"])
    store.close()
    return store.path, ids


def _review(study: Path, typed: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "feelmysign", "study", "review", str(study)],
        input=typed,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_review_is_blind_asks_again_and_keeps_codes_at_the_end_of_input(tmp_path: Path) -> None:
    study, ids = _study_with_unclear_answers(tmp_path)
    sent = [StudyStore(study).trial(i)["shape"] for i in ids]
    # "bogus" is asked again (not a skip that would shift later codes onto other answers);
    # "star" then codes the first answer, "-" the second, and the input ends at the third.
    result = _review(study, "bogus\nstar\n-\n")
    assert result.returncode == 0, result.stderr
    assert "'bogus' is not a choice" in result.stdout
    assert result.stdout.count("[1/3] P01, trial 1: 'something pointy' -> ") == 2
    assert "[3/3] P01, trial 3: 'some loops' -> " in result.stdout
    assert "Stopped: 2 decided and stored, 1 left" in result.stdout
    for shape in set(sent):
        assert f"sent: {shape}" not in result.stdout and f"({shape})" not in result.stdout
    store = StudyStore(study)
    codings = store.latest_codings()
    assert (codings[ids[0]]["status"], codings[ids[0]]["shape"]) == ("shape", "star")
    assert (codings[ids[1]]["status"], codings[ids[1]]["shape"]) == ("none", None)
    assert codings[ids[2]]["status"] == "unclear"
    # The same command goes on with what is left.
    again = _review(study, "circle\n")
    assert "1 answer to review" in again.stdout and "Review done: 1 decided" in again.stdout
    assert StudyStore(study).latest_codings()[ids[2]]["shape"] == "circle"
