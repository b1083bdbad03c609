"""``feelmysign study``: errors a person can act on, and the dry run from the command line."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from study_helpers import PAPER_DESIGN


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "feelmysign", "study", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
    )


def test_a_bad_design_is_refused_with_every_problem_and_no_traceback(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(PAPER_DESIGN.read_text().replace("repetitions = 3", "repetitions = 'three'"))
    result = _cli("check", str(bad), cwd=tmp_path)
    assert result.returncode == 1
    assert result.stderr.startswith("Error: ")
    assert "study.repetitions: must be a whole number from 1 to 20; got 'three'" in result.stderr
    assert "Traceback" not in result.stderr


def _review_counts(study: Path, tmp_path: Path) -> tuple[int, int, int]:
    """Answers awaiting review as ``status`` (summed), ``review`` and ``analyse`` count them."""
    status = _cli("status", str(study), cwd=tmp_path).stdout
    in_status = sum(int(n) for n in re.findall(r"(\d+) unclear", status))
    review = subprocess.run(
        [sys.executable, "-m", "feelmysign", "study", "review", str(study)],
        input="",  # the end of input at once: nothing decided, the count printed
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    in_review = int(re.search(r"(\d+) answers? to review", review.stdout).group(1))  # type: ignore[union-attr]
    out = tmp_path / "counted"
    analysed = _cli("analyse", str(study), "--out", str(out), "--bootstrap", "50", cwd=tmp_path)
    assert analysed.returncode == 0, analysed.stderr
    in_analysis = int(re.search(r"(\d+) awaiting review", analysed.stdout).group(1))  # type: ignore[union-attr]
    return in_status, in_review, in_analysis


def test_practice_answers_never_wait_for_review_and_every_count_agrees(tmp_path: Path) -> None:
    """A practice shape ('line') that is no shape of the study: its answers are coded
    unclear, yet they are not analysed, so neither status, review nor analyse counts them."""
    from feelmysign.study.store import StudyStore

    line_shape = '[[shapes]]\nname = "line"\nsegments = [1, 2, 4, 8]\n'
    paper = PAPER_DESIGN.read_text()
    start = paper.index(line_shape)
    design = tmp_path / "no-line.toml"
    design.write_text(paper[:start] + paper[paper.index("[[practice]]", start) :])
    study = tmp_path / "s.sqlite"
    assert _cli("new", str(design), "--out", str(study), cwd=tmp_path).returncode == 0
    simulate = [
        "simulate",
        str(study),
        "--participants",
        "2",
        "--seed",
        "1",
        "--wearer",
        "in-range",
    ]
    simulated = _cli(*simulate, cwd=tmp_path)
    assert simulated.returncode == 0, simulated.stderr
    store = StudyStore(study)
    codings = store.latest_codings()
    practice_unclear = [
        t["id"]
        for row in store.participants()
        for t in store.trials(row["code"])
        if t["block"] == "practice" and codings[t["id"]]["status"] == "unclear"
    ]
    main_unclear = [
        t["id"]
        for row in store.participants()
        for t in store.trials(row["code"])
        if t["block"] == "main" and codings[t["id"]]["status"] == "unclear"
    ]
    store.close()
    assert practice_unclear  # the case in question: unclear practice answers exist
    assert _review_counts(study, tmp_path) == (len(main_unclear),) * 3


def test_new_simulate_status_analyse(tmp_path: Path) -> None:
    study = tmp_path / "s.sqlite"
    assert _cli("new", str(PAPER_DESIGN), "--out", str(study), cwd=tmp_path).returncode == 0
    again = _cli("new", str(PAPER_DESIGN), "--out", str(study), cwd=tmp_path)
    assert again.returncode == 1 and "exists already" in again.stderr
    assert _cli("simulate", str(study), "--participants", "2", cwd=tmp_path).returncode == 0
    status = _cli("status", str(study), cwd=tmp_path)
    assert status.stdout.count("74/74 answered") == 2
    out = tmp_path / "results"
    analysed = _cli("analyse", str(study), "--out", str(out), "--bootstrap", "50", cwd=tmp_path)
    assert analysed.returncode == 0, analysed.stderr
    assert (out / "report.md").is_file() and (out / "accuracy.png").is_file()
    missing = _cli("status", str(tmp_path / "none.sqlite"), cwd=tmp_path)
    assert missing.returncode == 1 and "no study file" in missing.stderr


def test_a_design_given_for_a_study_file_says_how_to_make_one(tmp_path: Path) -> None:
    result = _cli("analyse", str(PAPER_DESIGN), cwd=tmp_path)
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert f"{PAPER_DESIGN} is not a study file" in result.stderr
    assert f"'feelmysign study new {PAPER_DESIGN} --out STUDY.sqlite'" in result.stderr


def test_counts_of_one_are_singular(tmp_path: Path) -> None:
    one = tmp_path / "one.toml"
    text = PAPER_DESIGN.read_text().replace("repetitions = 3", "repetitions = 1")
    one.write_text(text)
    checked = _cli("check", str(one), cwd=tmp_path)
    assert checked.returncode == 0, checked.stderr
    assert " x 1 repetition = " in checked.stdout
    study = tmp_path / "s.sqlite"
    assert _cli("new", str(one), "--out", str(study), cwd=tmp_path).returncode == 0
    assert _cli("simulate", str(study), "--participants", "1", cwd=tmp_path).returncode == 0
    out = tmp_path / "results"
    analysed = _cli("analyse", str(study), "--out", str(out), "--bootstrap", "50", cwd=tmp_path)
    assert analysed.returncode == 0, analysed.stderr
    assert analysed.stdout.startswith("1 participant, ")
