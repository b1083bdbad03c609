"""A session, and the review of unclear answers, in the terminal (``feelmysign study run``).

The same steps as the page, through the same ``Session``; Ctrl-C at any prompt
stops with every answer given so far stored, and the same command resumes.
"""

from __future__ import annotations

from feelmysign.connection import BrokerSettings
from feelmysign.events import StatusFloor
from feelmysign.plural import plural
from feelmysign.study.below_floor import below_floor, below_floor_message
from feelmysign.study.runner import Session
from feelmysign.study.sleeve_link import SleeveLink
from feelmysign.study.store import StudyStore


def _yes(question: str) -> bool:
    return input(f"{question} [y/n] ").strip().lower().startswith("y")


def run_in_terminal(store: StudyStore, settings: BrokerSettings, participant: str | None) -> int:
    try:
        return _session(store, settings, participant)
    except EOFError:  # Ctrl-D, or the end of piped input: every answer given is stored
        print(
            "\nStopped at the end of input; every answer given is stored. Resume with "
            "--participant and the code printed above."
        )
        return 0


def _session(store: StudyStore, settings: BrokerSettings, participant: str | None) -> int:
    with SleeveLink(settings) as link:
        session = Session(store, link.play)
        _say_below_floor(store, link.floor(), settings.sleeve_id)
        code = participant or store.add_participant()
        print(f"Participant {code} ({store.design.name}). Ctrl-C stops; the same command resumes.")
        design = store.design
        if session.step(code) == "consent":
            session.consent(code, _yes("Has the participant given informed consent?"))
            if session.step(code) == "consent":
                print("No consent: nothing is recorded.")
                return 1
        if session.step(code) == "comfort":
            answers = [_yes(q) for q in design.comfort]
            session.comfort(code, answers, adjusted=_yes("Was the sleeve adjusted?"))
        while session.step(code) == "trial":
            trial = session.state(code)["trial"]
            what = trial["resolution"] or "practice"
            speed = trial["speed_cm_s"]
            at = f", {speed:g} cm/s" if design.speed_is_factor and speed is not None else ""
            print(
                f"Trial {trial['number']}/{trial['total']}: {trial['shape']}, {what}, "
                f"{_plural(trial['segments'], 'stroke')}{at}"
            )
            input("  Enter sends the shape to the sleeve. ")
            sent = session.send(code)
            print(
                f"  played {sent['played']}/{_plural(sent['strokes'], 'stroke')}, "
                f"rejected {sent['rejected'] or 'none'}"
            )
            answer = input("  Answer (empty = felt nothing, 'r' = send again): ").strip()
            if answer == "r":
                continue
            # Felt nothing: there is nothing to be confident of, and none is asked.
            confidence = input("  Confidence 1-5 (empty = none): ").strip() if answer else ""
            coding = session.answer(
                code,
                trial["id"],
                answer=answer,
                felt_nothing=not answer,
                confidence=int(confidence) if confidence.isdigit() else None,
            )
            print(f"  coded: {coding['shape'] or coding['status']} ({coding['rule']})")
        if session.step(code) == "questionnaire":
            points = design.questionnaire.points
            values = []
            for item in design.questionnaire.items:
                while (
                    not (reply := input(f"{item} (1-{points}): ").strip()).isdigit()
                    or not 1 <= int(reply) <= points
                ):
                    print(f"  Type a number from 1 to {points}.")
                values.append(int(reply))
            session.questionnaire(code, values)
        print(f"Session of {code}: {session.step(code)}.")
    return 0


def _say_below_floor(store: StudyStore, floor: StatusFloor | None, sleeve_id: str) -> None:
    """Once, before the first trial: the conditions whose strokes are below the wearer's
    limits the sleeve advertises (none said without a wearer's limits: the sleeve's own floor
    is what ``study check`` warns about)."""
    if floor is None or not floor.wearer:
        return
    found = below_floor(store.design, store.base_dir, floor)
    if found:
        print(below_floor_message(found, floor, sleeve_id), flush=True)


def review_in_terminal(store: StudyStore) -> int:
    """Decide each unclear answer, blind: the prompt shows the answer and names its item,
    never the shape that was sent. A reply that is not a choice is asked again; every
    decision is stored at once, so Ctrl-D (or the end of piped input) stops with every
    earlier one kept, and the same command goes on with the rest."""
    from feelmysign.study.export import anonymous_labels

    shapes = store.design.shape_names
    labels = anonymous_labels(store)
    waiting = store.awaiting_review()
    choices = f"one of {', '.join(shapes)}; '-' = no shape named; Enter = leave it for later"
    print(
        f"{plural(len(waiting), 'answer')} to review, blind (the shape sent is not shown). "
        f"Type {choices}."
    )
    decided = 0
    for number, trial_id in enumerate(waiting, start=1):
        trial = store.trial(trial_id)
        item = (
            f"  [{number}/{len(waiting)}] {labels[trial['participant']]}, trial "
            f"{trial['position'] + 1}: {trial['answer']!r} -> "
        )
        while True:
            try:
                reply = input(item).strip().lower()
            except EOFError:
                print(
                    f"\nStopped: {decided} decided and stored, {len(waiting) - decided} left; "
                    "the same command goes on with them."
                )
                return 0
            if reply == "" or reply == "-" or reply in shapes:
                break
            print(f"  {reply!r} is not a choice. Type {choices}.")
        if reply == "-":
            store.decide(trial_id, None, "researcher: no shape named")
        elif reply:
            store.decide(trial_id, reply, f"researcher: {reply}")
        decided += bool(reply)
    print(f"Review done: {decided} decided, {len(waiting) - decided} left for later.")
    return 0


def _plural(count: int, noun: str) -> str:
    """ "1 stroke", "2 strokes"."""
    return f"{count} {noun}{'' if count == 1 else 's'}"
