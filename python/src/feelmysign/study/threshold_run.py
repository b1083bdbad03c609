"""Run the threshold procedure for one participant and dimension, every trial stored at once.

The run goes in steps, shared by the terminal (``run_threshold``) and the page
(``threshold_desk``): ``open_run`` (the unfinished run, replayed, or a new one),
``next_trial`` (the value QUEST+ chooses and the direction), ``trial_stroke``
(what the sleeve plays), ``record_answer`` (stored, then QUEST+ updated; the run
is finished with its estimate when the stopping rule says so). A run resumes
after any stop: its stored trials are replayed into QUEST+, and the next trial
is the same as it would have been.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

from feelmysign.errors import StudyError
from feelmysign.layout import Layout
from feelmysign.stroke import Stroke
from feelmysign.study.choices import DIRECTIONS, Dimension
from feelmysign.study.runner import Play
from feelmysign.study.store import StudyStore
from feelmysign.study.threshold import (
    Estimate,
    Procedure,
    check_fits,
    dimension_settings,
    direction_for,
    threshold_stroke,
)

Respond = Callable[[str, float], str]


@dataclass(frozen=True)
class NextTrial:
    run_id: int
    position: int  # 0.. within the run
    value: float  # grid units (length) or ms (duration)
    direction: str


def open_run(
    store: StudyStore, code: str, dimension: Dimension, *, simulated: bool = False
) -> tuple[int, Procedure]:
    """The participant's unfinished run of ``dimension`` (replayed), or a new one; a dry run
    (``simulated``) never continues a measured run, nor the other way round."""
    procedure = Procedure(store.design.threshold, dimension)
    run = unfinished_run(store, code, dimension, simulated=simulated)
    if run is not None:
        replay(store, run, procedure)
        return run, procedure
    settings = asdict(dimension_settings(store.design.threshold, dimension))
    return store.start_threshold_run(code, dimension, settings, simulated=simulated), procedure


def unfinished_run(
    store: StudyStore, code: str, dimension: Dimension, *, simulated: bool = False
) -> int | None:
    dry = simulated or bool(store.participant(code)["simulated"])
    for run in store.threshold_runs(code):
        if (
            run["dimension"] == dimension
            and run["finished_at_ms"] is None
            and bool(run["simulated"]) == dry
        ):
            return int(run["id"])
    return None


def replay(store: StudyStore, run_id: int, procedure: Procedure) -> None:
    """Feed QUEST+ the run's stored trials it has not seen yet."""
    for trial in store.threshold_trials(run_id)[procedure.trials :]:
        procedure.update(trial["value"], bool(trial["correct"]))


def next_trial(run_id: int, procedure: Procedure) -> NextTrial:
    position = procedure.trials
    return NextTrial(run_id, position, procedure.next_value(), direction_for(run_id, position))


def trial_stroke(
    store: StudyStore, layout: Layout, dimension: Dimension, trial: NextTrial
) -> Stroke:
    return threshold_stroke(
        layout, store.design.threshold, dimension, trial.value, trial.direction, str(uuid.uuid4())
    )


def record_answer(
    store: StudyStore,
    procedure: Procedure,
    trial: NextTrial,
    response: str,
    events: list[dict[str, Any]],
) -> str | None:
    """Store the answer, update QUEST+; the reason the run stopped (it is then finished)."""
    if response not in DIRECTIONS:
        raise StudyError(f"the answer is one of {', '.join(sorted(DIRECTIONS))}; got {response!r}")
    store.record_threshold_trial(
        trial.run_id,
        position=trial.position,
        value=trial.value,
        direction=trial.direction,
        response=response,
        events=events,
    )
    procedure.update(trial.value, response == trial.direction)
    reason = procedure.stop_reason()
    if reason is not None:
        finish_run(store, trial.run_id, procedure, reason)
    return reason


def finish_run(store: StudyStore, run_id: int, procedure: Procedure, reason: str) -> Estimate:
    estimate = procedure.estimate()
    store.finish_threshold_run(
        run_id,
        threshold=estimate.threshold,
        low=estimate.low,
        high=estimate.high,
        stop_reason=reason,
    )
    return estimate


def run_threshold(
    store: StudyStore,
    code: str,
    dimension: Dimension,
    layout: Layout,
    play: Play,
    respond: Respond,
    progress: Callable[[int, float, str, str], None] = lambda n, value, sent, said: None,
    *,
    simulated: bool = False,
) -> Estimate:
    """Trials until the stopping rule says so; the estimate is stored with the run.
    ``simulated``: a simulated observer answers (a dry run, stored as one)."""
    check_fits(layout, store.design.threshold)
    run_id, procedure = open_run(store, code, dimension, simulated=simulated)
    while procedure.stop_reason() is None:
        trial = next_trial(run_id, procedure)
        events = play([trial_stroke(store, layout, dimension, trial)])
        answer = respond(trial.direction, trial.value)
        record_answer(store, procedure, trial, answer, events)
        progress(procedure.trials, trial.value, trial.direction, answer)
    reason = procedure.stop_reason()
    assert reason is not None
    if (
        unfinished_run(store, code, dimension, simulated=simulated) == run_id
    ):  # stopped before it was finished
        return finish_run(store, run_id, procedure, reason)
    return procedure.estimate()
