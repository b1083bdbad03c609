"""The control message: a sender tells the sleeve to cancel one drawing, or everything.

Published (QoS 1, never retained) on ``feelmysign/<sleeve-id>/control``:

    {"v":1,"cancel":"6f1c2a9e-3b7d-4c55-9a1e-2f0b8d4c7e31"}   one drawing
    {"v":1,"cancel":"*"}                                       everything

The sleeve stops the strokes concerned within one frame of the player (the
motors they drive go off at once), drops those still queued, reports each one
as ``cancelled``, and refuses later strokes of a cancelled drawing (a stroke
the broker still held for it must not start it again). Checked like a stroke
(docs/protocol.md, "Control"): the same payload limits and reason codes, and
the same vectors for every port (``testdata/control``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

from feelmysign.protocol import (
    BAD_DRAWING_ID,
    EMPTY,
    INVALID_JSON,
    JSON_VERSION,
    MAX_DRAWING_ID_CHARS,
    MISSING_FIELD,
    NOT_AN_OBJECT,
    NOT_TEXT,
    TOO_LONG,
    UNKNOWN_VERSION,
    WRONG_TYPE,
    Rejected,
    is_drawing_id,
    payload_text,
)

CANCEL_ALL = "*"
_EXAMPLE = '{"v":1,"cancel":"*"}'


@dataclass(frozen=True)
class Cancel:
    """Cancel the strokes of ``drawing``, or of every drawing when it is ``"*"``."""

    drawing: str

    @property
    def everything(self) -> bool:
        return self.drawing == CANCEL_ALL

    def matches(self, drawing: str | None) -> bool:
        """Whether a stroke of ``drawing`` (None: a stroke without one) is cancelled."""
        return self.everything or drawing == self.drawing


def format_control(cancel: Cancel) -> str:
    """The exact text senders publish: compact, keys ``v, cancel``."""
    if not cancel.everything and not is_drawing_id(cancel.drawing):
        raise ValueError(f"not a drawing id: {cancel.drawing!r}")
    return json.dumps({"v": JSON_VERSION, "cancel": cancel.drawing}, separators=(",", ":"))


def parse_control(payload: object) -> Cancel | Rejected:
    """Read one control message; never raises. Unknown keys are ignored, as in strokes."""
    text = payload_text(payload, example=_EXAMPLE)
    if isinstance(text, Rejected):
        return text
    body = text.strip(" \t\r\n")
    if not body:
        return Rejected(EMPTY, f"The control message is empty; send e.g. {_EXAMPLE}.")
    try:
        document = json.loads(body, parse_constant=_no_constant)
    except (ValueError, RecursionError):
        return Rejected(
            INVALID_JSON, f"The control message is not valid JSON; send e.g. {_EXAMPLE}."
        )
    if not isinstance(document, dict):
        return Rejected(
            NOT_AN_OBJECT, f"The control message must be a JSON object such as {_EXAMPLE}."
        )
    for key in ("v", "cancel"):
        if document.get(key) is None:
            return Rejected(
                MISSING_FIELD,
                f'The control message has no "{key}"; it needs v and cancel, e.g. {_EXAMPLE}.',
                key,
            )
    version = document["v"]
    if isinstance(version, bool) or not isinstance(version, int | float):
        return Rejected(WRONG_TYPE, f'"v" must be the number {JSON_VERSION}.', "v")
    if version != JSON_VERSION:
        return Rejected(
            UNKNOWN_VERSION,
            f'"v" is {version}; this sleeve understands only version {JSON_VERSION}.',
            "v",
        )
    drawing = document["cancel"]
    if not isinstance(drawing, str):
        return Rejected(
            WRONG_TYPE, '"cancel" must be a string: a drawing id, or "*" for everything.', "cancel"
        )
    if drawing != CANCEL_ALL and not is_drawing_id(drawing):
        return Rejected(
            BAD_DRAWING_ID,
            f'"cancel" must be "*" or a drawing id of 1 to {MAX_DRAWING_ID_CHARS} printable '
            "ASCII characters without spaces.",
            "cancel",
        )
    return Cancel(drawing)


def _no_constant(name: str) -> float:
    raise ValueError(f"{name} is not JSON")


# Every reason a control message can be refused with (a subset of the stroke reasons).
REASONS = (
    NOT_TEXT,
    TOO_LONG,
    EMPTY,
    INVALID_JSON,
    NOT_AN_OBJECT,
    MISSING_FIELD,
    WRONG_TYPE,
    UNKNOWN_VERSION,
    BAD_DRAWING_ID,
)
