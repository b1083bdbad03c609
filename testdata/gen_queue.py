"""Vectors for the sleeve's queue (feelmysign.sleeve.queue): when each stroke starts, and
how long it plays once the sleeve catches up.

``<name>.json``: ``floor_ms``, the sleeve's floor (the paper sleeve's: the shortest
stroke it plays without slowing it, down to which a stroke behind its drawing is
played faster); ``steps``, in the order they reach the sleeve (times never
decrease), each a stroke ``{"arrival_ms", "duration_ms"}`` (with ``drawing``
and ``seq`` when it has them) or a cancel ``{"cancel": drawing or "*",
"at_ms"}``; and ``outcomes``, one per stroke in order: ``{"outcome"}`` (one of
``played``, ``cut``, ``cancelled``, ``held``, ``duplicate``) with ``start_ms``
and ``played_ms`` for a stroke that started (``played_ms`` is less than its
duration when a cancel cut it, or when it played faster to catch up).

Each case names the outcomes it is meant to show; generation stops if the
reference disagrees.
"""

from __future__ import annotations

from typing import Any

from feelmysign.apparent_motion import shortest_planned_ms
from feelmysign.layout import Layout
from feelmysign.sleeve.queue import Arrival, CancelAt, Outcome, replay

# The paper sleeve's floor (73.701 ms for its 20 ms bursts).
FLOOR_MS = shortest_planned_ms(Layout(rows=3, columns=4, spacing_cm=3.0).shortest_burst_ms)
F = FLOOR_MS

Step = dict[str, Any]


def s(
    arrival_ms: float, duration_ms: float, drawing: str | None = None, seq: int | None = None
) -> Step:
    step: Step = {"arrival_ms": arrival_ms, "duration_ms": duration_ms}
    if drawing is not None:
        step["drawing"] = drawing
    if seq is not None:
        step["seq"] = seq
    return step


def c(at_ms: float, drawing: str = "*") -> Step:
    return {"cancel": drawing, "at_ms": at_ms}


def played(start_ms: float, played_ms: float) -> Outcome:
    return Outcome("played", start_ms, played_ms)


def cut(start_ms: float, played_ms: float) -> Outcome:
    return Outcome("cut", start_ms, played_ms)


CANCELLED = Outcome("cancelled")
HELD = Outcome("held")
DUPLICATE = Outcome("duplicate")

CASES: dict[str, tuple[str, list[Step], list[Outcome]]] = {
    "idle": ("a stroke to an idle sleeve starts when it arrives", [s(40, 300)], [played(40, 300)]),
    "back-to-back": (
        "strokes sent faster than they play start as the one before ends, caught up to the floor",
        [s(0, 300, "d1", 0), s(10, 300, "d1", 1), s(20, 250.5, "d1", 2)],
        [played(0, 300), played(300, F), played(300 + F, F)],
    ),
    "gaps": (
        "a stroke after a pause starts when it arrives; one in the middle of a stroke waits, "
        "caught up (50 ms behind) but not below the floor",
        [s(0, 100, "d1", 0), s(500, 100, "d1", 1), s(550, 100, "d1", 2)],
        [played(0, 100), played(500, 100), played(600, F)],
    ),
    "touching": (
        "a stroke arriving as the one before ends starts then",
        [s(0, 200, "d1", 0), s(200, 200, "d1", 1)],
        [played(0, 200), played(200, 200)],
    ),
    "drawings-share-the-queue": (
        "strokes of two drawings play in the order they arrive, one queue",
        [s(0, 300, "a", 0), s(50, 300, "b", 0), s(100, 300, "a", 1)],
        [played(0, 300), played(300, 300), played(600, 300)],
    ),
    "no-drawing": (
        "strokes without drawing and seq (the legacy format) are never duplicates",
        [s(0, 100), s(10, 100)],
        [played(0, 100), played(100, 100)],
    ),
    "seq-gap": (
        "a gap in the seqs never waits for the missing one",
        [s(0, 100, "d1", 0), s(20, 100, "d1", 3)],
        [played(0, 100), played(100, F)],
    ),
    "out-of-order": (
        "a seq that comes after later ones still plays, in the order it arrives",
        [s(0, 300, "d1", 0), s(10, 300, "d1", 2), s(20, 300, "d1", 1)],
        [played(0, 300), played(300, F), played(300 + F, F)],
    ),
    "redelivery-waiting": (
        "a copy of a stroke still waiting to play is held, and queues nothing",
        [s(0, 300, "d1", 0), s(10, 300, "d1", 1), s(20, 300, "d1", 1), s(30, 300, "d1", 2)],
        [played(0, 300), played(300, F), HELD, played(300 + F, F)],
    ),
    "redelivery-played": (
        "a copy of a stroke that started is a duplicate, and queues nothing",
        [s(0, 300, "d1", 0), s(100, 300, "d1", 0), s(400, 300, "d1", 0), s(500, 100, "d1", 1)],
        [played(0, 300), DUPLICATE, DUPLICATE, played(500, 100)],
    ),
    "redelivery-other-drawing": (
        "the same seq in another drawing is another stroke",
        [s(0, 100, "a", 0), s(10, 100, "b", 0)],
        [played(0, 100), played(100, 100)],
    ),
    "cancel-mid-queue": (
        "a cancel cuts the stroke playing and drops those waiting; the queue then starts afresh",
        [
            s(0, 200, "d1", 0),
            s(10, 200, "d1", 1),
            s(20, 200, "d1", 2),
            s(30, 200, "d1", 3),
            c(250, "d1"),
            s(300, 200, "d2", 0),
        ],
        [played(0, 200), cut(200, 50), CANCELLED, CANCELLED, played(300, 200)],
    ),
    "cancel-refuses-later": (
        "strokes of a cancelled drawing that come later are cancelled, copies too",
        [s(0, 200, "d1", 0), c(50, "d1"), s(60, 200, "d1", 1), s(70, 200, "d1", 0)],
        [cut(0, 50), CANCELLED, CANCELLED],
    ),
    "cancel-one-drawing": (
        "a cancel of one drawing leaves the others where they were planned; the next stroke "
        "of one behind its drawing catches up",
        [
            s(0, 200, "a", 0),
            s(10, 200, "b", 0),
            s(20, 200, "a", 1),
            c(100, "a"),
            s(150, 200, "b", 1),
        ],
        [cut(0, 100), played(200, 200), CANCELLED, played(400, F)],
    ),
    "cancel-everything": (
        "a cancel of everything drops every drawing's strokes; new strokes still play",
        [
            s(0, 200, "a", 0),
            s(10, 200, "b", 0),
            c(300, "*"),
            s(310, 100, "a", 1),
            s(320, 100, "b", 0),
        ],
        [played(0, 200), cut(200, 100), played(310, 100), DUPLICATE],
    ),
    "cancel-between-strokes": (
        "a cancel when nothing plays changes no start",
        [s(0, 100, "d1", 0), c(500, "d2"), s(600, 100, "d1", 1)],
        [played(0, 100), played(600, 100)],
    ),
    "cancel-then-redelivery": (
        "a copy of a stroke dropped by a cancel of everything is a duplicate",
        [s(0, 100, "d1", 0), s(10, 100, "d1", 1), c(50, "*"), s(60, 100, "d1", 1)],
        [cut(0, 50), CANCELLED, DUPLICATE],
    ),
    "catch-up": (
        "a stroke behind its drawing plays shorter by as much as the sleeve is behind; one "
        "that arrives when the sleeve has caught up plays as it came",
        [s(0, 300, "d1", 0), s(200, 300, "d1", 1), s(600, 300, "d1", 2)],
        [played(0, 300), played(300, 200), played(600, 300)],
    ),
    "catch-up-floor": (
        "catching up stops at the floor; a stroke at or below the floor is never lengthened",
        [s(0, 300, "d1", 0), s(10, 300, "d1", 1), s(20, 50, "d1", 2), s(30, 73, "d1", 3)],
        [played(0, 300), played(300, F), played(300 + F, 50), played(350 + F, 73)],
    ),
    "catch-up-other-drawing": (
        "a stroke waiting behind another drawing plays as it came; the next of its own "
        "drawing, behind it, catches up",
        [s(0, 300, "a", 0), s(100, 300, "b", 0), s(200, 300, "b", 1)],
        [played(0, 300), played(300, 300), played(600, F)],
    ),
    "catch-up-after-cancel": (
        "after a cancel the tail is the latest stroke still planned, and its drawing: a stroke "
        "of that drawing catches up, and after a cancel of everything nothing is behind",
        [
            s(0, 300, "a", 0),
            s(10, 300, "b", 0),
            s(20, 300, "a", 1),
            c(100, "a"),
            s(150, 300, "b", 1),
            c(620, "*"),
            s(630, 300, "b", 2),
        ],
        [cut(0, 100), played(300, 300), CANCELLED, cut(600, 20), played(630, 300)],
    ),
    "catch-up-legacy": (
        "strokes without a drawing (the legacy format) are never caught up",
        [s(0, 300), s(10, 300), s(20, 300)],
        [played(0, 300), played(300, 300), played(600, 300)],
    ),
}


def _steps(steps: list[Step]) -> list[Arrival | CancelAt]:
    out: list[Arrival | CancelAt] = []
    for step in steps:
        if "cancel" in step:
            out.append(CancelAt(step["at_ms"], None if step["cancel"] == "*" else step["cancel"]))
        else:
            out.append(
                Arrival(
                    step["arrival_ms"], step["duration_ms"], step.get("drawing"), step.get("seq")
                )
            )
    return out


def _outcome(outcome: Outcome) -> dict[str, Any]:
    data: dict[str, Any] = {"outcome": outcome.outcome}
    if outcome.start_ms is not None:
        data["start_ms"] = outcome.start_ms
        data["played_ms"] = outcome.played_ms
    return data


def cases() -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name, (description, steps, expected) in CASES.items():
        outcomes = replay(_steps(steps), FLOOR_MS)
        assert outcomes == expected, (name, outcomes)
        out[f"{name}.json"] = {
            "description": description,
            "floor_ms": FLOOR_MS,
            "steps": steps,
            "outcomes": [_outcome(o) for o in outcomes],
        }
    return out
