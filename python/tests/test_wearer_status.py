"""What a sender does with the wearer's choice read from the sleeve's status
(``Status.controls``, docs/protocol.md): what holds a drawing, and the sentences it says."""

from __future__ import annotations

import time

from feelmysign.events import StatusControls
from feelmysign.wearer_status import (
    WearerHold,
    ceiling_sentence,
    clock_time,
    hold_sentence,
    wearer_hold,
)

NOW_MS = 1795320000000


def test_paused_holds_and_wins_over_do_not_disturb() -> None:
    controls = StatusControls(paused=True, do_not_disturb_until_ms=NOW_MS + 60_000)
    assert wearer_hold(controls, NOW_MS) == WearerHold("paused")


def test_do_not_disturb_holds_until_its_time_and_not_after() -> None:
    controls = StatusControls(do_not_disturb_until_ms=NOW_MS + 60_000)
    assert wearer_hold(controls, NOW_MS) == WearerHold("do_not_disturb", NOW_MS + 60_000)
    assert wearer_hold(controls, NOW_MS + 60_000) is None


def test_a_ceiling_alone_holds_nothing() -> None:
    assert wearer_hold(StatusControls(ceiling=0.3), NOW_MS) is None


def test_a_status_without_controls_holds_nothing() -> None:
    assert wearer_hold(None, NOW_MS) is None


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
