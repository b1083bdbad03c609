"""The wearer's controls: pause, stop, an intensity ceiling and "do not disturb".

The person wearing the motors decides, whatever a sender sends: a paused sleeve
plays nothing (every stroke refused as ``paused``), "do not disturb" refuses every
stroke until a time (``do_not_disturb``) and ends by itself, the wearer's ceiling
caps every stroke's intensity below the layout's ``max_intensity``, and stop cuts
what plays and drops what waits (like a sender's cancel of everything, reported
``by: "wearer"``). The pause button (``feelmysign.backends.button``), the wearer's
page and the CLI all call :class:`WearerControls`.

The state is kept in the sleeve's state directory,
``$XDG_STATE_HOME/feelmysign/controls/<sleeve-id>.json`` (``/var/lib/feelmysign/...``
for the systemd unit), written whole to a temporary file and renamed over the old one
before a method returns, so that it survives a restart, ``kill -9`` included::

    {"format": "feelmysign-controls/1", "paused": true, "paused_by": "button",
     "ceiling": 0.6, "do_not_disturb_until_ms": null}

Each change is first written to a second file, ``<sleeve-id>.json.last-good``, the same
way, then to the first: a file that cannot be read or makes no sense (a disk that lost
it, a hand edit) is said in one log line, and the other one is used. When neither can be
read the wearer's last choice is unknown, and the sleeve starts on the safe side of both
choices: **paused** (``paused_by: "sleeve"``) and with the **least ceiling**
(``MIN_CEILING``, 0.05), as the log line says. Not "no ceiling": after the wearer
resumes, the sleeve must never play stronger than the wearer chose, and the least
ceiling is below any ceiling the wearer can choose; the wearer raises it again on the
wearer's page (or removes it), which writes both files anew.
"""

from __future__ import annotations

import json
import logging
import math
import os
import threading
import time
from collections.abc import Callable
from typing import Any

from feelmysign.clock import wall_ms
from feelmysign.errors import FeelMySignError
from feelmysign.events import StatusControls
from feelmysign.input_files import loads_json, read_text
from feelmysign.player import Refusal
from feelmysign.protocol import DO_NOT_DISTURB, PAUSED
from feelmysign.state_home import state_path
from feelmysign.wearer_status import PAUSED_BY_SLEEVE

log = logging.getLogger(__name__)

# The wearer's controls as the status tells them (one class for both: the status's
# ``controls`` object is this state).
ControlsState = StatusControls

CONTROLS_FORMAT = "feelmysign-controls/1"
MAX_CONTROLS_BYTES = 64 * 1024  # the file is under 200 bytes
LAST_GOOD_SUFFIX = ".last-good"  # the second copy, written before the first
# Below this a stroke is barely felt at all: a ceiling lower than it is a pause, which the
# wearer has its own control for.
MIN_CEILING = 0.05
MAX_DO_NOT_DISTURB_MS = 24 * 3600 * 1000  # one night and day: longer is a mistake, or a pause
# Who changed the controls: the sleeve's button, the wearer's page, ``feelmysign wearer``.
# ``sleeve``: the sleeve paused itself at start, its controls file unreadable.
BY = ("button", "page", "cli")
BY_SLEEVE = PAUSED_BY_SLEEVE

NOT_PAUSED = ControlsState(paused=False)


class ControlsError(FeelMySignError):
    """A control the sleeve cannot take: the message says what, the allowed range and what to
    do."""


def controls_path(sleeve_id: str) -> str:
    """``$XDG_STATE_HOME/feelmysign/controls/<sleeve-id>.json``: one file per sleeve, as two
    sleeves on one machine (the load bench) are two wearers."""
    return state_path("controls", f"{sleeve_id}.json")


def refusal_for(state: ControlsState, now_ms: float) -> Refusal | None:
    """Why every stroke is refused in ``state`` (a pause before "do not disturb"), or None."""
    if state.paused:
        return Refusal(
            PAUSED,
            "the wearer paused the sleeve; it plays again when the wearer presses the pause "
            "button again, or resumes on the wearer's page",
        )
    until_ms = state.do_not_disturb_until_ms
    if until_ms is not None and until_ms > now_ms:
        return Refusal(
            DO_NOT_DISTURB,
            f"the wearer asked not to be disturbed until {_clock_time(until_ms)}; strokes play "
            "again after that",
        )
    return None


def _clock_time(at_ms: float) -> str:
    return time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(at_ms / 1000))


class WearerControls:
    """The wearer's controls of one sleeve; every method may be called from any thread.

    ``apply`` is called with each new state before it is written (the sleeve makes the
    player pause or resume, and sets the ceiling: the motors go off before the disk is
    touched), ``stop`` for the wearer's stop. ``subscribe``'s callbacks follow, once the
    state is kept.
    """

    def __init__(
        self,
        path: str,
        *,
        max_intensity: float,
        apply: Callable[[ControlsState], None] = lambda state: None,
        stop: Callable[[], None] = lambda: None,
        clock_ms: Callable[[], float] = wall_ms,
    ) -> None:
        self._path = path
        self._max_intensity = max_intensity
        self._apply = apply
        self._stop = stop
        self._clock_ms = clock_ms
        self._lock = threading.RLock()
        self._subscribers: list[Callable[[ControlsState], None]] = []
        self._timer: threading.Timer | None = None
        self._state = self._load()
        self._apply(self._state)
        self._time_do_not_disturb()

    @property
    def path(self) -> str:
        return self._path

    @property
    def max_intensity(self) -> float:
        """The layout's cap: the highest ceiling the wearer may set."""
        return self._max_intensity

    def state(self) -> ControlsState:
        # No lock: the state is one frozen value, replaced whole; a reader (the status the
        # player's thread publishes after a lost chip) must never wait for a change's fsync.
        return self._state

    def refusal(self) -> Refusal | None:
        """Why a stroke arriving now is refused (paused, "do not disturb"), or None."""
        return refusal_for(self.state(), self._clock_ms())

    # --- the wearer's controls ---------------------------------------------------------

    def pause(self, by: str) -> ControlsState:
        """Pause: what plays is cut and every stroke refused until ``resume``. Idempotent."""
        _check_by(by)
        with self._lock:
            if self._state.paused:
                return self._state
            return self._change(paused=True, paused_by=by)

    def resume(self, by: str) -> ControlsState:
        """Play again (a "do not disturb" still running still refuses). Idempotent."""
        _check_by(by)
        with self._lock:
            if not self._state.paused:
                return self._state
            return self._change(paused=False, paused_by=None)

    def stop(self, by: str) -> ControlsState:
        """Stop what plays and drop what waits, like a sender's cancel of everything (the
        events say ``by: "wearer"``); the sleeve is not paused by it."""
        _check_by(by)
        log.info("the wearer stopped the sleeve (%s)", by)
        self._stop()
        return self.state()

    def set_ceiling(self, ceiling: float | None, by: str) -> ControlsState:
        """No stroke driven above ``ceiling`` (``MIN_CEILING`` to the layout's max_intensity);
        None removes it."""
        _check_by(by)
        if ceiling is not None:
            ceiling = self._checked_ceiling(ceiling)
        with self._lock:
            if ceiling == self._state.ceiling:
                return self._state
            return self._change(ceiling=ceiling)

    def set_do_not_disturb(self, until_ms: int | None, by: str) -> ControlsState:
        """Refuse every stroke until ``until_ms`` (wall clock, ms since 1970; in the future and
        at most 24 h ahead); None ends it. It ends by itself at that time."""
        _check_by(by)
        if until_ms is not None:
            until_ms = self._checked_until(until_ms)
        with self._lock:
            state = self._change(do_not_disturb_until_ms=until_ms)
        self._time_do_not_disturb()
        return state

    def subscribe(self, callback: Callable[[ControlsState], None]) -> None:
        """``callback(state)`` after each change (on the thread that made it, or the timer's
        when "do not disturb" runs out). It must not raise; if it does, it is logged."""
        with self._lock:
            self._subscribers.append(callback)

    def close(self) -> None:
        """Stop the "do not disturb" timer (the sleeve is stopping)."""
        with self._lock:
            timer, self._timer = self._timer, None
        if timer is not None:
            timer.cancel()

    # --- checks ------------------------------------------------------------------------

    def _checked_ceiling(self, ceiling: object) -> float:
        top = self._max_intensity
        value = _finite(ceiling)
        if value is None or not MIN_CEILING <= value <= top:
            raise ControlsError(
                f"the intensity ceiling must be a number from {MIN_CEILING:g} to {top:g} (the "
                f"layout's max_intensity), got {ceiling!r}; choose one in that range, or none "
                "to remove the ceiling (to stop every stroke, pause instead)"
            )
        return round(value, 4)

    def _checked_until(self, until_ms: object) -> int:
        now_ms = self._clock_ms()
        value = _finite(until_ms)
        if value is None:
            raise ControlsError(
                f'"do not disturb" needs the time it ends, in ms since 1970, got {until_ms!r}; '
                "give a time within the next 24 hours, or none to end it now"
            )
        until = round(value)
        if not now_ms < until <= now_ms + MAX_DO_NOT_DISTURB_MS:
            instead = (
                "a later time, up to 24 hours ahead"
                if until <= now_ms
                else "an earlier time, at most 24 hours ahead"
            )
            raise ControlsError(
                f'"do not disturb" until {_clock_time(until)} is not within the next 24 hours '
                f"(now {_clock_time(now_ms)}); give {instead}, or none to end it now"
            )
        return int(until)

    # --- state -------------------------------------------------------------------------

    def _change(self, **changes: Any) -> ControlsState:
        """Under the lock: the new state applied (the motors first), kept, then told."""
        values = {**self._state.to_json(), **changes}
        state = ControlsState(**values)
        self._state = state
        self._apply(state)
        self._save(state)
        for callback in list(self._subscribers):
            try:
                callback(state)
            except Exception:  # a subscriber must not undo the wearer's choice
                log.exception("a subscriber to the wearer's controls failed")
        return state

    def _save(self, state: ControlsState) -> None:
        """Written whole or not at all, the second copy first (so one of the two holds a
        whole state whatever happens meanwhile). A disk that refuses leaves the choice in
        force in this process (the wearer's choice wins now) and says it will not survive a
        restart."""
        text = json.dumps({"format": CONTROLS_FORMAT, **state.to_json()}) + "\n"
        try:
            os.makedirs(os.path.dirname(self._path), mode=0o700, exist_ok=True)
            for path in (self._path + LAST_GOOD_SUFFIX, self._path):
                temporary = f"{path}.{os.getpid()}.tmp"
                with open(temporary, "w", encoding="utf-8") as file:
                    file.write(text)
                    file.flush()
                    os.fsync(file.fileno())  # a pause must survive a power cut that follows it
                os.replace(temporary, path)
        except OSError as error:
            log.error(
                "the wearer's controls could not be kept in %s (%s): they hold until the sleeve "
                "restarts, not after; check that the sleeve's state directory can be written",
                self._path,
                error.strerror or error,
            )

    def _load(self) -> ControlsState:
        """The first file's state; else the second copy's, said in one line; else the safe
        side (paused, the least ceiling). Neither file: a sleeve the wearer never touched."""
        last_good = self._path + LAST_GOOD_SUFFIX
        state, problem = self._read(self._path)
        if state is not None:
            return state
        if problem is None and not os.path.exists(last_good):
            return NOT_PAUSED
        fallback, fallback_problem = self._read(last_good)
        if fallback is not None:
            if problem is not None:
                log.error(
                    "the wearer's controls file %s is unusable (%s): using its last good copy "
                    "%s (%s)",
                    self._path,
                    problem,
                    last_good,
                    describe(fallback),
                )
            return fallback
        problems = [f"{self._path}: {problem or 'missing'}"]
        problems.append(f"{last_good}: {fallback_problem or 'missing'}")
        return self._unreadable("; ".join(problems))

    def _read(self, path: str) -> tuple[ControlsState | None, str | None]:
        """The state in ``path``, or None and what is wrong with it (None: no such file)."""
        try:
            text = read_text(path, max_bytes=MAX_CONTROLS_BYTES)
        except FileNotFoundError:
            return None, None
        except (OSError, UnicodeDecodeError) as error:
            return None, f"cannot be read: {getattr(error, 'strerror', None) or error}"
        try:
            return self._parse(loads_json(text)), None
        except (ValueError, TypeError, KeyError) as error:
            return None, str(error) or type(error).__name__

    def _parse(self, data: Any) -> ControlsState:
        if not isinstance(data, dict) or data.get("format") != CONTROLS_FORMAT:
            raise ValueError(f'not a controls file (its "format" is not {CONTROLS_FORMAT!r})')
        paused, paused_by = data["paused"], data.get("paused_by")
        if not isinstance(paused, bool):
            raise ValueError('"paused" is not true or false')
        if paused and paused_by not in (*BY, BY_SLEEVE):
            paused_by = BY_SLEEVE
        ceiling = data.get("ceiling")
        if ceiling is not None:
            ceiling = self._checked_ceiling(min(float(ceiling), self._max_intensity))
        until_ms = data.get("do_not_disturb_until_ms")
        if until_ms is not None and (not isinstance(until_ms, int) or until_ms <= self._clock_ms()):
            until_ms = None  # passed while the sleeve was off
        return ControlsState(
            paused=paused,
            paused_by=paused_by if paused else None,
            ceiling=ceiling,
            do_not_disturb_until_ms=until_ms,
        )

    def _unreadable(self, problem: str) -> ControlsState:
        log.error(
            "the wearer's controls cannot be read (%s): starting paused and with the least "
            "ceiling, %g, the safe side, as the ceiling the wearer chose is unknown; the wearer "
            "resumes with the pause button or the wearer's page, and sets the ceiling again "
            "there (which writes the file anew)",
            problem,
            MIN_CEILING,
        )
        return ControlsState(paused=True, paused_by=BY_SLEEVE, ceiling=MIN_CEILING)

    def _time_do_not_disturb(self) -> None:
        """A timer that ends "do not disturb" at its time (none when it is off)."""
        with self._lock:
            if self._timer is not None:
                self._timer.cancel()
                self._timer = None
            until_ms = self._state.do_not_disturb_until_ms
            if until_ms is None:
                return
            delay_s = max(0.0, (until_ms - self._clock_ms()) / 1000)
            self._timer = threading.Timer(delay_s, self._end_do_not_disturb, args=(until_ms,))
            self._timer.daemon = True
            self._timer.name = "feelmysign-do-not-disturb"
            self._timer.start()

    def _end_do_not_disturb(self, until_ms: int) -> None:
        with self._lock:
            if self._state.do_not_disturb_until_ms != until_ms:
                return  # changed meanwhile: that change set its own timer
            if self._clock_ms() < until_ms:  # the wall clock was set back: wait on
                self._time_do_not_disturb()
                return
            log.info('"do not disturb" ended at %s', _clock_time(until_ms))
            self._timer = None
            self._change(do_not_disturb_until_ms=None)


def describe(state: ControlsState) -> str:
    """The controls in words, for the log: "paused (by button), ceiling 0.6, do not disturb
    until 2026-11-26 23:00:00 UTC"."""
    paused = f"paused (by {state.paused_by})" if state.paused else "not paused"
    ceiling = "no ceiling" if state.ceiling is None else f"ceiling {state.ceiling:g}"
    until_ms = state.do_not_disturb_until_ms
    dnd = "" if until_ms is None else f', "do not disturb" until {_clock_time(until_ms)}'
    return f"{paused}, {ceiling}{dnd}"


def _finite(value: object) -> float | None:
    """``value`` as a finite float; None for anything else (a bool, text, NaN)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None


def _check_by(by: str) -> None:
    if by not in BY:
        raise ControlsError(
            f"who changes the wearer's controls must be one of {', '.join(BY)}, got {by!r}; "
            "this is a bug in the caller"
        )
