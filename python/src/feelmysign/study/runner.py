"""One participant's session, step by step, as section 6.1 describes it; shared by the
researcher's page (``api``) and the terminal (``feelmysign study run``).

Steps: consent -> comfort check -> trials (practice, then the measured ones)
-> questionnaire -> done. The step is always computed from the study file,
never kept in memory, so after a crash or a restart the session continues
exactly where the last stored answer left it. ``Play`` sends a trial's strokes
to the sleeve and returns the sleeve's events (``SleeveLink.play``, or the
offline ``simulated_sleeve.play_offline`` for dry runs without a sleeve).
"""

from __future__ import annotations

import functools
import json
import sqlite3
import threading
import uuid
from collections.abc import Callable
from typing import Any

from feelmysign.errors import FeelMySignError, StudyError
from feelmysign.events import Adjusted, Event, EventError, Played, event_from_json
from feelmysign.fates import DrawingFates
from feelmysign.layout import Layout
from feelmysign.schedule import stroke_to_json
from feelmysign.stroke import Point, Stroke
from feelmysign.study.coding import code_answer
from feelmysign.study.stimulus import stimulus_layout, trial_strokes
from feelmysign.study.store import StudyStore

Play = Callable[[list[Stroke]], list[dict[str, Any]]]
MAX_ANSWER_CHARS = 200
CONFIDENCE_POINTS = 5


def stroke_from_json(data: dict[str, Any]) -> Stroke:
    return Stroke(
        start=(float(data["start"][0]), float(data["start"][1])),
        end=(float(data["end"][0]), float(data["end"][1])),
        duration_ms=float(data["duration_ms"]),
        intensity=data.get("intensity"),
        drawing=data.get("drawing"),
        seq=data.get("seq"),
    )


def sleeve_events(events: list[dict[str, Any]]) -> list[Event]:
    """The sleeve's events among ``events`` (as stored); anything else is left out."""
    typed: list[Event] = []
    for data in events:
        try:
            typed.append(event_from_json(data))
        except EventError:
            continue  # not a sleeve event: nothing in the summary counts it
    return typed


def events_summary(events: list[dict[str, Any]], strokes: int) -> dict[str, Any]:
    """What became of a send's strokes, by the rule the page and ``up`` report from
    (:mod:`feelmysign.fates`): each stroke once, under one fate."""
    typed = sleeve_events(events)
    played = [e for e in typed if isinstance(e, Played)]  # adjusted ones were played too
    fates = DrawingFates()
    for event in typed:
        fates.add(event)
    counts = fates.counts()
    catch_up = fates.catch_up()
    return {
        "strokes": strokes,
        "played": counts["played"],
        "cut_short": counts["cut"],
        "cancelled": counts["cancelled"],
        "adjusted": sum(1 for e in typed if isinstance(e, Adjusted)),
        "rejected": list(fates.refusals().elements()),
        # How the sleeve kept the send in time (docs/protocol.md, "Catching up"): strokes
        # skipped as late (also among the rejected), and played faster to catch up.
        "late": catch_up.late,
        "compressed": catch_up.compressed,
        "compressed_ms": round(catch_up.compressed_ms, 1),
        "latency_ms_max": round(max(e.latency_ms for e in played), 3) if played else None,
        "felt_duration_ms": round(sum(float(e.duration_ms) for e in played), 1),
    }


class Session:
    """``Session(store, play)``: the operations on one study's participants."""

    def __init__(
        self,
        store: StudyStore,
        play: Play | None,
        *,
        simulation_seed: int = 0,
        wearer: str = "template",
        dry_run: bool = False,
    ) -> None:
        self.store = store
        self._play = play
        self.layout: Layout = stimulus_layout(store.design.stimulus, store.base_dir)
        self._simulation_seed = simulation_seed
        self._wearer = wearer  # how simulated participants answer (simulated.WEARERS)
        # Trials whose shape the sleeve is playing now (a send, or a repeat send, under way):
        # their answer waits until it has played. Kept in memory: after a restart nothing
        # plays, and the trial is sent again.
        self._playing: set[int] = set()
        self._playing_lock = threading.Lock()
        # A runner that sends to a sleeve (the page's server, the terminal): its start is
        # kept, so that an answer's time is counted within one run of it (export.trial_rows).
        if play is not None and not dry_run:
            store.note_runner_start()

    @functools.cached_property
    def _templates(self) -> dict[str, list[Point]]:
        """The shapes' outlines a simulated participant compares with: made when one first
        answers, since they import numpy and plan every shape (seconds on a Pi) and a
        study with real participants only never needs them."""
        from feelmysign.study.simulated import templates

        return templates(self.store.design, self.layout, self.store.base_dir)

    @property
    def player(self) -> Play | None:
        """What plays strokes on the sleeve (None: no sleeve connected)."""
        return self._play

    # ---- what the page shows -----------------------------------------------------------

    def step(self, code: str) -> str:
        row = self.store.participant(code)
        if row["withdrawn"]:
            return "withdrawn"
        if row["consent"] != 1:
            return "consent"
        if row["comfort_json"] is None:
            return "comfort"
        if self.store.current_trial(code) is not None:
            return "trial"
        if not self.store.questionnaire(code):
            return "questionnaire"
        return "done"

    def state(self, code: str) -> dict[str, Any]:
        row = self.store.participant(code)
        trials = self.store.trials(row["code"])
        answered = sum(1 for t in trials if t["answered_at_ms"] is not None)
        current = self.store.current_trial(row["code"])
        return {
            "participant": row["code"],
            "simulated": bool(row["simulated"]),
            "step": self.step(row["code"]),
            "paused": bool(row["paused"]),
            "answered": answered,
            "total": len(trials),
            "trial": None if current is None else self._trial_state(current, len(trials)),
        }

    def _trial_state(self, trial: sqlite3.Row, total: int) -> dict[str, Any]:
        design = self.store.design
        sends = self.store.sends(trial["id"])
        last = None
        if sends:
            events = [json.loads(e["json"]) for e in self.store.events(sends[-1]["id"])]
            strokes = len(json.loads(sends[-1]["strokes_json"]))
            last = {**events_summary(events, strokes), "error": sends[-1]["error"]}
        level = trial["level"]
        return {
            "id": trial["id"],
            "number": trial["position"] + 1,
            "total": total,
            "block": trial["block"],
            "repetition": trial["repetition"],
            "shape": trial["shape"],
            "resolution": None if level is None else design.resolutions[level],
            "segments": trial["segments"],
            # cm/s the shape is drawn at; None: a recorded drawing at its own timing
            "speed_cm_s": trial["speed_cm_s"],
            "sends": len(sends),
            "last_send": last,
        }

    # ---- the steps ---------------------------------------------------------------------

    def consent(self, code: str, given: bool) -> None:
        self.store.set_consent(code, given)

    def comfort(self, code: str, answers: list[bool], adjusted: bool) -> None:
        self.store.record_comfort(code, answers, adjusted)

    def _current(self, code: str, trial_id: int | None) -> sqlite3.Row:
        row = self.store.participant(code)
        if row["paused"]:
            raise StudyError(f"the session of {row['code']} is paused; resume it first")
        if self.step(row["code"]) != "trial":
            raise StudyError(f"{row['code']} is at the {self.step(row['code'])} step, not a trial")
        current = self.store.current_trial(row["code"])
        assert current is not None
        if trial_id is not None and current["id"] != trial_id:
            raise StudyError(
                f"trial {trial_id} is not the current one ({current['id']}): the page is out of "
                "date; reload it"
            )
        return current

    def strokes_of(self, trial: sqlite3.Row, drawing: str) -> list[Stroke]:
        return trial_strokes(
            self.store.design,
            self.store.base_dir,
            trial["shape"],
            level=trial["level"],
            segments=trial["segments"],
            drawing=drawing,
            layout=self.layout,
            speed_cm_s=trial["speed_cm_s"],
        )

    def send(self, code: str, trial_id: int | None = None) -> dict[str, Any]:
        """Send the current trial's shape; its events are stored with the trial."""
        if self._play is None:
            raise StudyError("no sleeve is connected to this runner; start it with a broker")
        trial = self._current(code, trial_id)
        drawing = str(uuid.uuid4())
        strokes = self.strokes_of(trial, drawing)
        with self._playing_lock:
            if trial["id"] in self._playing:
                raise StudyError(
                    "the sleeve is still playing this trial's shape; wait until it has played, "
                    "then send again"
                )
            self._playing.add(trial["id"])
        try:
            send_id = self.store.record_send(
                trial["id"], drawing, [stroke_to_json(s) for s in strokes]
            )
            try:
                events = self._play(strokes)
            except FeelMySignError as error:
                self.store.record_send_error(send_id, str(error))
                raise
            self.store.record_events(send_id, events)
        finally:
            with self._playing_lock:
                self._playing.discard(trial["id"])
        return events_summary(events, len(strokes))

    def answer(
        self,
        code: str,
        trial_id: int | None,
        *,
        answer: str,
        felt_nothing: bool,
        confidence: int | None,
    ) -> dict[str, Any]:
        trial = self._current(code, trial_id)
        if not self.store.sends(trial["id"]):
            raise StudyError("send the shape to the sleeve before recording an answer")
        with self._playing_lock:
            if trial["id"] in self._playing:
                raise StudyError(
                    "the sleeve is still playing the shape (sent again); record the answer "
                    "when it has played, so that it answers what was felt"
                )
        text = answer.strip()
        if len(text) > MAX_ANSWER_CHARS:
            raise StudyError(f"an answer is at most {MAX_ANSWER_CHARS} characters")
        if not text and not felt_nothing:
            raise StudyError("type the answer, or choose 'felt nothing'")
        if felt_nothing and confidence is not None:
            raise StudyError(
                "'felt nothing' takes no confidence: record it without one, or record the "
                "answer the participant gave with its confidence"
            )
        if confidence is not None and not 1 <= confidence <= CONFIDENCE_POINTS:
            raise StudyError(f"confidence is 1 to {CONFIDENCE_POINTS}, or none")
        synonyms = [(s.name, s.synonyms) for s in self.store.design.shapes]
        coding = code_answer(text, felt_nothing, synonyms)
        self.store.record_answer(
            trial["id"],
            answer=text,
            felt_nothing=felt_nothing,
            confidence=confidence,
            coding=(coding.status, coding.shape, coding.rule),
        )
        return {"status": coding.status, "shape": coding.shape, "rule": coding.rule}

    def pause(self, code: str, paused: bool) -> None:
        self.store.set_paused(code, paused)

    def questionnaire(self, code: str, values: list[int]) -> None:
        if self.step(code) != "questionnaire":
            raise StudyError(f"{code} is at the {self.step(code)} step, not the questionnaire")
        self.store.record_questionnaire(code, values)

    # ---- dry runs ----------------------------------------------------------------------

    def simulated_answer(self, code: str) -> dict[str, Any]:
        """What the simulated participant answers to the current trial (as last sent)."""
        row = self.store.participant(code)
        if not row["simulated"]:
            raise StudyError(
                f"{row['code']} is a real participant; only simulated ones answer here"
            )
        trial = self._current(row["code"], None)
        sends = self.store.sends(trial["id"])
        if not sends:
            raise StudyError("send the shape first: the simulated participant answers what it felt")
        strokes = [stroke_from_json(s) for s in json.loads(sends[-1]["strokes_json"])]
        from feelmysign.study.simulated import (
            IN_RANGE,
            InRangeWearer,
            SimulatedParticipant,
            in_range_truths,
        )

        # The participant's number and the trial's position, not their random code and row
        # id: the same seed then gives the same answers in every new study file.
        seed = self._simulation_seed + int(row["number"])
        key = f"{row['number']}:{trial['position']}"
        design = self.store.design
        if self._wearer == IN_RANGE:
            result = InRangeWearer(seed, in_range_truths(design)).answer(
                strokes,
                self.layout,
                design,
                self._templates,
                key,
                sent=str(trial["shape"]),
                segments=int(trial["segments"]),
            )
        else:
            participant = SimulatedParticipant(seed=seed)
            result = participant.answer(strokes, self.layout, design, self._templates, key)
        return {
            "answer": result.answer,
            "felt_nothing": result.felt_nothing,
            "confidence": result.confidence,
        }
