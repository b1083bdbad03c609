"""The wearer's choice read from the sleeve's status, on hand-written statuses as the sleeve's
contract writes them (docs/protocol.md, ``controls``), and the sentences a sender says of it."""

from __future__ import annotations

import json
import time

import pytest

from feelmysign.events import EventError
from feelmysign.wearer_status import (
    NO_CONTROLS,
    WearerControls,
    WearerHold,
    cancelled_by_wearer,
    ceiling_sentence,
    clock_time,
    controls_from_status,
    hold_sentence,
)

PAUSED_STATUS = {
    "online": True,
    "sleeve_id": "sleeve1",
    "controls": {
        "paused": True,
        "paused_by": "button",
        "ceiling": 0.6,
        "do_not_disturb_until_ms": 1795330000000,
    },
}
NOW_MS = 1795320000000


def test_the_four_fields_of_the_contract_are_read() -> None:
    assert controls_from_status(PAUSED_STATUS) == WearerControls(
        paused=True, paused_by="button", ceiling=0.6, do_not_disturb_until_ms=1795330000000
    )


def test_the_payload_as_bytes_or_text_is_read_alike() -> None:
    text = json.dumps(PAUSED_STATUS)
    assert (
        controls_from_status(text)
        == controls_from_status(text.encode())
        == (controls_from_status(PAUSED_STATUS))
    )


def test_nulls_are_unset_and_a_whole_float_is_a_time() -> None:
    status = {
        "controls": {
            "paused": False,
            "paused_by": "page",
            "ceiling": None,
            "do_not_disturb_until_ms": 1795330000000.0,
        }
    }
    read = controls_from_status(status)
    assert read == WearerControls(do_not_disturb_until_ms=1795330000000)
    assert read.paused_by is None  # who paused means nothing when not paused


@pytest.mark.parametrize("status", [{"online": True}, {"online": False}, {"controls": None}])
def test_a_status_without_controls_is_not_paused(status: dict[str, object]) -> None:
    assert controls_from_status(status) == NO_CONTROLS
    assert NO_CONTROLS.hold(NOW_MS) is None


@pytest.mark.parametrize(
    ("controls", "field"),
    [
        ({"paused": "yes"}, "controls.paused"),
        ({}, "controls.paused"),
        ({"paused": True, "paused_by": 1}, "controls.paused_by"),
        ({"paused": False, "ceiling": 1.5}, "controls.ceiling"),
        ({"paused": False, "ceiling": -0.2}, "controls.ceiling"),
        ({"paused": False, "ceiling": True}, "controls.ceiling"),
        ({"paused": False, "ceiling": "0.6"}, "controls.ceiling"),
        ({"paused": False, "do_not_disturb_until_ms": 1.5}, "controls.do_not_disturb_until_ms"),
        ({"paused": False, "do_not_disturb_until_ms": "14:30"}, "controls.do_not_disturb_until_ms"),
        ({"paused": False, "do_not_disturb_until_ms": -1}, "controls.do_not_disturb_until_ms"),
        ([True], "controls"),
    ],
)
def test_a_field_of_the_wrong_type_is_refused_naming_it(controls: object, field: str) -> None:
    with pytest.raises(EventError) as raised:
        controls_from_status({"online": True, "controls": controls})
    assert raised.value.field == field
    assert field in str(raised.value)


def test_a_status_that_is_not_a_json_object_is_refused() -> None:
    for payload in (b"{not json", b"[1]", "true"):
        with pytest.raises(EventError):
            controls_from_status(payload)


def test_paused_holds_and_wins_over_do_not_disturb() -> None:
    controls = WearerControls(paused=True, do_not_disturb_until_ms=NOW_MS + 60_000)
    assert controls.hold(NOW_MS) == WearerHold("paused")


def test_do_not_disturb_holds_until_its_time_and_not_after() -> None:
    controls = WearerControls(do_not_disturb_until_ms=NOW_MS + 60_000)
    assert controls.hold(NOW_MS) == WearerHold("do_not_disturb", NOW_MS + 60_000)
    assert controls.hold(NOW_MS + 60_000) is None


def test_a_ceiling_alone_holds_nothing() -> None:
    assert WearerControls(ceiling=0.3).hold(NOW_MS) is None


def test_the_sentences_say_what_holds_until_when_and_what_to_do() -> None:
    paused = hold_sentence(WearerHold("paused"), "sleeve1")
    assert paused.startswith("The wearer paused sleeve 'sleeve1'")
    assert "Nothing was sent" in paused and "resumed" in paused
    until_ms = NOW_MS + 3_600_000
    expected = time.strftime("%H:%M", time.localtime(until_ms / 1000))
    assert clock_time(until_ms) == expected
    dnd = hold_sentence(WearerHold("do_not_disturb", until_ms), "sleeve1")
    assert f"asked not to be disturbed until {expected}" in dnd
    assert f"send again after {expected}" in dnd


def test_the_ceiling_sentence_counts_the_strokes_it_caps() -> None:
    assert ceiling_sentence(0.6, [0.8, 0.5, 0.7]) == (
        "The wearer set a ceiling of 60 % (intensity 0.6): it caps every stroke's intensity; "
        "2 of the 3 strokes ask for more and play at 0.6."
    )
    assert "every stroke asks for no more than that" in ceiling_sentence(0.6, [0.5])


def test_a_cancel_by_the_wearer_is_told_from_a_sender_s() -> None:
    event = {"type": "cancelled", "reason": "cancelled", "started": True}
    assert cancelled_by_wearer(json.dumps({**event, "by": "wearer"}))
    assert not cancelled_by_wearer(json.dumps(event))
    assert not cancelled_by_wearer(b"{not json")
    assert not cancelled_by_wearer(json.dumps({"type": "rejected", "by": "wearer"}))
