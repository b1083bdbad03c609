"""The sleeve's events and status against the shared vectors (testdata/events)."""

from __future__ import annotations

import dataclasses
import json
from typing import Any

import pytest
from vectors import load

from feelmysign.events import (
    Adjusted,
    Cancelled,
    EventError,
    Played,
    Rejected,
    Status,
    StrokeRef,
    delivery_delay_ms,
    event_from_json,
    is_delayed,
)
from feelmysign.fates import NOTABLE_CHANGE, DrawingFates

CASES = load("events")
EVENTS = [(name, case) for name, case in CASES if name.startswith("event/")]
STATUSES = [(name, case) for name, case in CASES if name.startswith("status/")]
INVALID = [(name, case) for name, case in CASES if name.startswith("invalid/")]
DELAYS = [(name, case) for name, case in CASES if name.startswith("delay/")]


def test_every_group_has_vectors() -> None:
    assert EVENTS and STATUSES and INVALID and DELAYS


@pytest.mark.parametrize(("name", "case"), EVENTS, ids=[n for n, _ in EVENTS])
def test_event_vectors(name: str, case: dict[str, Any]) -> None:
    event = event_from_json(case["wire"])
    typed = {"type": event.kind, **event.typed()}
    if isinstance(event, Cancelled) and "by" not in case["typed"]:  # older than the field
        assert typed.pop("by") is None
    assert typed == case["typed"]
    assert event.to_json() == case["json"]
    # The text form reads back as the same event, and the class reads its own type.
    assert event_from_json(event.dumps()) == event
    assert type(event).from_json(case["json"]) == event


@pytest.mark.parametrize(("name", "case"), STATUSES, ids=[n for n, _ in STATUSES])
def test_status_vectors(name: str, case: dict[str, Any]) -> None:
    status = Status.from_json(json.dumps(case["wire"]))
    typed = dataclasses.asdict(status)
    if "floor" not in case["typed"]:  # vectors older than the floor leave it out
        assert typed.pop("floor") is None
    if "hardware" not in case["typed"]:  # nor the motors' hardware, later still
        assert typed.pop("hardware") is None
    if "controls" not in case["typed"]:  # nor the wearer's controls, later again
        assert typed.pop("controls") is None
    assert typed == case["typed"]
    assert status.to_json() == case["json"]


@pytest.mark.parametrize(("name", "case"), INVALID, ids=[n for n, _ in INVALID])
def test_invalid_vectors(name: str, case: dict[str, Any]) -> None:
    read = event_from_json if case["kind"] == "event" else Status.from_json
    with pytest.raises(EventError) as caught:
        read(case["wire"])
    assert caught.value.field == case["field"]


@pytest.mark.parametrize(("name", "case"), DELAYS, ids=[n for n, _ in DELAYS])
def test_delay_vectors(name: str, case: dict[str, Any]) -> None:
    played = Played.from_json(case["wire"])
    assert delivery_delay_ms(played) == case["delay_ms"]
    assert is_delayed(played, threshold_ms=case["delayed_ms"]) is case["delayed"]


def test_the_vectors_show_both_sides_of_the_delayed_threshold() -> None:
    # Delayed and not, with a delay exactly at the threshold among the not delayed.
    delayed = {case["delayed"] for _, case in DELAYS}
    assert delayed == {True, False}
    at = [case for _, case in DELAYS if case["delay_ms"] == case["delayed_ms"]]
    assert at and not any(case["delayed"] for case in at)


def test_a_class_reads_only_its_own_type() -> None:
    played = next(case["wire"] for name, case in EVENTS if name == "event/played")
    assert isinstance(Played.from_json(played), Played)
    with pytest.raises(EventError, match="expected a 'rejected' event"):
        Rejected.from_json(played)
    adjusted = next(case["wire"] for name, case in EVENTS if name == "event/adjusted")
    # An adjusted stroke was played too: Played reads it, Adjusted keeps what changed.
    assert isinstance(Played.from_json(adjusted), Adjusted)
    assert Adjusted.from_json(adjusted).requested_duration_ms == 120


def test_text_that_is_not_json_is_an_event_error() -> None:
    with pytest.raises(EventError, match="not JSON"):
        event_from_json("{")
    with pytest.raises(EventError, match="not JSON"):
        Status.from_json(b"\xff")


def test_cancelled_defaults_to_its_reason() -> None:
    event = Cancelled(
        message="m", stroke=StrokeRef(received_at_ms=1), cancelled_at_ms=2, started=False
    )
    assert event.to_json()["reason"] == "cancelled"


FATES = [(name, case) for name, case in CASES if name.startswith("fates/")]


@pytest.mark.parametrize(("name", "case"), FATES, ids=[n for n, _ in FATES])
def test_fate_vectors(name: str, case: dict[str, Any]) -> None:
    """What became of each stroke: the rule the page, ``up`` and the study report from."""
    fates = DrawingFates()
    for wire in case["wire"]:
        fates.add(event_from_json(wire))
    assert {str(seq): fate for seq, fate in fates.fates().items()} == case["fates"]
    assert fates.counts() == case["counts"]
    assert dict(fates.refusals()) == case["refusals"]
    assert case["notable_change"] == NOTABLE_CHANGE
    assert dataclasses.asdict(fates.catch_up()) == case["catch_up"]
    assert fates.catch_up().played_words() == case["catch_up_words"]
    # Each stroke once: the counts add up to the strokes the events name.
    assert sum(case["counts"].values()) == len(case["fates"])


def test_the_fate_vectors_cover_every_fate_and_the_copies() -> None:
    fates = {fate for _, case in FATES for fate in case["fates"].values()}
    assert fates == {"played", "cut", "cancelled", "refused"}
    originals = {
        wire.get("original_played")
        for _, case in FATES
        for wire in case["wire"]
        if wire.get("reason") == "duplicate"
    }
    assert originals == {True, False, None}
    caught_up = [case["catch_up"] for _, case in FATES]
    assert any(c["compressed"] and c["compressed_ms"] >= 1000 for c in caught_up)
    assert any(c["compressed"] and c["compressed_ms"] < 1000 for c in caught_up)
    assert any(c["slowed"] for c in caught_up)
    assert any(c["late"] for c in caught_up)


@pytest.mark.parametrize(
    "controls",
    [
        {"paused": "yes"},
        {},
        {"paused": True, "paused_by": 1},
        {"paused": False, "ceiling": 1.5},
        {"paused": False, "ceiling": -0.2},
        {"paused": False, "ceiling": True},
        {"paused": False, "ceiling": "0.6"},
        {"paused": False, "do_not_disturb_until_ms": 1.5},
        {"paused": False, "do_not_disturb_until_ms": "14:30"},
        {"paused": False, "do_not_disturb_until_ms": -1},
        [True],
    ],
)
def test_controls_of_the_wrong_type_are_refused(controls: object) -> None:
    with pytest.raises(EventError):
        Status.from_json({"online": True, "controls": controls})


def test_controls_read_from_bytes_or_text_alike_and_a_whole_float_is_a_time() -> None:
    text = json.dumps(
        {"online": True, "controls": {"paused": False, "do_not_disturb_until_ms": 1795330000000.0}}
    )
    read = Status.from_json(text).controls
    assert read == Status.from_json(text.encode()).controls
    assert read is not None and read.do_not_disturb_until_ms == 1795330000000


@pytest.mark.parametrize(("name", "case"), FATES, ids=[n for n, _ in FATES])
def test_a_study_send_summary_says_how_the_sleeve_caught_up(
    name: str, case: dict[str, Any]
) -> None:
    """The study's record of a send (its page and trials.csv) counts by the same rule."""
    from feelmysign.study.runner import events_summary

    summary = events_summary(case["wire"], len(case["fates"]))
    assert summary["played"] == case["counts"]["played"]
    assert summary["late"] == case["catch_up"]["late"] == case["refusals"].get("late", 0)
    assert summary["compressed"] == case["catch_up"]["compressed"]
    assert summary["compressed_ms"] == round(case["catch_up"]["compressed_ms"], 1)
