"""Run the threshold procedure for one participant and dimension, every trial stored at once.

``respond(direction, value) -> answer`` is the wearer: the researcher typing what
they said, or a ``SimulatedObserver``. The run resumes after any stop: its stored
trials are replayed into QUEST+ and it continues with the next one.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable
from dataclasses import asdict

from feelmysign.layout import Layout
from feelmysign.study.runner import Play
from feelmysign.study.store import StudyStore
from feelmysign.study.threshold import (
    Dimension,
    Estimate,
    Procedure,
    check_fits,
    dimension_settings,
    direction_for,
    threshold_stroke,
)

Respond = Callable[[str, float], str]


def open_run(store: StudyStore, code: str, dimension: Dimension) -> tuple[int, Procedure]:
    """The participant's unfinished run of ``dimension`` (replayed), or a new one."""
    procedure = Procedure(store.design.threshold, dimension)
    for run in store.threshold_runs(code):
        if run["dimension"] == dimension and run["finished_at_ms"] is None:
            for trial in store.threshold_trials(run["id"]):
                procedure.update(trial["value"], bool(trial["correct"]))
            return int(run["id"]), procedure
    settings = asdict(dimension_settings(store.design.threshold, dimension))
    return store.start_threshold_run(code, dimension, settings), procedure


def run_threshold(
    store: StudyStore,
    code: str,
    dimension: Dimension,
    layout: Layout,
    play: Play,
    respond: Respond,
    progress: Callable[[int, float, str, str], None] = lambda n, value, sent, said: None,
) -> Estimate:
    """Trials until the stopping rule says so; the estimate is stored with the run."""
    check_fits(layout, store.design.threshold)
    run_id, procedure = open_run(store, code, dimension)
    while (reason := procedure.stop_reason()) is None:
        value = procedure.next_value()
        direction = direction_for(run_id, procedure.trials)
        stroke = threshold_stroke(
            layout, store.design.threshold, dimension, value, direction, str(uuid.uuid4())
        )
        events = play([stroke])
        answer = respond(direction, value)
        store.record_threshold_trial(
            run_id, value=value, direction=direction, response=answer, events=events
        )
        procedure.update(value, answer == direction)
        progress(procedure.trials, value, direction, answer)
    estimate = procedure.estimate()
    store.finish_threshold_run(
        run_id,
        threshold=estimate.threshold,
        low=estimate.low,
        high=estimate.high,
        stop_reason=reason,
    )
    return estimate
