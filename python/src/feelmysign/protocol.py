"""Stroke messages on the wire: the original sleeve's legacy CSV and JSON v1.

``parse`` turns a payload (bytes from MQTT, or text) into an ``Accepted`` stroke
or a ``Rejected`` reason; it never raises, whatever the payload, because one bad
message must never stop the sleeve. ``format_legacy`` and ``format_json`` write
the text a sender publishes. The legacy format is the one of the original sleeve
("Can You Feel My Sign?", appendix A.2): ``startX,startY,endX,endY,duration``.
docs/protocol.md describes both formats, every field's range and every reason.

Checks run in a fixed order and the first problem found is reported, so every
port (TypeScript, Java) gives the same reason for the same payload:
payload (type, size, UTF-8, empty), then the format's syntax, then the fields in
wire order (drawing, seq, start, end, duration_ms, intensity, sent_at_ms).
"""

from __future__ import annotations

import difflib
import json
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from decimal import ROUND_HALF_UP, Context, Decimal
from typing import Any, Literal

from feelmysign.errors import StrokeError
from feelmysign.frozen_init import dict_init
from feelmysign.layout import Layout
from feelmysign.stroke import Point, Stroke

Format = Literal["auto", "legacy", "json"]
WireFormat = Literal["legacy", "json"]

MAX_PAYLOAD_BYTES = 512  # one stroke fits in ~150 bytes; more is junk or an attack
LEGACY_DECIMALS = 4  # 1e-4 grid units is ~3 micrometres on a 3 cm grid: far below touch acuity
GRID_TOLERANCE = 1e-9  # a sender's float maths may land 2.9999999999 for 3; accepted, then clamped
MAX_DRAWING_ID_CHARS = 64  # a UUID is 36; room for a prefix, small enough for logs and topics
MAX_SEQ = 2**53 - 1  # the largest integer a JavaScript sender holds exactly
# The latest sent_at_ms a sender's clock can give: 1e13 ms since 1970 is 20 November 2286.
# Beyond it the clock is broken (or the field holds something else), and its pace is nonsense.
MAX_SENT_AT_MS = 1e13
JSON_VERSION = 1
SHOWN_VALUE_CHARS = 40  # bad values are quoted in messages up to this many characters

# Reason codes: stable, snake_case, the same in every language and in docs/protocol.md.
NOT_TEXT = "not_text"
TOO_LONG = "too_long"
EMPTY = "empty"
WRONG_FIELD_COUNT = "wrong_field_count"
NOT_A_NUMBER = "not_a_number"
NOT_FINITE = "not_finite"
INVALID_JSON = "invalid_json"
NOT_AN_OBJECT = "not_an_object"
MISSING_FIELD = "missing_field"
WRONG_TYPE = "wrong_type"
UNKNOWN_VERSION = "unknown_version"
BAD_DRAWING_ID = "bad_drawing_id"
SEQ_OUT_OF_RANGE = "seq_out_of_range"
OUTSIDE_GRID = "outside_grid"
DURATION_NOT_POSITIVE = "duration_not_positive"
DURATION_TOO_LONG = "duration_too_long"
INTENSITY_OUT_OF_RANGE = "intensity_out_of_range"
SENT_AT_OUT_OF_RANGE = "sent_at_out_of_range"
# The sleeve's own reasons, for a stroke it could read (feelmysign.sleeve.admission, in the
# order it checks them; docs/protocol.md, "What the sleeve publishes").
RETAINED = "retained"
CANCELLED = "cancelled"
HELD = "held"  # a copy waiting with its original: no event, acknowledged when it plays
DUPLICATE = "duplicate"
RATE_LIMITED = "rate_limited"
STALE = "stale"
LATE = "late"
QUEUE_FULL = "queue_full"
PLAYER_STOPPED = "player_stopped"
SILENCED = "silenced"  # the enable line is held low for a chip that does not answer
# The sleeve stopped: a stroke not started is rejected so (never acknowledged: the broker
# delivers it again), one playing is cut short so (a ``safety`` event after its ``played``).
STOPPED = "stopped"
# The sleeve's process ended (kill -9, a crash, a power cut) while the stroke played: a
# ``safety`` event after its ``played``, from the sleeve started next
# (feelmysign.sleeve.pace_memory).
CRASHED = "crashed"
# The wearer's (feelmysign.sleeve.controls): the sleeve paused, or "do not disturb" running.
PAUSED = "paused"
DO_NOT_DISTURB = "do_not_disturb"

REASONS: dict[str, str] = {
    NOT_TEXT: "the payload is not a string or bytes, or its bytes are not UTF-8",
    TOO_LONG: f"the payload is longer than {MAX_PAYLOAD_BYTES} bytes (UTF-8)",
    EMPTY: "the payload is empty or only whitespace",
    WRONG_FIELD_COUNT: "a legacy payload without exactly 5 comma-separated fields",
    NOT_A_NUMBER: "a legacy field that is not a decimal number",
    NOT_FINITE: "a number that is NaN, infinite or too large to represent",
    INVALID_JSON: "a payload chosen as JSON that is not valid JSON",
    NOT_AN_OBJECT: "valid JSON that is not an object",
    MISSING_FIELD: "a JSON message without a required field (v, start, end, duration_ms)",
    WRONG_TYPE: "a JSON field of the wrong type (e.g. start not [x, y], seq not an integer)",
    UNKNOWN_VERSION: f"a JSON message whose v is not {JSON_VERSION}",
    BAD_DRAWING_ID: "drawing is not 1 to 64 printable ASCII characters without spaces",
    SEQ_OUT_OF_RANGE: f"seq is below 0 or above {MAX_SEQ}",
    OUTSIDE_GRID: "start or end lies outside the sleeve's grid",
    DURATION_NOT_POSITIVE: "duration_ms is 0 or negative",
    DURATION_TOO_LONG: "duration_ms is above the sleeve's max_stroke_duration_ms",
    INTENSITY_OUT_OF_RANGE: "intensity is outside 0..1",
    SENT_AT_OUT_OF_RANGE: "sent_at_ms is negative or above 1e13 (the year 2286)",
}

# JSON's whitespace (RFC 8259), also stripped around the legacy payload and each field.
_WHITESPACE = " \t\r\n"
_BOM = "\ufeff"
_LEGACY_FIELDS = ("startX", "startY", "endX", "endY", "duration")
_LEGACY_STROKE_FIELDS = ("start", "start", "end", "end", "duration_ms")
_LEGACY_EXAMPLE = "'0,0,2,0,1000'"
_JSON_EXAMPLE = '{"v":1,"start":[0,0],"end":[2,0],"duration_ms":1000}'
# ASCII only: Python's float() also takes '1_000' and non-ASCII digits, other languages don't.
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NON_FINITE_WORD = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)
_DRAWING_ID = re.compile(rf"[!-~]{{1,{MAX_DRAWING_ID_CHARS}}}")
_LEGACY_QUANTUM = Decimal(1).scaleb(-LEGACY_DECIMALS)
_EXACT = Context(prec=400)  # enough digits for any finite double, so quantize never overflows


@dict_init
@dataclass(frozen=True)
class Accepted:
    """A payload the sleeve would play: the stroke (clamped into the grid) and its format.

    Made with one dict update (``dict_init``): one per message, before its first motor command.
    """

    stroke: Stroke
    format: WireFormat


@dataclass(frozen=True)
class Rejected:
    """A payload the sleeve refuses: a stable ``reason`` code, a sentence a person can act on,
    and the stroke field at fault (``start``, ``duration_ms``...) when there is one."""

    reason: str
    message: str
    field: str | None = None
    # The stroke's drawing and seq, when they were read and valid and something else was wrong:
    # the sleeve's event carries them, so the sender's page and log know which stroke it was.
    drawing: str | None = None
    seq: int | None = None

    def as_error(self, what: str, *, then: str = "") -> StrokeError:
        """The error for a stroke of ours the sleeve would refuse: ``what`` names the stroke,
        ``then`` (a sentence) says what was not done because of it."""
        return StrokeError(
            self.reason,
            f"{what} would be rejected by the sleeve ({self.reason}): {self.message}{then}",
        )


def parse(
    payload: object, layout: Layout | None, *, format: Format = "auto"
) -> Accepted | Rejected:
    """Parse and validate one stroke message against ``layout``'s grid and duration cap.

    ``layout`` None: the message's form only, for a sender that does not know the sleeve
    yet: no grid and no duration cap (any sleeve's), and the stroke is not clamped.

    ``format="auto"`` reads JSON when the text starts with ``{`` or ``[`` (after
    whitespace), the legacy CSV otherwise. Never raises on any payload.
    """
    if format not in ("auto", "legacy", "json"):
        raise ValueError(f"format must be 'auto', 'legacy' or 'json', not {format!r}")
    text = _payload_text(payload)
    if isinstance(text, Rejected):
        return text
    body = text.strip(_WHITESPACE)
    if not body:
        return Rejected(
            EMPTY,
            f"The payload is empty; send a stroke such as {_LEGACY_EXAMPLE} "
            f"(startX,startY,endX,endY,duration in grid units and ms) or {_JSON_EXAMPLE}.",
        )
    chosen = _detect(body) if format == "auto" else format
    if chosen == "json":
        stroke = _parse_json(body, layout)
        if isinstance(stroke, Accepted):  # plainly valid: checked as it was read
            return stroke
    else:
        stroke = _parse_legacy(body)
    if isinstance(stroke, Rejected):
        return stroke
    checked = (
        validate_stroke(stroke, layout) if layout is not None else _first_problem(stroke, None)
    )
    if isinstance(checked, Rejected):
        return _named(checked, stroke)
    return Accepted(stroke if checked is None else checked, chosen)


def _named(problem: Rejected, stroke: Stroke) -> Rejected:
    """``problem`` with the stroke's drawing and seq, unless one of them is the problem."""
    if problem.field in ("drawing", "seq"):
        return problem
    return replace(problem, drawing=stroke.drawing, seq=stroke.seq)


def _detect(body: str) -> WireFormat:
    # '[' too: a JSON array gets "not an object", clearer than a legacy field error.
    return "json" if body[0] in "{[" else "legacy"


def validate_stroke(stroke: Stroke, layout: Layout) -> Stroke | Rejected:
    """Check ``stroke`` against ``layout``: the stroke with its points clamped into the grid,
    or why the sleeve would refuse it. For strokes built in code (planner, simulator)."""
    problem = _first_problem(stroke, layout)
    if problem is not None:
        return problem
    return _clamped(stroke, layout)


def playable(stroke: Stroke, layout: Layout) -> Stroke:
    """``stroke`` with its points clamped into the grid when the sleeve would play what it
    draws (its points, duration and intensity), else StrokeError with the sleeve's reason and
    message. The planner's check: a stroke's drawing, seq and sending time do not change what
    is felt, so they are the protocol's alone."""
    problem = _motion_problem(stroke, layout)
    if problem is not None:
        raise StrokeError(problem.reason, problem.message)
    return _clamped(stroke, layout)


def _clamped(stroke: Stroke, layout: Layout) -> Stroke:
    # As dataclasses.replace makes it, without its look at every field.
    return Stroke(
        _clamp(stroke.start, layout),
        _clamp(stroke.end, layout),
        stroke.duration_ms,
        stroke.intensity,
        stroke.drawing,
        stroke.seq,
        stroke.sent_at_ms,
    )


def format_legacy(stroke: Stroke) -> str:
    """The legacy text ``startX,startY,endX,endY,duration``: at most 4 decimals, no trailing zeros.

    Rounds half away from zero on the exact binary value (what JavaScript's
    ``toFixed`` does). Intensity, drawing, seq and sent_at_ms cannot be carried
    and are dropped. Raises StrokeError for a stroke no sleeve would accept.
    """
    _raise_if_invalid(stroke)
    numbers = (*stroke.start, *stroke.end, stroke.duration_ms)
    return ",".join(_legacy_decimal(value) for value in numbers)


def format_json(stroke: Stroke) -> str:
    """The compact JSON v1 text, keys in wire order, optional fields omitted when None.

    Numbers are written as JavaScript's ``JSON.stringify`` writes them (shortest
    round-trip digits, ``1`` not ``1.0``), so every port produces the same bytes.
    Raises StrokeError for a stroke no sleeve would accept.
    """
    _raise_if_invalid(stroke)
    parts = [f'"v":{JSON_VERSION}']
    for key, value in stroke_to_dict(stroke).items():
        parts.append(f'"{key}":{_json_value(value)}')
    return "{" + ",".join(parts) + "}"


def stroke_to_dict(stroke: Stroke) -> dict[str, Any]:
    """The stroke's JSON v1 fields (without ``v``) in wire order, None fields left out."""
    fields: dict[str, Any] = {
        "drawing": stroke.drawing,
        "seq": stroke.seq,
        "start": [stroke.start[0], stroke.start[1]],
        "end": [stroke.end[0], stroke.end[1]],
        "duration_ms": stroke.duration_ms,
        "intensity": stroke.intensity,
        "sent_at_ms": stroke.sent_at_ms,
    }
    return {key: value for key, value in fields.items() if value is not None}


# --- payload ------------------------------------------------------------------------------


def is_drawing_id(text: str) -> bool:
    """1 to 64 printable ASCII characters without spaces (what ``drawing`` allows)."""
    return _DRAWING_ID.fullmatch(text) is not None


def payload_text(payload: object, *, example: str = _LEGACY_EXAMPLE) -> str | Rejected:
    """The payload as text, or not_text / too_long, checked as every message to the sleeve is
    (the size in UTF-8 bytes, UTF-8, a byte-order mark dropped); ``example`` goes in messages."""
    return _payload_text(payload, example)


def _payload_text(payload: object, example: str = _LEGACY_EXAMPLE) -> str | Rejected:
    """The payload as text, or not_text / too_long. The size counts UTF-8 bytes."""
    if isinstance(payload, str):
        try:
            data = payload.encode("utf-8")
        except UnicodeEncodeError as error:
            return Rejected(
                NOT_TEXT,
                f"The payload text cannot be encoded as UTF-8 (a lone surrogate at character "
                f"{error.start}); send valid Unicode text such as {example}.",
            )
    elif isinstance(payload, (bytes, bytearray, memoryview)):
        data = bytes(payload)
    else:
        # Only the type's name: repr() of an arbitrary object could itself raise.
        kind = "None" if payload is None else f"of type {type(payload).__name__}"
        return Rejected(
            NOT_TEXT,
            f"The payload is {kind}, not text; send a string or UTF-8 bytes such as {example}.",
        )
    if len(data) > MAX_PAYLOAD_BYTES:
        return Rejected(
            TOO_LONG,
            f"The payload is {len(data)} bytes long; the limit is {MAX_PAYLOAD_BYTES} bytes. "
            "Send one stroke per message.",
        )
    if isinstance(payload, str):
        text = payload
    else:
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as error:
            return Rejected(
                NOT_TEXT,
                f"The payload is not UTF-8 text (byte 0x{data[error.start]:02x} at position "
                f"{error.start}); send ASCII such as {example} or UTF-8 JSON.",
            )
    # A byte-order mark is invisible in editors; TextDecoder drops it too.
    return text.removeprefix(_BOM)


# --- legacy -------------------------------------------------------------------------------


def _parse_legacy(body: str) -> Stroke | Rejected:
    fields = body.split(",")
    if len(fields) != len(_LEGACY_FIELDS):
        return Rejected(WRONG_FIELD_COUNT, _field_count_message(body, len(fields)))
    values: list[float] = []
    for index, raw in enumerate(fields):
        value = _legacy_number(raw.strip(_WHITESPACE), index)
        if isinstance(value, Rejected):
            return value
        values.append(value)
    return Stroke(start=(values[0], values[1]), end=(values[2], values[3]), duration_ms=values[4])


def _field_count_message(body: str, count: int) -> str:
    message = (
        f"The legacy payload {_show_text(body)} has {count} comma-separated field(s); it needs "
        f"exactly 5: startX,startY,endX,endY,duration (e.g. {_LEGACY_EXAMPLE})."
    )
    if body.startswith(("{", "[")):
        message += " This looks like JSON: send it with the JSON format (or format auto)."
    elif count == 6:
        message += " To send an intensity, use the JSON format."
    elif count == 1 and (";" in body or " " in body):
        message += " Separate the fields with commas and use '.' as the decimal point."
    elif count > 5 and body.count(",") >= 8:
        message += " Use '.' as the decimal point, not ','."
    return message


def _legacy_number(raw: str, index: int) -> float | Rejected:
    name, field = _LEGACY_FIELDS[index], _LEGACY_STROKE_FIELDS[index]
    where = f"Field {index + 1} ({name}) of the legacy payload"
    if _NON_FINITE_WORD.fullmatch(raw):
        return Rejected(
            NOT_FINITE,
            f"{where} is {_show_text(raw)}, which is not a finite number; "
            "coordinates and the duration must be finite decimal numbers.",
            field,
        )
    if not _DECIMAL.fullmatch(raw):
        shown = "empty" if not raw else _show_text(raw)
        return Rejected(
            NOT_A_NUMBER,
            f"{where} is {shown}, which is not a decimal number; write digits with '.' as the "
            "decimal point, e.g. 420.5.",
            field,
        )
    value = float(raw)
    if math.isinf(value):
        return Rejected(
            NOT_FINITE,
            f"{where} is {_show_text(raw)}, which is too large to be a finite number; "
            "coordinates are grid units and the duration milliseconds.",
            field,
        )
    return value


# --- JSON ---------------------------------------------------------------------------------


class _NonFiniteLiteral(ValueError):
    """Python's json reads NaN and Infinity, which are not JSON (RFC 8259) nor JSON.parse's."""


def _reject_constant(name: str) -> float:
    raise _NonFiniteLiteral(name)


# Made once: json.loads(parse_constant=...) builds a decoder for every message.
_DECODER = json.JSONDecoder(parse_constant=_reject_constant)


# The C scanner that decode() calls, after two regex matches (not in the typeshed stubs).
_SCAN: Callable[[str, int], tuple[Any, int]] = _DECODER.scan_once  # type: ignore[attr-defined]


def _loads(body: str) -> Any:
    """``json.loads(body, parse_constant=_reject_constant)``, with the same errors.

    A document that is one value from its first character to its last (the payload comes
    stripped of whitespace) is read by the decoder's scanner directly, without the two Python
    frames and two regex matches of ``decode``; anything else (whitespace, trailing data, an
    error) goes through ``decode`` or ``json.loads``, which say what is wrong."""
    if body.startswith("\ufeff"):
        return json.loads(body, parse_constant=_reject_constant)  # its byte-order-mark error
    try:
        document, end = _SCAN(body, 0)
    except Exception:  # decode() below raises it again, as json.loads does
        end = -1
    if end != len(body):
        return _DECODER.decode(body)
    return document


def _parse_json(body: str, layout: Layout | None = None) -> Stroke | Accepted | Rejected:
    """The stroke of a JSON payload, or why not; with ``layout``, a stroke plainly valid on its
    grid comes back already ``Accepted`` (see ``_plain_json``)."""
    try:
        document = _loads(body)
    except _NonFiniteLiteral as error:
        return Rejected(
            INVALID_JSON,
            f"The payload is not valid JSON: {error} is not a JSON number; "
            "send finite numbers only.",
        )
    except (ValueError, RecursionError) as error:
        return Rejected(
            INVALID_JSON,
            f"The payload is not valid JSON ({_json_error_text(error)}); "
            f"check quotes, commas and brackets, e.g. {_JSON_EXAMPLE}.",
        )
    if not isinstance(document, dict):
        return Rejected(
            NOT_AN_OBJECT,
            f"The JSON payload is {_described(document)}, not an object; send an object "
            f"such as {_JSON_EXAMPLE}.",
        )
    if layout is not None:
        plain = _plain_json(document, layout)
        if plain is not None:
            return Accepted(plain, "json")
    return _stroke_from_object(document)


_NUMBER_TYPES = (int, float)  # exactly these: bool, an int subclass, is not a JSON number


def _plain_json(document: dict[str, Any], layout: Layout) -> Stroke | None:
    """The stroke of ``document`` when it is plainly valid on ``layout``'s grid, else None.

    Plainly valid: version 1, every field of the type the protocol asks (numbers read as
    int or float, never bool), each value inside its range with no clamping to do (points
    on the grid itself, not within its tolerance outside). Such a stroke is what reading it
    field by field, checking it and clamping it would give, in a few comparisons: it is
    read on the path from a stroke's message to its first motor command. Anything else
    (None) goes the long way, which says what is wrong.
    """
    get = document.get
    version = get("v")
    if type(version) is not int or version != JSON_VERSION:
        return None
    drawing = get("drawing")
    if drawing is not None and (type(drawing) is not str or not _DRAWING_ID.fullmatch(drawing)):
        return None
    seq = get("seq")
    if seq is not None and (type(seq) is not int or not 0 <= seq <= MAX_SEQ):
        return None
    start, end = get("start"), get("end")
    duration_ms: Any = get("duration_ms")  # checked below to be a number
    if type(start) is not list or type(end) is not list or len(start) != 2 or len(end) != 2:
        return None
    (x0, y0), (x1, y1) = start, end
    numbers = _NUMBER_TYPES
    if not (
        type(x0) in numbers
        and type(y0) in numbers
        and type(x1) in numbers
        and type(y1) in numbers
        and type(duration_ms) in numbers
    ):
        return None
    x_max, y_max = layout.columns - 1, layout.rows - 1
    # Comparisons fail for NaN, so these also say every number is finite (and an int this
    # small converts exactly as _to_float converts it).
    if not (
        0 <= x0 <= x_max
        and 0 <= x1 <= x_max
        and 0 <= y0 <= y_max
        and 0 <= y1 <= y_max
        and 0 < duration_ms < math.inf
        and duration_ms <= layout.max_stroke_duration_ms
    ):
        return None
    intensity = get("intensity")
    if intensity is not None:
        if type(intensity) not in numbers or not 0 <= intensity <= 1:
            return None
        intensity = float(intensity)
    sent_at_ms = get("sent_at_ms")
    if sent_at_ms is not None:
        if type(sent_at_ms) not in numbers or not 0 <= sent_at_ms <= MAX_SENT_AT_MS:
            return None
        sent_at_ms = float(sent_at_ms)
    # As _clamp leaves a point inside the grid: a float, -0.0 made 0.0.
    return Stroke(
        (float(x0) + 0.0, float(y0) + 0.0),
        (float(x1) + 0.0, float(y1) + 0.0),
        float(duration_ms),
        intensity,
        drawing,
        seq,
        sent_at_ms,
    )


def _json_error_text(error: Exception) -> str:
    if isinstance(error, json.JSONDecodeError):
        # Some of Python's messages end in "at" already ("Invalid control character at").
        what = error.msg.removesuffix(" at")
        return f"{what} at line {error.lineno}, column {error.colno}"
    if isinstance(error, RecursionError):
        return "nested too deeply"
    return str(error)[:SHOWN_VALUE_CHARS]


def _stroke_from_object(document: dict[str, Any]) -> Stroke | Rejected:
    if "v" not in document:
        return Rejected(MISSING_FIELD, _missing_message("v", document), "v")
    try:
        # The version before the other fields: another version may need other fields,
        # so "no start" would send its sender looking for the wrong problem.
        _check_version(document["v"])
        for key in ("start", "end", "duration_ms"):
            if key not in document:
                return Rejected(MISSING_FIELD, _missing_message(key, document), key)
        # Read in wire order, so the first problem reported is the same in every port.
        drawing = _read_drawing(document.get("drawing"))
        seq = _read_seq(document.get("seq"))
        start = _read_point(document["start"], "start")
        end = _read_point(document["end"], "end")
        duration_ms = _read_number(document["duration_ms"], "duration_ms")
        intensity = _read_optional_number(document.get("intensity"), "intensity")
        sent_at_ms = _read_optional_number(document.get("sent_at_ms"), "sent_at_ms")
    except _Reject as reject:
        return reject.rejected
    return Stroke(start, end, duration_ms, intensity, drawing, seq, sent_at_ms)


class _Reject(Exception):
    """Carries a Rejected out of the nested JSON readers; never escapes ``parse``."""

    def __init__(self, rejected: Rejected) -> None:
        super().__init__(rejected.message)
        self.rejected = rejected


def _missing_message(key: str, document: dict[str, Any]) -> str:
    message = (
        f'The JSON message has no "{key}"; the required fields are v, start, end and '
        f"duration_ms, e.g. {_JSON_EXAMPLE}."
    )
    # A typo or a unit left out ("duration" for "duration_ms") deserves a hint.
    near = difflib.get_close_matches(key, [k for k in document if k != key], n=1, cutoff=0.6)
    if near:
        message += f' Found {_show_text(near[0])}: did you mean "{key}"?'
    return message


def _check_version(value: Any) -> None:
    if not _is_number(value):
        raise _wrong_type("v", value, f"the number {JSON_VERSION}")
    if _to_float(value) != JSON_VERSION:
        raise _Reject(
            Rejected(
                UNKNOWN_VERSION,
                f'"v" is {_show_json(value)}; this sleeve understands only version '
                f'{JSON_VERSION}. Send "v":{JSON_VERSION}, or update the sleeve.',
                "v",
            )
        )


def _read_drawing(value: Any) -> str | None:
    if value is None or isinstance(value, str):
        return value
    raise _wrong_type("drawing", value, "a string such as a UUID, or left out")


def _read_seq(value: Any) -> int | None:
    if value is None:
        return None
    # 3.0 counts as an integer: JavaScript cannot tell 3.0 from 3.
    if _is_number(value) and (isinstance(value, int) or float(value).is_integer()):
        return int(value)
    raise _wrong_type("seq", value, f"a whole number from 0 to {MAX_SEQ}, or left out")


def _read_point(value: Any, key: str) -> Point:
    if isinstance(value, list) and len(value) == 2 and all(_is_number(v) for v in value):
        return (_to_float(value[0]), _to_float(value[1]))
    raise _wrong_type(key, value, "an array of two numbers [x, y] in grid units")


def _read_number(value: Any, key: str) -> float:
    if _is_number(value):
        return _to_float(value)
    raise _wrong_type(key, value, "a number")


def _read_optional_number(value: Any, key: str) -> float | None:
    # null for an optional field means "not given", as if the key were absent.
    return None if value is None else _read_number(value, key)


def _wrong_type(key: str, value: Any, expected: str) -> _Reject:
    return _Reject(
        Rejected(
            WRONG_TYPE,
            f'"{key}" is {_described(value)}; it must be {expected}.',
            key,
        )
    )


def _is_number(value: Any) -> bool:
    # bool is an int in Python, but true is not a number in JSON.
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _to_float(value: int | float) -> float:
    try:
        return float(value)
    except OverflowError:  # an integer with hundreds of digits
        return math.inf if value > 0 else -math.inf


def json_kind(value: Any) -> str:
    """What a JSON value is, in JSON's words ("null", "an array"...), for error messages."""
    kinds = {dict: "an object", list: "an array", str: "a string", bool: "a boolean"}
    if value is None:
        return "null"
    return kinds.get(type(value), "a number")


# --- values -------------------------------------------------------------------------------


def _first_problem(stroke: Stroke, layout: Layout | None) -> Rejected | None:
    """The first problem in wire order; grid and duration cap only checked with a layout."""
    checks = (
        _check_drawing(stroke.drawing),
        _check_seq(stroke.seq),
        _motion_problem(stroke, layout),
        _check_sent_at(stroke.sent_at_ms),
    )
    return next((problem for problem in checks if problem is not None), None)


def _motion_problem(stroke: Stroke, layout: Layout | None) -> Rejected | None:
    """The first problem with what the stroke draws: its points, duration and intensity."""
    return (
        _check_point(stroke.start, "start", layout)
        or _check_point(stroke.end, "end", layout)
        or _check_duration(stroke.duration_ms, layout)
        or _check_intensity(stroke.intensity)
    )


def _check_drawing(drawing: str | None) -> Rejected | None:
    if drawing is None or _DRAWING_ID.fullmatch(drawing):
        return None
    return Rejected(
        BAD_DRAWING_ID,
        f'"drawing" is {_show_text(drawing)} ({len(drawing)} characters); it must be 1 to '
        f"{MAX_DRAWING_ID_CHARS} printable ASCII characters without spaces (a UUID works), "
        "or left out.",
        "drawing",
    )


def _check_seq(seq: int | None) -> Rejected | None:
    if seq is None or 0 <= seq <= MAX_SEQ:
        return None
    return Rejected(
        SEQ_OUT_OF_RANGE,
        f'"seq" is {_cut(str(seq))}; it must be a whole number from 0 to {MAX_SEQ} '
        "(count the strokes of a drawing from 0).",
        "seq",
    )


def _check_point(point: Point, key: str, layout: Layout | None) -> Rejected | None:
    x, y = point
    if not (math.isfinite(x) and math.isfinite(y)):
        return Rejected(
            NOT_FINITE,
            f"{key} ({_number(x)}, {_number(y)}) is not a finite point; coordinates must be "
            "finite numbers in grid units.",
            key,
        )
    if layout is None or (_inside(x, layout.columns) and _inside(y, layout.rows)):
        return None
    return Rejected(
        OUTSIDE_GRID,
        f"{key} ({_number(x)}, {_number(y)}) is outside the {layout.rows}-row x "
        f"{layout.columns}-column grid: x must be in 0..{layout.columns - 1} and y in "
        f"0..{layout.rows - 1} (grid units, counted from 0 at the first actuator); "
        "scale the drawing to the sleeve's grid.",
        key,
    )


def _inside(value: float, count: int) -> bool:
    return -GRID_TOLERANCE <= value <= count - 1 + GRID_TOLERANCE


def _check_duration(duration_ms: float, layout: Layout | None) -> Rejected | None:
    capped = layout is not None and duration_ms > layout.max_stroke_duration_ms
    if math.isfinite(duration_ms) and duration_ms > 0 and not capped:
        return None  # before the messages below: formatting them costs a stroke's parse
    allowed = "more than 0 ms"
    if layout is not None:
        allowed += f" and at most {_number(layout.max_stroke_duration_ms)} ms"
    if not math.isfinite(duration_ms):
        return Rejected(
            NOT_FINITE,
            f"duration_ms is {_number(duration_ms)}; it must be a finite number of "
            f"milliseconds, {allowed}.",
            "duration_ms",
        )
    if duration_ms <= 0:
        return Rejected(
            DURATION_NOT_POSITIVE,
            f"duration_ms is {_number(duration_ms)}; a stroke must last {allowed}.",
            "duration_ms",
        )
    if layout is not None and duration_ms > layout.max_stroke_duration_ms:
        return Rejected(
            DURATION_TOO_LONG,
            f"duration_ms is {_number(duration_ms)}; this sleeve plays strokes of at most "
            f"{_number(layout.max_stroke_duration_ms)} ms. Split the stroke into shorter ones.",
            "duration_ms",
        )
    return None


def _check_intensity(intensity: float | None) -> Rejected | None:
    if intensity is None:
        return None
    if not math.isfinite(intensity):
        return Rejected(
            NOT_FINITE,
            f"intensity is {_number(intensity)}; it must be a finite number from 0 to 1.",
            "intensity",
        )
    if 0 <= intensity <= 1:
        return None
    return Rejected(
        INTENSITY_OUT_OF_RANGE,
        f"intensity is {_number(intensity)}; it must be from 0 (off) to 1 (strongest), or "
        "left out for the sleeve's default.",
        "intensity",
    )


def _check_sent_at(sent_at_ms: float | None) -> Rejected | None:
    if sent_at_ms is None:
        return None
    if not math.isfinite(sent_at_ms):
        return Rejected(
            NOT_FINITE,
            f"sent_at_ms is {_number(sent_at_ms)}; it must be a finite time in milliseconds.",
            "sent_at_ms",
        )
    if 0 <= sent_at_ms <= MAX_SENT_AT_MS:
        return None
    if sent_at_ms > MAX_SENT_AT_MS:
        return Rejected(
            SENT_AT_OUT_OF_RANGE,
            f"sent_at_ms is {_number(sent_at_ms)}; it must be the sender's clock in "
            f"milliseconds since 1970-01-01 UTC, from 0 to {_number(MAX_SENT_AT_MS)} (the year "
            "2286): check the sender's clock, or leave it out.",
            "sent_at_ms",
        )
    return Rejected(
        SENT_AT_OUT_OF_RANGE,
        f"sent_at_ms is {_number(sent_at_ms)}; it must be the sender's clock in milliseconds "
        "since 1970-01-01 UTC (0 or more), or left out.",
        "sent_at_ms",
    )


def _clamp(point: Point, layout: Layout) -> Point:
    # "+ 0.0" turns -0.0 into 0.0, so -0 never reaches a formatter.
    x = min(max(point[0], 0.0), layout.columns - 1) + 0.0
    y = min(max(point[1], 0.0), layout.rows - 1) + 0.0
    return (float(x), float(y))


def _raise_if_invalid(stroke: Stroke) -> None:
    problem = _first_problem(stroke, None)
    if problem is not None:
        raise StrokeError(problem.reason, problem.message)


# --- text ---------------------------------------------------------------------------------


def _legacy_decimal(value: float) -> str:
    rounded = Decimal(value).quantize(_LEGACY_QUANTUM, rounding=ROUND_HALF_UP, context=_EXACT)
    text = f"{rounded:f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def _json_value(value: Any) -> str:
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ",".join(_json_value(item) for item in value) + "]"
    if isinstance(value, int):
        return str(value)
    return _number(float(value))


def _number(value: float) -> str:
    """``value`` as ECMAScript's Number::toString writes it: shortest digits, no '.0'."""
    if math.isnan(value):
        return "NaN"
    if math.isinf(value):
        return "Infinity" if value > 0 else "-Infinity"
    if value == 0:
        return "0"
    if value < 0:
        return "-" + _number(-value)
    decimal = Decimal(repr(value)).as_tuple()
    digits = "".join(map(str, decimal.digits)).rstrip("0")
    exponent = int(decimal.exponent)
    point = exponent + len(decimal.digits)  # digits d1d2.. stand for 0.d1d2.. x 10**point
    count = len(digits)
    if count <= point <= 21:
        return digits + "0" * (point - count)
    if 0 < point <= 21:
        return f"{digits[:point]}.{digits[point:]}"
    if -6 < point <= 0:
        return "0." + "0" * -point + digits
    power = point - 1
    mantissa = digits if count == 1 else f"{digits[0]}.{digits[1:]}"
    return f"{mantissa}e{'+' if power >= 0 else '-'}{abs(power)}"


def _cut(text: str) -> str:
    """``text`` cut to SHOWN_VALUE_CHARS characters, so a message stays one readable line."""
    return text if len(text) <= SHOWN_VALUE_CHARS else text[:SHOWN_VALUE_CHARS] + "..."


def _show_text(text: str) -> str:
    """``text`` quoted for a message, cut, control characters escaped."""
    if len(text) <= SHOWN_VALUE_CHARS:
        return json.dumps(text, ensure_ascii=False)
    return json.dumps(text[:SHOWN_VALUE_CHARS], ensure_ascii=False) + "..."


def _described(value: Any) -> str:
    """A JSON value and its kind, for wrong_type messages: '"0,0" (a string)'."""
    return "null" if value is None else f"{_show_json(value)} ({json_kind(value)})"


def _show_json(value: Any) -> str:
    try:
        shown = json.dumps(value, ensure_ascii=False)
    except (ValueError, RecursionError):  # deeper than the decoder allowed from here
        return json_kind(value)
    return _cut(shown)
