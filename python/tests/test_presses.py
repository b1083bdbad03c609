"""A button's presses: debounced at once, short told from long (feelmysign.sleeve.presses)."""

from __future__ import annotations

from feelmysign.sleeve.presses import DEBOUNCE_MS, LONG_PRESS_MS, Presses


def test_a_press_counts_at_its_first_edge_and_the_bounce_after_it_is_ignored() -> None:
    presses = Presses(now_ms=0.0)
    assert presses.level(True, 100.0) == ["press"]
    # The contact bounces: open, closed, open again within the debounce window.
    assert presses.level(False, 101.0) == []
    assert presses.level(True, 102.5) == []
    assert presses.down
    assert presses.level(False, 250.0) == ["short"]


def test_a_let_go_inside_the_bounce_window_is_taken_when_the_window_closes() -> None:
    presses = Presses(now_ms=0.0)
    assert presses.level(True, 100.0) == ["press"]
    assert presses.level(False, 105.0) == []  # a very quick tap
    assert presses.next_ms() == 100.0 + DEBOUNCE_MS
    assert presses.tick(100.0 + DEBOUNCE_MS) == ["short"]
    assert presses.next_ms() is None


def test_a_long_press_is_said_once_while_held_and_its_let_go_says_nothing() -> None:
    presses = Presses(now_ms=0.0)
    presses.level(True, 100.0)
    assert presses.next_ms() == 100.0 + LONG_PRESS_MS
    assert presses.tick(100.0 + LONG_PRESS_MS - 1) == []
    assert presses.tick(100.0 + LONG_PRESS_MS) == ["long"]
    assert presses.tick(100.0 + 3 * LONG_PRESS_MS) == []
    assert presses.level(False, 100.0 + 3 * LONG_PRESS_MS) == []
    assert presses.level(True, 5000.0) == ["press"]  # and the next press is a new one


def test_a_button_held_at_start_does_nothing_until_pressed_again() -> None:
    presses = Presses(pressed=True, now_ms=0.0)
    assert presses.tick(5000.0) == []
    assert presses.level(False, 5000.0) == []
    assert presses.level(True, 6000.0) == ["press"]
