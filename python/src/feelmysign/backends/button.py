"""The wearer's buttons: a pause button and, optionally, a "turn down" button, on GPIO lines.

Each button sits between its line and ground; the line is pulled up (the Pi's own
pull-up, asked for here), so it reads low while the button is pressed: a line
requested *active low* reads "active" when pressed. Wiring: docs/sleeve-hardware.md.

- **pause button**: a press while the sleeve plays pauses it at once (every motor off
  within the player's next pass, the strokes waiting and arriving refused ``paused``);
  a short press while paused resumes it; a press held ``LONG_PRESS_MS`` (1 s) stops the
  drawing under way (the wearer's stop) and leaves the pause as it was before the press,
  so a long press never pauses nor resumes the sleeve by itself.
- **turn-down button**: each press lowers the wearer's intensity ceiling by
  ``TURN_DOWN_STEP`` (from the layout's max_intensity when there is none), never below
  ``MIN_CEILING``; raising it again is for the wearer's page (a button held by accident
  never makes the sleeve stronger).

Presses are debounced and told short from long by :mod:`feelmysign.sleeve.presses`. The
real line is read through libgpiod v2 (``gpiod``, as the enable line); the emulated bus
has its own button (:mod:`feelmysign.backends.emulated_button`), with the same methods.
A line that cannot be had stops the sleeve at start with what to check: the wearer's
control must never be silently absent.
"""

from __future__ import annotations

import logging
import threading
import time
from datetime import timedelta
from typing import TYPE_CHECKING, Any, Protocol

from feelmysign.backends.enable import CONSUMER, import_gpiod, line_error
from feelmysign.errors import HardwareError
from feelmysign.sleeve.controls import MIN_CEILING, WearerControls
from feelmysign.sleeve.presses import LONG_PRESS_MS, Press, Presses

if TYPE_CHECKING:
    from feelmysign.layout import ButtonLine

log = logging.getLogger(__name__)

TURN_DOWN_STEP = 0.1  # ten presses from full drive to the least; each one clearly felt
IDLE_WAIT_S = 1.0  # nothing pending: wake now and then to see whether to stop
BY = "button"
# What the log says of each press (presses.Press).
PRESS_WORDS: dict[Press, str] = {
    "press": "pressed",
    "short": "let go (a short press)",
    "long": f"held {LONG_PRESS_MS / 1000:g} s (a long press)",
}


class ButtonInput(Protocol):
    """What the watcher needs of a button's line."""

    @property
    def description(self) -> str: ...

    def request(self) -> None:
        """Take the line as an input; HardwareError (what to check) when it cannot be had."""

    def pressed(self) -> bool:
        """Whether the button is down now."""
        ...

    def edges(self, timeout_s: float) -> list[tuple[bool, float]]:
        """The changes since the last call, in order, each (pressed, when: monotonic ms),
        waiting up to ``timeout_s`` for one. A press shorter than the thread takes to wake is
        two edges, never lost."""
        ...

    def close(self) -> None:
        """Let the line go; idempotent."""


class GpiodButton:
    """A button on a real GPIO line, through libgpiod v2, pulled up and read active low."""

    def __init__(self, button: ButtonLine) -> None:
        self._button = button
        self._request: Any = None
        self._active: Any = None
        self._rising: Any = None

    @property
    def description(self) -> str:
        return f"{self._button.role.replace('_', '-')} button ({self._button.name})"

    def request(self) -> None:
        if self._request is not None:
            return
        gpiod = import_gpiod(self._button.key)
        self._active = gpiod.line.Value.ACTIVE
        self._rising = gpiod.EdgeEvent.Type.RISING_EDGE
        settings = gpiod.LineSettings(
            direction=gpiod.line.Direction.INPUT,
            edge_detection=gpiod.line.Edge.BOTH,
            bias=gpiod.line.Bias.PULL_UP,
            active_low=True,
        )
        try:
            self._request = gpiod.request_lines(
                self._button.path, consumer=CONSUMER, config={self._button.line: settings}
            )
        except (OSError, ValueError) as error:
            what = f"the wearer's {self._button.role.replace('_', '-')} button"
            raise HardwareError(line_error(self._button, error, self._button.key, what)) from error

    def pressed(self) -> bool:
        return bool(self._request.get_value(self._button.line) == self._active)

    def edges(self, timeout_s: float) -> list[tuple[bool, float]]:
        if not self._request.wait_edge_events(timedelta(seconds=timeout_s)):
            return []
        # Active low: the kernel reports a press (the line falling) as a rising edge. Its
        # timestamps are CLOCK_MONOTONIC, as time.monotonic.
        return [
            (event.event_type == self._rising, event.timestamp_ns / 1e6)
            for event in self._request.read_edge_events()
        ]

    def close(self) -> None:
        request, self._request = self._request, None
        if request is not None:
            request.release()


class ButtonWatcher:
    """One thread per button: its presses become the wearer's controls."""

    def __init__(self, line: ButtonInput, role: str, controls: WearerControls) -> None:
        self._line = line
        self._role = role
        self._controls = controls
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        # The pause button: whether the press now down paused the sleeve (a long press then
        # undoes that pause, as a long press is a stop and not a pause).
        self._paused_by_this_press = False
        self._max_intensity = controls.max_intensity
        self._presses = Presses()

    def start(self) -> None:
        self._line.request()  # HardwareError here, at start, before the sleeve plays
        # Before the thread: every edge from now on counts.
        self._presses = Presses(pressed=self._line.pressed(), now_ms=_now_ms())
        self._thread = threading.Thread(
            target=self._run, name=f"feelmysign-{self._role}-button", daemon=True
        )
        self._thread.start()

    def stop(self) -> None:
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(timeout=2 * IDLE_WAIT_S)
        self._line.close()

    def _run(self) -> None:
        presses = self._presses
        while not self._stopping.is_set():
            due_ms = presses.next_ms()
            wait_s = IDLE_WAIT_S if due_ms is None else max(0.0, (due_ms - _now_ms()) / 1000)
            try:
                found: list[Press] = []
                for pressed, at_ms in self._line.edges(min(wait_s, IDLE_WAIT_S)):
                    found += presses.level(pressed, at_ms)
                found += presses.tick(_now_ms())
            except (OSError, HardwareError) as error:
                log.error("the wearer's %s cannot be read: %s", self._line.description, error)
                self._stopping.wait(IDLE_WAIT_S)
                continue
            for press in found:
                self._act(press)

    def _act(self, press: Press) -> None:
        log.info("the wearer's %s: %s", self._line.description, PRESS_WORDS[press])
        try:
            if self._role == "pause":
                self._pause_button(press)
            elif press == "press":
                self._turn_down()
        except Exception:  # the button's thread must go on whatever one press did
            log.exception("the wearer's %s: %s", self._line.description, press)

    def _pause_button(self, press: Press) -> None:
        controls = self._controls
        if press == "press":
            self._paused_by_this_press = not controls.state().paused
            if self._paused_by_this_press:
                controls.pause(BY)  # at once: the motors must not wait to know how long it is
        elif press == "short":
            if not self._paused_by_this_press:
                controls.resume(BY)
        elif press == "long":
            controls.stop(BY)
            if self._paused_by_this_press:
                controls.resume(BY)

    def _turn_down(self) -> None:
        current = self._controls.state().ceiling
        start = self._max_intensity if current is None else current
        lowered = max(MIN_CEILING, round(start - TURN_DOWN_STEP, 4))
        self._controls.set_ceiling(min(lowered, self._max_intensity), BY)


def _now_ms() -> float:
    return time.monotonic() * 1000.0
