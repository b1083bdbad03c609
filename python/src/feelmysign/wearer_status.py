"""The wearer's choice as a sender reads it from the sleeve's retained status (``controls``,
docs/protocol.md): paused, an intensity ceiling, "do not disturb" until a time.

The wearer's choice always wins over the sender's: a paused sleeve refuses every stroke
(``paused``), one in "do not disturb" every stroke until its end (``do_not_disturb``), and a
ceiling caps every stroke's intensity. So a sender does not send into refusals: it says so and
waits. A status without ``controls`` (an older sleeve, the last will) means none of them; a
``controls`` of the wrong shape raises ``EventError``, as the typed readers of events.py do.
The mirror of web/src/wearer-status.ts.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from typing import Any, Literal

from feelmysign.events import EventError

PAUSED_REASON = "paused"
DO_NOT_DISTURB_REASON = "do_not_disturb"
# Refusals that are the wearer's choice, not the sender's fault: waiting is what to do.
WEARER_REASONS = frozenset({PAUSED_REASON, DO_NOT_DISTURB_REASON})
# The ``by`` of a ``cancelled`` event when the wearer's pause or stop cut the stroke.
BY_WEARER = "wearer"


@dataclass(frozen=True)
class WearerHold:
    """Why the sleeve plays nothing now: ``paused``, or ``do_not_disturb`` until ``until_ms``."""

    reason: Literal["paused", "do_not_disturb"]
    until_ms: int | None = None


@dataclass(frozen=True)
class WearerControls:
    paused: bool = False
    paused_by: str | None = None  # "button" | "page" | "cli"; None when not paused
    ceiling: float | None = None  # the wearer's intensity ceiling, 0..1; None: none
    do_not_disturb_until_ms: int | None = None  # wall clock, ms since 1970; None: off

    def hold(self, now_ms: int | None = None) -> WearerHold | None:
        """What holds a drawing now, or None. A "do not disturb" whose time has passed holds
        nothing, whether or not the sleeve has republished its status yet."""
        if self.paused:
            return WearerHold("paused")
        until_ms = self.do_not_disturb_until_ms
        now = int(time.time() * 1000) if now_ms is None else now_ms
        if until_ms is not None and until_ms > now:
            return WearerHold("do_not_disturb", until_ms)
        return None


NO_CONTROLS = WearerControls()


def controls_from_status(status: object) -> WearerControls:
    """The ``controls`` of a status: its JSON object, or its payload (bytes or text).

    NO_CONTROLS when it has none; EventError naming the field when one has the wrong type."""
    if isinstance(status, bytes | str):
        try:
            status = json.loads(status)
        except ValueError as error:
            raise EventError(f"The status is not JSON: {error}.") from None
    if not isinstance(status, dict):
        raise EventError("The status is not a JSON object.")
    controls = status.get("controls")
    if controls is None:
        return NO_CONTROLS
    if not isinstance(controls, dict):
        raise EventError("The status's controls is not a JSON object.", "controls")
    paused = controls.get("paused")
    if not isinstance(paused, bool):
        raise EventError("controls.paused must be true or false.", "controls.paused")
    return WearerControls(
        paused=paused,
        paused_by=_text(controls, "paused_by") if paused else None,
        ceiling=_fraction(controls, "ceiling"),
        do_not_disturb_until_ms=_time_ms(controls, "do_not_disturb_until_ms"),
    )


def _text(controls: dict[str, Any], name: str) -> str | None:
    value = controls.get(name)
    if value is not None and not isinstance(value, str):
        raise EventError(f"controls.{name} must be a string or null.", f"controls.{name}")
    return value


def _fraction(controls: dict[str, Any], name: str) -> float | None:
    value = controls.get(name)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0 <= value <= 1:
        raise EventError(
            f"controls.{name} must be a number from 0 to 1 or null.", f"controls.{name}"
        )
    return float(value)


def _time_ms(controls: dict[str, Any], name: str) -> int | None:
    value = controls.get(name)
    if value is None:
        return None
    # 3.0 is the whole number 3 (events.py's rule for every reader).
    whole = isinstance(value, int | float) and not isinstance(value, bool) and value == int(value)
    if not whole or value < 0:
        raise EventError(
            f"controls.{name} must be a whole number of ms since 1970 or null.", f"controls.{name}"
        )
    return int(value)


def clock_time(ms: int) -> str:
    """A wall-clock time as a person reads it here: "14:30" in the local time zone."""
    return time.strftime("%H:%M", time.localtime(ms / 1000))


def hold_sentence(hold: WearerHold, sleeve_id: str) -> str:
    """What holds the sleeve and what to do, in one sentence (for ``send``)."""
    if hold.reason == "paused":
        return (
            f"The wearer paused sleeve {sleeve_id!r}: it plays nothing and refuses every stroke "
            "until the wearer resumes it (their button or the wearer's page). Nothing was sent; "
            "send again once the wearer has resumed."
        )
    until = clock_time(hold.until_ms or 0)
    return (
        f"The wearer of sleeve {sleeve_id!r} asked not to be disturbed until {until}: it refuses "
        f"every stroke until then. Nothing was sent; send again after {until}, or once the "
        "wearer has ended it."
    )


def ceiling_sentence(ceiling: float, asked: list[float]) -> str:
    """The wearer's ceiling and how many of the intensities ``asked`` it caps."""
    above = sum(1 for intensity in asked if intensity > ceiling)
    capped = (
        f"{above} of the {len(asked)} strokes ask for more and play at {ceiling:g}"
        if above
        else "every stroke asks for no more than that"
    )
    return (
        f"The wearer set a ceiling of {ceiling * 100:.0f} % (intensity {ceiling:g}): it caps "
        f"every stroke's intensity; {capped}."
    )


def cancelled_by_wearer(payload: bytes | str) -> bool:
    """Whether an event's payload is a ``cancelled`` one the wearer caused (``"by": "wearer"``)."""
    try:
        data = json.loads(payload)
    except ValueError:
        return False
    return (
        isinstance(data, dict) and data.get("type") == "cancelled" and data.get("by") == BY_WEARER
    )
