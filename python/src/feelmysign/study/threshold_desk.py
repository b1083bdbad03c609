"""The threshold procedure (SQ2.2) on the researcher's page: one step per request.

``send`` plays the next stroke QUEST+ chose (opening a run when the participant
has none going); ``answer`` stores the direction the wearer named and updates
QUEST+; ``state`` is everything the page shows: the trials so far, the running
estimate with its 95% interval, the stopping rule, and the next trial. The
direction sent is not shown before the answer, so the researcher types what was
said without knowing what is right.

Everything is in the study file: after a restart the runs are replayed from their
stored trials. Only a send without an answer lives in memory (the sleeve's events
of that send); after a restart, the researcher sends that stroke again.
"""

from __future__ import annotations

import math
import random
import threading
from dataclasses import dataclass
from typing import Any

from feelmysign.errors import StudyError
from feelmysign.layout import Layout
from feelmysign.study.choices import DIMENSIONS, Dimension
from feelmysign.study.runner import Play, events_summary
from feelmysign.study.store import DISCARDED, StudyStore
from feelmysign.study.threshold import (
    MIN_TRIALS,
    Procedure,
    SimulatedObserver,
    censored,
    check_fits,
    dimension_settings,
)
from feelmysign.study.threshold_run import (
    NextTrial,
    next_trial,
    open_run,
    record_answer,
    replay,
    trial_stroke,
    unfinished_run,
)

UNITS = {"length": "grid units", "duration": "ms"}


@dataclass
class _Sent:
    trial: NextTrial
    events: list[dict[str, Any]]


def dimension_of(value: Any) -> Dimension:
    if value not in DIMENSIONS:
        raise StudyError(f"dimension is one of {', '.join(DIMENSIONS)}; got {value!r}")
    return value  # type: ignore[no-any-return]


def simulated_observer(store: StudyStore, dimension: Dimension) -> SimulatedObserver:
    """The simulated wearer of a dry run on the page: its threshold lies in the middle of the
    grid (geometrically), where QUEST+ must find it."""
    grid = dimension_settings(store.design.threshold, dimension)
    return SimulatedObserver(math.sqrt(grid.minimum * grid.maximum))


class ThresholdDesk:
    def __init__(self, store: StudyStore, play: Play | None, layout: Layout) -> None:
        self.store = store
        self._play = play
        self._layout = layout
        self._procedures: dict[int, Procedure] = {}  # run -> QUEST+ (rebuilt from the file)
        self._sent: dict[int, _Sent] = {}  # run -> the send waiting for its answer
        self._lock = threading.Lock()  # QUEST+ is not thread-safe; the server is

    def _procedure(self, run_id: int, dimension: Dimension) -> Procedure:
        procedure = self._procedures.get(run_id)
        if procedure is None or procedure.trials > len(self.store.threshold_trials(run_id)):
            procedure = Procedure(self.store.design.threshold, dimension)
        replay(self.store, run_id, procedure)
        self._procedures[run_id] = procedure
        return procedure

    # ---- requests ------------------------------------------------------------------------

    def state(self, code: str) -> dict[str, Any]:
        with self._lock:
            return self._state(code)

    def send(self, code: str, dimension: Dimension) -> dict[str, Any]:
        if self._play is None:
            raise StudyError("no sleeve is connected to this runner; start it with a broker")
        with self._lock:
            check_fits(self._layout, self.store.design.threshold)
            run_id = unfinished_run(self.store, code, dimension)
            if run_id is None:
                run_id, procedure = open_run(self.store, code, dimension)
                self._procedures[run_id] = procedure
            trial = next_trial(run_id, self._procedure(run_id, dimension))
            events = self._play([trial_stroke(self.store, self._layout, dimension, trial)])
            self._sent[run_id] = _Sent(trial, events)
            return self._state(code)

    def answer(
        self, code: str, dimension: Dimension, position: int, response: str
    ) -> dict[str, Any]:
        with self._lock:
            run_id = unfinished_run(self.store, code, dimension)
            sent = self._sent.get(run_id) if run_id is not None else None
            if run_id is None or sent is None or sent.trial.position != position:
                raise StudyError(
                    f"trial {position + 1} of the {dimension} run has not been sent (or the "
                    "server restarted since): send the stroke, then record the answer"
                )
            procedure = self._procedure(run_id, dimension)
            record_answer(self.store, procedure, sent.trial, response, sent.events)
            del self._sent[run_id]
            return self._state(code)

    def discard(self, code: str, dimension: Dimension) -> dict[str, Any]:
        """Discard the participant's run under way (a run started by mistake, or one to
        begin again): it stays in the study file, marked discarded, out of the results."""
        with self._lock:
            run_id = unfinished_run(self.store, code, dimension)
            if run_id is None:
                raise StudyError(f"no {dimension} run is under way for {code}; nothing to discard")
            self.store.discard_threshold_run(run_id)
            self._sent.pop(run_id, None)
            self._procedures.pop(run_id, None)
            return self._state(code)

    # ---- what the page shows -------------------------------------------------------------

    def _state(self, code: str) -> dict[str, Any]:
        row = self.store.participant(code)
        return {
            "participant": row["code"],
            "simulated": bool(row["simulated"]),
            "stopping_rule": self._stopping_rule(),
            "dimensions": {
                d: self._dimension(row["code"], d, bool(row["simulated"])) for d in DIMENSIONS
            },
        }

    def _stopping_rule(self) -> str:
        s = self.store.design.threshold
        if s.stop_width > 0:
            return (
                f"stops when the 95% interval is narrower than {s.stop_width:g} x the threshold "
                f"(after at least {MIN_TRIALS} trials), at {s.max_trials} trials at the latest"
            )
        return f"stops after {s.trials} trials"

    def _dimension(self, code: str, dimension: Dimension, simulated: bool) -> dict[str, Any]:
        runs = [r for r in self.store.threshold_runs(code) if r["dimension"] == dimension]
        grid = dimension_settings(self.store.design.threshold, dimension)
        out: dict[str, Any] = {
            "unit": UNITS[dimension],
            "range": [grid.minimum, grid.maximum],
            "fixed": grid.fixed,
            "finished_runs": [
                {
                    "run": r["id"],
                    "threshold": r["threshold"],
                    "low": r["low"],
                    "high": r["high"],
                    "censored": censored(grid, r["low"], r["high"]),
                    "stop_reason": r["stop_reason"],
                    "trials": len(self.store.threshold_trials(r["id"])),
                }
                for r in runs
                if r["finished_at_ms"] is not None and r["stop_reason"] != DISCARDED
            ],
            "discarded_runs": [
                {"run": r["id"], "trials": len(self.store.threshold_trials(r["id"]))}
                for r in runs
                if r["stop_reason"] == DISCARDED
            ],
            "run": None,
        }
        run_id = unfinished_run(self.store, code, dimension)
        if run_id is None:
            return out
        procedure = self._procedure(run_id, dimension)
        trials = self.store.threshold_trials(run_id)
        coming = next_trial(run_id, procedure)
        sent = self._sent.get(run_id)
        waiting = sent is not None and sent.trial.position == coming.position
        estimate = procedure.estimate()
        current: dict[str, Any] = {
            "run": run_id,
            "trials": [
                {
                    "position": t["position"],
                    "value": t["value"],
                    "direction": t["direction"],
                    "response": t["response"],
                    "correct": bool(t["correct"]),
                }
                for t in trials
            ],
            "estimate": None
            if not trials
            else {
                "threshold": estimate.threshold,
                "low": estimate.low,
                "high": estimate.high,
                "censored": estimate.censored,
            },
            # The direction stays hidden until the answer is in.
            "next": {"position": coming.position, "value": coming.value, "sent": waiting},
            "last_send": events_summary(sent.events, 1) if waiting and sent else None,
        }
        if waiting and simulated and sent:
            rng = random.Random(f"{run_id}:{coming.position}")
            observer = simulated_observer(self.store, dimension)
            current["simulated_answer"] = observer.respond(coming.direction, coming.value, rng)
        out["run"] = current
        return out
