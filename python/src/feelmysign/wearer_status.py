"""What a sender does with the wearer's choice in the sleeve's retained status (``controls``,
docs/protocol.md, read by ``feelmysign.events.Status.controls``): paused, an intensity
ceiling, "do not disturb" until a time.

The wearer's choice always wins over the sender's: a paused sleeve refuses every stroke
(``paused``), one in "do not disturb" every stroke until its end (``do_not_disturb``), and a
ceiling caps every stroke's intensity. So a sender does not send into refusals: it says so and
waits. A status without ``controls`` (an older sleeve, the last will) means none of them.
The mirror of web/src/wearer-status.ts.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from feelmysign.protocol import DO_NOT_DISTURB, PAUSED

if TYPE_CHECKING:
    from feelmysign.events import StatusControls

# Refusals that are the wearer's choice, not the sender's fault: waiting is what to do.
WEARER_REASONS = frozenset({PAUSED, DO_NOT_DISTURB})
# A status's ``paused_by`` when the sleeve paused itself (feelmysign.sleeve.controls.BY_SLEEVE).
PAUSED_BY_SLEEVE = "sleeve"


@dataclass(frozen=True)
class WearerHold:
    """Why the sleeve plays nothing now: ``paused``, or ``do_not_disturb`` until ``until_ms``."""

    reason: Literal["paused", "do_not_disturb"]
    until_ms: int | None = None
    # Paused by the sleeve itself (``paused_by: "sleeve"``): it could not read its wearer's
    # last choices at start, so it started paused and at the least strength.
    by_sleeve: bool = False


def wearer_hold(controls: StatusControls | None, now_ms: int | None = None) -> WearerHold | None:
    """What holds a drawing now, or None (no ``controls``: an older sleeve, the last will). A
    "do not disturb" whose time has passed holds nothing, whether or not the sleeve has
    republished its status yet."""
    if controls is None:
        return None
    if controls.paused:
        return WearerHold("paused", by_sleeve=controls.paused_by == PAUSED_BY_SLEEVE)
    until_ms = controls.do_not_disturb_until_ms
    now = int(time.time() * 1000) if now_ms is None else now_ms
    if until_ms is not None and until_ms > now:
        return WearerHold("do_not_disturb", until_ms)
    return None


def clock_time(ms: int) -> str:
    """A wall-clock time as a person reads it here: "14:30" in the local time zone."""
    return time.strftime("%H:%M", time.localtime(ms / 1000))


def hold_sentence(hold: WearerHold, sleeve_id: str) -> str:
    """What holds the sleeve and what to do, in one sentence (for ``send``)."""
    if hold.reason == "paused" and hold.by_sleeve:
        return (
            f"Sleeve {sleeve_id!r} paused itself: it could not read its wearer's last choices "
            "(its settings file), so it started paused and at the least strength, and refuses "
            "every stroke until the wearer resumes it (their button or the wearer's page). "
            "Nothing was sent; send again once the wearer has resumed."
        )
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
