"""A whole study with simulated participants, before anyone is recruited.

Every step a real session has (consent, comfort check, practice and measured
trials, questionnaire) runs through the same ``Session`` as the page and the
terminal, into a real study file. The sleeve is either the offline one (its
planner's events, at once) or a real sleeve over MQTT (``play``).

Reproducible: everything a simulated participant does follows from the run's seed
and the participant's number in the study (never from their random code), and
with the offline sleeve the study file's clock is a simulated one (a trial takes
its felt duration plus a drawn time to answer), so the same design and seed give
the same export byte for byte.
"""

from __future__ import annotations

import json
import math
import random
from collections.abc import Callable

from feelmysign.errors import StudyError
from feelmysign.study.runner import Play, Session
from feelmysign.study.simulated import (
    IN_RANGE,
    TEMPLATE,
    TRUTH_KEY,
    WEARERS,
    simulated_truth,
    truth_json,
)
from feelmysign.study.simulated_sleeve import offline_player
from feelmysign.study.store import StudyStore, now_ms

ANSWER_MEDIAN_S = 3.0  # a simulated participant's time to answer after a shape has played


def _record_in_range(store: StudyStore, number: int) -> None:
    truth = simulated_truth(store) or {**truth_json(store.design), "participants": []}
    truth["participants"] = sorted({*truth["participants"], number})
    store.set_meta(TRUTH_KEY, json.dumps(truth, sort_keys=True))


class SimulatedClock:
    """A clock that moves only when told: the study file's times in an offline dry run."""

    def __init__(self, start_ms: int) -> None:
        self.at_ms = start_ms

    def __call__(self) -> int:
        return self.at_ms

    def advance(self, ms: float) -> None:
        self.at_ms += round(ms)


def run_simulated_participant(
    session: Session, code: str, rng: random.Random, clock: SimulatedClock | None = None
) -> None:
    """Consent, comfort, every trial (send + simulated answer), questionnaire; ``clock``
    (when the sleeve is simulated too) moves by each trial's felt duration and a drawn
    time to answer."""
    design = session.store.design
    if session.step(code) == "consent":
        session.consent(code, True)
    if session.step(code) == "comfort":
        session.comfort(code, [True] * len(design.comfort), adjusted=False)
    while session.step(code) == "trial":
        played = session.send(code)
        if clock is not None:
            clock.advance(
                played["felt_duration_ms"]
                + 1000 * rng.lognormvariate(math.log(ANSWER_MEDIAN_S), 0.4)
            )
        reply = session.simulated_answer(code)
        session.answer(
            code,
            None,
            answer=reply["answer"],
            felt_nothing=reply["felt_nothing"],
            confidence=reply["confidence"],
        )
    if session.step(code) == "questionnaire":
        points = design.questionnaire.points
        values = [
            min(points, max(1, round(rng.gauss(points * 0.7, 1))))
            for _ in design.questionnaire.items
        ]
        session.questionnaire(code, values)


def dry_run(
    store: StudyStore,
    participants: int,
    *,
    seed: int = 0,
    wearer: str = TEMPLATE,
    play: Play | None = None,
    progress: Callable[[int, str], None] = lambda number, code: None,
) -> list[str]:
    """Add ``participants`` simulated participants to ``store`` and run each whole session;
    ``wearer`` says how they answer (``simulated.WEARERS``)."""
    if wearer not in WEARERS:
        raise StudyError(f"unknown simulated wearer {wearer!r}; one of {', '.join(WEARERS)}")
    session = Session(store, None, simulation_seed=seed)
    session = Session(
        store,
        play or offline_player(session.layout),
        simulation_seed=seed,
        wearer=wearer,
        dry_run=True,
    )
    clock = SimulatedClock(now_ms()) if play is None else None
    codes = []
    if clock is not None:
        store.clock = clock
    try:
        for number in range(participants):
            code = store.add_participant(simulated=True)
            row = store.participant(code)
            if wearer == IN_RANGE:
                _record_in_range(store, int(row["number"]))
            run_simulated_participant(
                session, code, random.Random(f"{seed}:{row['number']}"), clock
            )
            codes.append(code)
            progress(number + 1, code)
    finally:
        store.clock = now_ms
    return codes
