"""Vectors for the control message (feelmysign.control): cancel one drawing, or everything.

- ``valid/<name>.json``: ``payload`` (text) and ``cancel``, the drawing id or ``"*"`` read;
- ``invalid/<name>.json``: ``payload`` and the ``reason`` code and ``field`` it is refused with
  (``message`` is the reference's sentence, for information);
- ``format/<name>.json``: ``cancel`` and the exact ``text`` senders publish.

Each case names the outcome it is meant to show; generation stops if the reference disagrees.
"""

from __future__ import annotations

from typing import Any

from feelmysign.control import Cancel, format_control, parse_control
from feelmysign.protocol import Rejected

UUID = "6f1c2a9e-3b7d-4c55-9a1e-2f0b8d4c7e31"

VALID: dict[str, tuple[str, str, str]] = {
    "one-drawing": ("cancel one drawing", f'{{"v":1,"cancel":"{UUID}"}}', UUID),
    "everything": ("cancel everything", '{"v":1,"cancel":"*"}', "*"),
    "spaces-around": (
        "whitespace around and inside is JSON's",
        ' \n{ "v": 1, "cancel": "d1" }\n',
        "d1",
    ),
    "version-as-float": ("1.0 is version 1", '{"v":1.0,"cancel":"d1"}', "d1"),
    "unknown-keys": (
        "keys a newer sender adds are ignored",
        '{"v":1,"cancel":"d1","by":"x"}',
        "d1",
    ),
    "longest-id": ("a drawing id of 64 characters", f'{{"v":1,"cancel":"{"a" * 64}"}}', "a" * 64),
}

INVALID: dict[str, tuple[str, str, str]] = {
    "empty": ("nothing", "   ", "empty"),
    "too-long": (
        "more than 512 bytes",
        '{"v":1,"cancel":"d1","pad":"' + "x" * 600 + '"}',
        "too_long",
    ),
    "not-json": ("text that is not JSON", "cancel d1", "invalid_json"),
    "nan": ("NaN is not JSON", '{"v":NaN,"cancel":"*"}', "invalid_json"),
    "array": ("an array", '["*"]', "not_an_object"),
    "no-cancel": ("no cancel", '{"v":1}', "missing_field"),
    "null-cancel": ("null for a required field", '{"v":1,"cancel":null}', "missing_field"),
    "no-version": ("no v", '{"cancel":"*"}', "missing_field"),
    "version-string": ("v as text", '{"v":"1","cancel":"*"}', "wrong_type"),
    "version-bool": ("true is not a number", '{"v":true,"cancel":"*"}', "wrong_type"),
    "version-2": ("a version this sleeve does not know", '{"v":2,"cancel":"*"}', "unknown_version"),
    "cancel-number": ("a drawing id as a number", '{"v":1,"cancel":3}', "wrong_type"),
    "cancel-list": ("a list of drawings", '{"v":1,"cancel":["a","b"]}', "wrong_type"),
    "cancel-empty": ("an empty drawing id", '{"v":1,"cancel":""}', "bad_drawing_id"),
    "cancel-space": ("a drawing id with a space", '{"v":1,"cancel":"a b"}', "bad_drawing_id"),
    "cancel-too-long": (
        "a drawing id of 65 characters",
        f'{{"v":1,"cancel":"{"a" * 65}"}}',
        "bad_drawing_id",
    ),
}

FORMAT: dict[str, tuple[str, str]] = {
    "one-drawing": ("one drawing", UUID),
    "everything": ("everything", "*"),
}


def cases() -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name, (description, payload, drawing) in VALID.items():
        result = parse_control(payload)
        assert result == Cancel(drawing), (name, result)
        out[f"valid/{name}.json"] = {
            "description": description,
            "payload": payload,
            "cancel": result.drawing,
        }
    for name, (description, payload, reason) in INVALID.items():
        refused = parse_control(payload)
        assert isinstance(refused, Rejected) and refused.reason == reason, (name, refused)
        out[f"invalid/{name}.json"] = {
            "description": description,
            "payload": payload,
            "reason": refused.reason,
            "field": refused.field,
            "message": refused.message,
        }
    for name, (description, drawing) in FORMAT.items():
        text = format_control(Cancel(drawing))
        assert parse_control(text) == Cancel(drawing), name
        out[f"format/{name}.json"] = {"description": description, "cancel": drawing, "text": text}
    return out
