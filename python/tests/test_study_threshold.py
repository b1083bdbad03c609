"""SQ2.2: QUEST+ finds a simulated wearer's known threshold, and a run survives a restart."""

from __future__ import annotations

import contextlib
import io
import json
import random
from pathlib import Path
from typing import Any

import pytest
from study_helpers import PAPER_DESIGN, new_study

from feelmysign.cli import main as cli_main
from feelmysign.errors import StudyError
from feelmysign.layout import grid_layout
from feelmysign.study import StudyStore, load_design
from feelmysign.study.api import StudyApi
from feelmysign.study.choices import DIRECTIONS
from feelmysign.study.runner import Session
from feelmysign.study.simulated_sleeve import offline_player
from feelmysign.study.threshold import Procedure, SimulatedObserver, check_fits
from feelmysign.study.threshold_run import run_threshold


@pytest.mark.parametrize(("dimension", "truth"), [("length", 0.6), ("duration", 150.0)])
def test_the_interval_covers_a_known_threshold_about_95_percent(
    dimension: str, truth: float
) -> None:
    design = load_design(PAPER_DESIGN)
    runs, covered = 20, 0
    for run in range(runs):
        procedure = Procedure(design.threshold, dimension)  # type: ignore[arg-type]
        observer, rng = SimulatedObserver(truth), random.Random(run)
        while procedure.stop_reason() is None:
            value, direction = procedure.next_value(), rng.choice(["up", "down", "left", "right"])
            procedure.update(value, observer.respond(direction, value, rng) == direction)
        estimate = procedure.estimate()
        assert estimate.trials == design.threshold.trials
        covered += estimate.low <= truth <= estimate.high
    assert covered >= 16  # P(X >= 16) = 0.98 for a 95% interval over 20 runs


def test_a_run_is_stored_trial_by_trial_and_resumes(tmp_path: Path) -> None:
    store = new_study(tmp_path)
    code = store.add_participant(simulated=True)
    store.set_consent(code, True)
    layout = Session(store, None).layout
    observer, rng = SimulatedObserver(0.5), random.Random(1)
    calls = 0

    def respond(direction: str, value: float) -> str:
        nonlocal calls
        calls += 1
        if calls == 8:
            raise KeyboardInterrupt  # Ctrl-C at the eighth answer
        return observer.respond(direction, value, rng)

    with pytest.raises(KeyboardInterrupt):
        run_threshold(store, code, "length", layout, offline_player(layout), respond)
    reopened = StudyStore(store.path)
    (run,) = reopened.threshold_runs(code)
    assert len(reopened.threshold_trials(run["id"])) == 7
    estimate = run_threshold(reopened, code, "length", layout, offline_player(layout), respond)
    assert len(reopened.threshold_trials(run["id"])) == reopened.design.threshold.trials
    assert reopened.threshold_runs(code)[0]["threshold"] == pytest.approx(estimate.threshold)


def test_a_stroke_longer_than_the_sleeve_is_refused_before_any_trial() -> None:
    design = load_design(PAPER_DESIGN)
    with pytest.raises(StudyError, match="at most 1"):
        check_fits(grid_layout(2, 4, 3.0), design.threshold)


def _desk_call(api: StudyApi, method: str, path: str, body: dict[str, Any]) -> tuple[int, Any]:
    raw = json.dumps(body).encode()
    status, _kind, payload = api.handle(method, path, "127.0.0.1:8000", raw, "application/json")
    return status, json.loads(payload)


def _answer_as_simulated(api: StudyApi, base: str, run: dict[str, Any]) -> tuple[int, Any]:
    """Answers the trial just sent as the simulated participant would."""
    answer = {
        "dimension": "length",
        "position": run["next"]["position"],
        "response": run["simulated_answer"],
    }
    return _desk_call(api, "POST", f"{base}/threshold-answer", answer)


def test_the_page_runs_the_procedure_step_by_step_and_resumes_after_a_restart(
    tmp_path: Path,
) -> None:
    store = new_study(tmp_path)
    code = store.add_participant(simulated=True)
    store.set_consent(code, True)
    layout = Session(store, None).layout

    def api() -> StudyApi:
        return StudyApi(Session(StudyStore(store.path), offline_player(layout)), tmp_path / "r")

    page, base = api(), f"/api/study/participants/{code}"
    status, refused = _desk_call(
        page, "POST", f"{base}/threshold-answer", {"dimension": "length", "position": 0}
    )
    assert status == 400 and "has not been sent" in refused["error"]
    for _ in range(5):
        status, state = _desk_call(page, "POST", f"{base}/threshold-send", {"dimension": "length"})
        run = state["dimensions"]["length"]["run"]
        assert status == 200 and run["next"]["sent"] and "direction" not in run["next"]
        assert run["last_send"]["played"] == 1
        status, state = _answer_as_simulated(page, base, run)
        assert status == 200
    before = state["dimensions"]["length"]["run"]
    assert len(before["trials"]) == 5 and before["estimate"]["low"] < before["estimate"]["high"]
    # A restarted server: the run is replayed from the file and goes on with the same trial.
    page = api()
    status, after = _desk_call(page, "GET", f"{base}/threshold", {})
    assert after["dimensions"]["length"]["run"]["trials"] == before["trials"]
    assert after["dimensions"]["length"]["run"]["next"] == {**before["next"], "sent": False}
    assert after["dimensions"]["length"]["run"]["estimate"] == pytest.approx(before["estimate"])
    status, refused = _desk_call(
        page,
        "POST",
        f"{base}/threshold-answer",
        {"dimension": "length", "position": 5, "response": "up"},
    )
    assert status == 400  # sent before the restart only: send it again
    while after["dimensions"]["length"]["run"] is not None:
        _, after = _desk_call(page, "POST", f"{base}/threshold-send", {"dimension": "length"})
        run = after["dimensions"]["length"]["run"]
        _, after = _answer_as_simulated(page, base, run)
    (finished,) = after["dimensions"]["length"]["finished_runs"]
    assert finished["trials"] == store.design.threshold.trials
    assert finished["low"] <= finished["threshold"] <= finished["high"]
    (stored,) = StudyStore(store.path).threshold_runs(code)
    assert stored["stop_reason"] == f"{store.design.threshold.trials} trials"
    assert len(StudyStore(store.path).threshold_trials(stored["id"])) == finished["trials"]
    # Another run started by mistake, one stroke in: discarded, kept in the file, not a result.
    _, again = _desk_call(page, "POST", f"{base}/threshold-send", {"dimension": "length"})
    _, again = _answer_as_simulated(page, base, again["dimensions"]["length"]["run"])
    status, discarded = _desk_call(
        page, "POST", f"{base}/threshold-discard", {"dimension": "length"}
    )
    length = discarded["dimensions"]["length"]
    assert status == 200 and length["run"] is None
    assert length["finished_runs"] == after["dimensions"]["length"]["finished_runs"]
    (thrown,) = length["discarded_runs"]
    assert thrown["trials"] == 1
    row = next(r for r in StudyStore(store.path).threshold_runs(code) if r["id"] == thrown["run"])
    assert row["stop_reason"] == "discarded" and row["threshold"] is None
    status, refused = _desk_call(page, "POST", f"{base}/threshold-discard", {"dimension": "length"})
    assert status == 400 and "nothing to discard" in refused["error"]
    shown = _status_lines(store.path)
    assert f" {thrown['run']} (length): 1 trial, discarded (kept in the file" in shown
    assert f" {stored['id']} (length): {finished['trials']} trials, finished" in shown


def _status_lines(path: Path) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli_main(["study", "status", str(path)]) == 0
    return out.getvalue()


def _run(design_threshold: Any, dimension: str, answer: Any, seed: int) -> Any:
    procedure = Procedure(design_threshold, dimension)  # type: ignore[arg-type]
    rng = random.Random(seed)
    while procedure.stop_reason() is None:
        value, direction = procedure.next_value(), rng.choice(["up", "down", "left", "right"])
        procedure.update(value, answer(direction, value, rng) == direction)
    return procedure.estimate()


@pytest.mark.parametrize("dimension", ["length", "duration"])
def test_a_run_at_an_end_of_the_tested_range_is_a_bound_not_a_measurement(dimension: str) -> None:
    """A wearer who tells no direction (answers by chance) is not measured: the interval
    reaches the top of the range; one who tells every direction gives a bound at its bottom;
    a threshold inside the range is measured."""
    threshold = load_design(PAPER_DESIGN).threshold
    grid = threshold.length if dimension == "length" else threshold.duration
    for seed in range(5):
        guess = _run(threshold, dimension, lambda d, v, rng: rng.choice(sorted(DIRECTIONS)), seed)
        assert guess.censored == "above", guess
        words = guess.words(dimension, grid)
        assert words.startswith("not measured") and "run again" in words
        always = _run(threshold, dimension, lambda d, v, rng: d, seed)
        assert always.censored == "below", always
        assert always.words(dimension, grid).startswith("at most ")
        middle = (grid.minimum * grid.maximum) ** 0.5
        observer = SimulatedObserver(middle)
        inside = _run(threshold, dimension, observer.respond, seed)
        assert inside.censored is None and grid.minimum < inside.low < inside.high < grid.maximum
        assert "e+" not in inside.words(dimension, grid)


def test_a_run_that_measured_nothing_is_not_saved_as_the_wearers_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    store = new_study(tmp_path)
    code = store.add_participant(simulated=True)
    store.set_consent(code, True)
    path = str(store.path)
    store.close()
    wearer = tmp_path / "wearer.json"
    argv = ["study", "threshold", path, "--participant", code, "--dimension", "duration"]
    # A threshold far above the longest stroke tested: the wearer tells almost nothing.
    assert cli_main([*argv, "--simulated-observer", "100000", "--save", str(wearer)]) == 1
    out, err = capsys.readouterr()
    assert "Simulated duration threshold (a dry run, stored as one): not measured" in out, out
    assert f"nothing saved to {wearer}" in err and "Traceback" not in err, err
    assert not wearer.exists()
    # The run is kept, and the report says what it is.
    (run,) = StudyStore(tmp_path / "study.sqlite").threshold_runs(code)
    assert run["threshold"] is not None
