"""A whole study with simulated participants, before anyone is recruited.

Every step a real session has (consent, comfort check, practice and measured
trials, questionnaire) runs through the same ``Session`` as the page and the
terminal, into a real study file. The sleeve is either the offline one (its
planner's events, at once) or a real sleeve over MQTT (``play``).
"""

from __future__ import annotations

import random
from collections.abc import Callable

from feelmysign.study.runner import Play, Session
from feelmysign.study.simulated_sleeve import offline_player
from feelmysign.study.store import StudyStore


def run_simulated_participant(session: Session, code: str, rng: random.Random) -> None:
    """Consent, comfort, every trial (send + simulated answer), questionnaire."""
    design = session.store.design
    if session.step(code) == "consent":
        session.consent(code, True)
    if session.step(code) == "comfort":
        session.comfort(code, [True] * len(design.comfort), adjusted=False)
    while session.step(code) == "trial":
        session.send(code)
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
    play: Play | None = None,
    progress: Callable[[int, str], None] = lambda number, code: None,
) -> list[str]:
    """Add ``participants`` simulated participants to ``store`` and run each whole session."""
    session = Session(store, None, simulation_seed=seed)
    session = Session(store, play or offline_player(session.layout), simulation_seed=seed)
    codes = []
    for number in range(participants):
        code = store.add_participant(simulated=True)
        run_simulated_participant(session, code, random.Random(f"{seed}:{code}"))
        codes.append(code)
        progress(number + 1, code)
    return codes
