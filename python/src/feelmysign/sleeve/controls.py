"""The wearer's controls: pause, stop, an intensity ceiling and "do not disturb".

Placeholder with the interface of the wearer-controls contract (section 1), so that the
wearer's page and its HTTP API (``feelmysign.wearer_api``) can be built and tested against
it. The sleeve's own version replaces this module: it also refuses strokes while paused,
switches the motors off, caps every stroke and republishes the retained status. This one
only keeps the state (in memory, and in ``state_path`` when given) and tells subscribers.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from feelmysign.errors import FeelMySignError

MIN_CEILING = 0.05
MAX_DO_NOT_DISTURB_MS = 24 * 60 * 60 * 1000
CONTROLLERS = ("button", "page", "cli")


@dataclass(frozen=True)
class ControlsState:
    paused: bool
    paused_by: str | None  # "button" | "page" | "cli"; None when not paused
    ceiling: float | None  # the wearer's intensity ceiling; None = none
    do_not_disturb_until_ms: int | None  # wall clock, ms since 1970; None = off (or passed)

    def to_json(self) -> dict[str, Any]:
        return {
            "paused": self.paused,
            "paused_by": self.paused_by,
            "ceiling": self.ceiling,
            "do_not_disturb_until_ms": self.do_not_disturb_until_ms,
        }


class ControlsError(FeelMySignError):
    """A control the wearer cannot set: the message says what, the allowed range, what to do."""


class WearerControls:
    """The wearer's choices; every change is saved (with ``state_path``) before it returns."""

    def __init__(
        self,
        max_intensity: float,
        state_path: Path | None = None,
        on_stop: Callable[[], None] | None = None,
    ) -> None:
        self._max_intensity = max_intensity
        self._path = state_path
        self._on_stop = on_stop
        self._lock = threading.Lock()
        self._subscribers: list[Callable[[ControlsState], None]] = []
        self._state = ControlsState(False, None, None, None)
        if state_path is not None and state_path.is_file():
            data = json.loads(state_path.read_text(encoding="utf-8"))
            self._state = ControlsState(
                bool(data["paused"]),
                data["paused_by"],
                data["ceiling"],
                data["do_not_disturb_until_ms"],
            )

    def state(self) -> ControlsState:
        with self._lock:
            until = self._state.do_not_disturb_until_ms
            if until is not None and until <= time.time() * 1000:
                self._state = ControlsState(
                    self._state.paused, self._state.paused_by, self._state.ceiling, None
                )
            return self._state

    def pause(self, by: str) -> ControlsState:
        _by(by)
        s = self.state()
        paused_by = s.paused_by or by  # idempotent: the first pause says who paused
        return self._set(ControlsState(True, paused_by, s.ceiling, s.do_not_disturb_until_ms))

    def resume(self, by: str) -> ControlsState:
        _by(by)
        s = self.state()
        return self._set(ControlsState(False, None, s.ceiling, s.do_not_disturb_until_ms))

    def stop(self, by: str) -> ControlsState:
        _by(by)
        if self._on_stop is not None:
            self._on_stop()
        return self.state()

    def set_ceiling(self, ceiling: float | None, by: str) -> ControlsState:
        _by(by)
        if ceiling is not None and not MIN_CEILING <= ceiling <= self._max_intensity:
            raise ControlsError(
                f"the intensity ceiling {ceiling} is out of range: it must be between "
                f"{MIN_CEILING} and the sleeve's maximum {self._max_intensity}; choose one in "
                "that range, or none to remove the ceiling"
            )
        s = self.state()
        return self._set(ControlsState(s.paused, s.paused_by, ceiling, s.do_not_disturb_until_ms))

    def set_do_not_disturb(self, until_ms: int | None, by: str) -> ControlsState:
        _by(by)
        now_ms = time.time() * 1000
        if until_ms is not None and not now_ms < until_ms <= now_ms + MAX_DO_NOT_DISTURB_MS:
            raise ControlsError(
                f"'do not disturb' until {until_ms} ms is not allowed: it must end in the future "
                "and at most 24 hours from now; choose a time in that range, or none to end it"
            )
        s = self.state()
        return self._set(ControlsState(s.paused, s.paused_by, s.ceiling, until_ms))

    def subscribe(self, callback: Callable[[ControlsState], None]) -> None:
        with self._lock:
            self._subscribers.append(callback)

    def _set(self, state: ControlsState) -> ControlsState:
        with self._lock:
            self._state = state
            if self._path is not None:
                temporary = self._path.with_name(self._path.name + ".tmp")
                temporary.write_text(json.dumps(state.to_json()) + "\n", encoding="utf-8")
                temporary.replace(self._path)
            subscribers = list(self._subscribers)
        for callback in subscribers:
            callback(state)
        return state


def _by(by: str) -> str:
    if by not in CONTROLLERS:
        raise ControlsError(f"unknown controller {by!r}: use one of {', '.join(CONTROLLERS)}")
    return by
