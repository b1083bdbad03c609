"""Vectors for the stroke protocol: parsing, validation and formatting.

Three groups, one file per case (docs/protocol.md, "Test vectors", says how to read them):

- ``valid/<name>.json``: a payload the sleeve accepts, with the stroke it reads;
- ``invalid/<name>.json``: a payload it rejects, with the reason code and field;
- ``format/<name>.json``: a stroke and the exact legacy and JSON v1 texts for it.

Every expected value is computed here by feelmysign.protocol; the case lists only
say what to feed it. Each parse case also names the outcome it is meant to show,
and generation stops if the reference disagrees, so a change in behaviour is
never written silently.
"""

from __future__ import annotations

import base64
from dataclasses import dataclass
from typing import Any

from feelmysign.layout import Layout
from feelmysign.protocol import (
    REASONS,
    Accepted,
    Format,
    format_json,
    format_legacy,
    parse,
)
from feelmysign.stroke import Stroke

# Only the limits validation uses; a port builds its layout from these.
PAPER = {"rows": 3, "columns": 4, "max_stroke_duration_ms": 10000.0}
LRA = {"rows": 4, "columns": 6, "max_stroke_duration_ms": 8000.0}
ACCEPTED = "accepted"

START = '"start":[0,0]'
END = '"end":[2,0]'
DUR = '"duration_ms":1000'


@dataclass(frozen=True)
class Case:
    name: str
    description: str
    payload: Any  # what parse() receives: str, bytes or another Python value
    outcome: str  # ACCEPTED or the reason code this case is meant to show
    layout: dict[str, float] | None = None
    format: Format = "auto"


def expect(outcome: str, *rows: tuple[str, str, Any], **options: Any) -> list[Case]:
    """Cases meant to show one ``outcome``, from (name, description, payload) rows; ``options``
    (``layout``, ``format``) apply to each of them."""
    return [
        Case(name, description, payload, outcome, **options) for name, description, payload in rows
    ]


def js(*fields: str) -> str:
    """A JSON v1 object from ``"key":value`` parts, written compactly."""
    return "{" + ",".join(['"v":1', *fields]) + "}"


def minimal(*extra: str) -> str:
    return js(START, END, DUR, *extra)


def valid_cases() -> list[Case]:
    full = js(
        '"drawing":"6f1c2a9e-3b7d-4c55-9a1e-2f0b8d4c7e31"',
        '"seq":3',
        '"start":[0.5,1.0]',
        '"end":[2.0,1.5]',
        '"duration_ms":420',
        '"intensity":0.8',
        '"sent_at_ms":1732280000123',
    )
    pretty = '{\n  "v": 1,\n  "start": [0, 0],\n  "end": [3, 2],\n  "duration_ms": 800\n}\n'
    unknown = js(START, END, DUR, '"colour":"red"', '"extra":{"nested":[1,2,{"a":null}]}')
    nulls = js(START, END, DUR, '"drawing":null', '"seq":null', '"intensity":null')
    return [
        *expect(
            ACCEPTED,
            ("legacy-integers", "the simplest legacy stroke", "0,0,2,0,1000"),
            ("legacy-decimals", "decimals as senders write them", "0.5,1.25,3,2,420.5"),
            ("legacy-corner-to-corner", "both extreme corners", "0,0,3,2,1000"),
            ("legacy-reverse", "right to left, bottom to top", "3,2,0,0,250"),
            ("legacy-point", "start = end: a tap", "1,1,1,1,300"),
            ("legacy-whitespace", "whitespace around the payload", " 0,0,2,0,1000\r\n"),
            ("legacy-field-spaces", "spaces around fields", "0, 0 ,2,\t0, 1000"),
            ("legacy-sign-exponent", "plus sign and exponents", "+1,0,2e0,0,1.5E3"),
            ("legacy-bare-points", "'.5' and '1.' are numbers", ".5,1.,2,0,100"),
            ("legacy-negative-zero", "-0 is read as 0", "-0,-0.0,2,0,100"),
            (
                "legacy-tolerance-high",
                "within 1e-9 above the grid: clamped to the edge",
                "3.0000000001,2.0000000005,0,0,100",
            ),
            (
                "legacy-tolerance-low",
                "within 1e-9 below 0: clamped to 0",
                "-0.0000000001,0,0,-1e-10,100",
            ),
            ("legacy-max-duration", "exactly the maximum duration", "0,0,2,0,10000"),
            ("legacy-tiny-duration", "a tiny positive duration", "0,0,2,0,0.0001"),
            (
                "legacy-many-decimals",
                "more decimals than senders write: read in full",
                "0.123456789,1.99999,2.5,0.3333333333333333,123.456789",
            ),
            ("legacy-bytes", "bytes, as MQTT delivers them", b"0,0,2,0,1000"),
            ("legacy-bom", "a UTF-8 byte-order mark is dropped", b"\xef\xbb\xbf1,1,2,2,500"),
        ),
        *expect(
            ACCEPTED,
            ("legacy-forced", "format=legacy", "0,1,3,1,900"),
            format="legacy",
        ),
        *expect(
            ACCEPTED,
            ("legacy-larger-grid", "a 4 x 6 sleeve", "5,3,0,0,8000"),
            layout=LRA,
        ),
        *expect(
            ACCEPTED,
            ("json-full", "every field of JSON v1", full),
            ("json-minimal", "only the required fields", minimal()),
            (
                "json-sent-at-latest",
                "sent_at_ms exactly 1e13 (the year 2286), the latest",
                minimal('"sent_at_ms":10000000000000'),
            ),
            ("json-pretty", "indented over several lines", pretty),
            ("json-unknown-keys", "unknown keys are ignored", unknown),
            ("json-null-optionals", "null optional fields = absent", nulls),
            (
                "json-integral-floats",
                "1.0 and 3.0 are integers (JavaScript cannot tell them apart)",
                js('"v":1.0', '"seq":3.0', START, END, DUR),
            ),
            ("json-intensity-zero", "intensity 0 (off)", minimal('"intensity":0')),
            ("json-intensity-one", "intensity 1", minimal('"intensity":1')),
            (
                "json-tolerance",
                "within 1e-9 of the grid: clamped",
                js('"start":[3.0000000001,-1e-10]', END, DUR),
            ),
            (
                "json-duplicate-key",
                "a repeated key: the last one counts, as in JSON.parse",
                js('"start":[9,9]', START, END, DUR),
            ),
            ("json-seq-max", "the largest seq", minimal('"seq":9007199254740991')),
            ("json-drawing-64", "a 64-character drawing id", minimal(f'"drawing":"{"d" * 64}"')),
            (
                "json-escaped-drawing",
                "JSON escapes in the drawing id",
                minimal('"drawing":"a\\u002db\\"c\\\\"'),
            ),
            (
                "json-utf8-bytes",
                "UTF-8 bytes with non-ASCII text in an ignored key",
                minimal('"note":"héllo ✍"').encode("utf-8"),
            ),
        ),
        *expect(
            ACCEPTED,
            ("json-forced", "format=json with leading whitespace", "\n " + minimal()),
            format="json",
        ),
        *expect(
            ACCEPTED,
            ("json-larger-grid", "a 4 x 6 sleeve", js('"start":[5,3]', END, DUR)),
            layout=LRA,
        ),
    ]


def payload_cases() -> list[Case]:
    """Rejected before any format is chosen: type, size, encoding, emptiness."""
    return [
        *expect(
            "not_text",
            ("not-text-invalid-utf8", "bytes that are not UTF-8", b"\xff\xfe0,0"),
            ("not-text-latin1", "Latin-1 bytes", b"0,0,2,0,1000 \xe9"),
            ("not-text-overlong", "an overlong UTF-8 sequence", b"\xc0\xaf"),
            ("not-text-truncated-utf8", "a cut UTF-8 sequence", b"0,0,2,0,1\xe2\x82"),
            ("not-text-null", "null instead of text", None),
            ("not-text-number", "a number instead of text", 5),
            ("not-text-list", "a list instead of text", [0, 0, 2, 0, 1000]),
            (
                "not-text-object",
                "an already-parsed object instead of text",
                {"v": 1, "start": [0, 0], "end": [2, 0], "duration_ms": 1000},
            ),
        ),
        *expect(
            "too_long",
            ("too-long-legacy", "513 bytes", "0,0,2,0," + "1" * 505),
            ("too-long-multibyte", "257 characters, 514 UTF-8 bytes", "é" * 257),
            ("too-long-whitespace", "600 spaces: size is checked first", " " * 600),
            ("too-long-json", "padded JSON", minimal(f'"pad":"{"x" * 480}"')),
        ),
        *expect(
            "empty",
            ("empty-string", "nothing", ""),
            ("empty-whitespace", "only whitespace", " \t\r\n "),
            ("empty-bytes", "no bytes", b""),
            ("empty-bom", "only a byte-order mark", b"\xef\xbb\xbf"),
        ),
    ]


def legacy_cases() -> list[Case]:
    return [
        *expect(
            "wrong_field_count",
            ("four-fields", "no duration", "0,0,2,0"),
            ("six-fields", "an intensity appended", "0,0,2,0,1000,0.8"),
            ("trailing-comma", "a sixth, empty field", "0,0,2,0,1000,"),
            ("semicolons", "';' as separator", "0;0;2;0;1000"),
            ("space-separated", "spaces as separator", "0 0 2 0 1000"),
            ("decimal-commas", "',' as decimal point", "0,5,1,0,2,0,1,0,1000"),
        ),
        *expect(
            "wrong_field_count",
            ("json-as-legacy", "JSON with format=legacy", minimal()),
            format="legacy",
        ),
        *expect(
            "not_a_number",
            ("letters", "a word", "a,0,2,0,1000"),
            ("empty-field", "nothing between commas", "0,,2,0,1000"),
            ("underscore", "'1_000' (Python's float() takes it)", "0,0,2,0,1_000"),
            ("unit-suffix", "a unit after the number", "0,0,2,0,1000ms"),
            ("hex", "a hexadecimal number", "0x1,0,2,0,1000"),
            ("arabic-digits", "non-ASCII digits", "0,0,2,0,١٠٠٠"),
            ("fullwidth-digits", "fullwidth digits", "０,0,2,0,1000"),
            ("double-point", "two decimal points", "1..2,0,2,0,1000"),
            ("bare-exponent", "an exponent without digits", "1e,0,2,0,1000"),
            ("bare-sign", "a sign alone", "-,0,2,0,1000"),
            ("inner-space", "a space inside a number", "1 0,0,2,0,1000"),
        ),
        *expect(
            "not_finite",
            ("nan", "NaN", "nan,0,2,0,1000"),
            ("inf", "inf", "0,0,2,0,inf"),
            ("infinity", "-Infinity", "0,-Infinity,2,0,1000"),
            ("overflow", "too large for a double", "1e999,0,2,0,1000"),
        ),
    ]


def json_syntax_cases() -> list[Case]:
    return [
        *expect(
            "invalid_json",
            ("json-truncated", "cut short", '{"v":1,"start":[0,0]'),
            ("json-open-brace", "a lone brace", "{"),
            ("json-trailing-comma", "a trailing comma", minimal()[:-1] + ",}"),
            ("json-nan-literal", "NaN is not JSON", js('"start":[NaN,0]', END, DUR)),
            (
                "json-infinity-literal",
                "Infinity is not JSON",
                js(START, END, '"duration_ms":Infinity'),
            ),
            ("json-single-quotes", "single quotes", "{'v':1}"),
            ("json-unquoted-keys", "unquoted keys", "{v:1}"),
            ("json-comment", "a comment", '{"v":1 /* one */}'),
            ("json-extra-data", "text after the object", minimal() + " 0,0,2,0,1000"),
            ("json-two-objects", "two objects", minimal() + minimal()),
            (
                "json-control-character",
                "a raw control character in a string",
                minimal('"drawing":"a\tb"'),
            ),
        ),
        *expect(
            "invalid_json",
            ("legacy-as-json", "legacy text, format=json", "0,0,2,0,1000"),
            format="json",
        ),
        *expect(
            "not_an_object",
            ("json-array", "a JSON array", "[0,0,2,0,1000]"),
        ),
        *expect(
            "not_an_object",
            ("json-string", "a JSON string", '"0,0,2,0,1000"'),
            ("json-number", "a JSON number", "42"),
            ("json-null", "JSON null", "null"),
            ("json-true", "JSON true", "true"),
            format="json",
        ),
    ]


def json_field_cases() -> list[Case]:
    return [
        *expect(
            "missing_field",
            ("missing-v", "no version", '{"start":[0,0],"end":[2,0],"duration_ms":1}'),
            ("missing-start", "no start", js(END, DUR)),
            ("missing-end", "no end", js(START, DUR)),
            ("missing-duration", "'duration' for 'duration_ms'", js(START, END, '"duration":5')),
            ("missing-everything", "an empty object", "{}"),
        ),
        *expect(
            "unknown_version",
            ("version-2", "a future version", minimal().replace('"v":1', '"v":2')),
            ("version-0", "version 0", minimal().replace('"v":1', '"v":0')),
            ("version-fraction", "version 1.5", minimal().replace('"v":1', '"v":1.5')),
        ),
        *expect(
            "wrong_type",
            ("version-string", 'v "1"', minimal().replace('"v":1', '"v":"1"')),
            ("version-boolean", "v true", minimal().replace('"v":1', '"v":true')),
            ("version-null", "v null", minimal().replace('"v":1', '"v":null')),
            ("start-string", 'start "0,0"', js('"start":"0,0"', END, DUR)),
            ("start-one-number", "start [0]", js('"start":[0]', END, DUR)),
            ("start-three-numbers", "start [0,0,0]", js('"start":[0,0,0]', END, DUR)),
            ("start-boolean", "true is not a number", js('"start":[true,0]', END, DUR)),
            ("start-nested", "start [[0],0]", js('"start":[[0],0]', END, DUR)),
            ("start-object", 'start {"x":0,"y":0}', js('"start":{"x":0,"y":0}', END, DUR)),
            ("start-null", "a required field null", js('"start":null', END, DUR)),
            ("end-number", "end 2", js(START, '"end":2', DUR)),
            ("duration-string", 'duration_ms "1000"', js(START, END, '"duration_ms":"1000"')),
            ("duration-boolean", "duration_ms true", js(START, END, '"duration_ms":true')),
            ("duration-null", "duration_ms null", js(START, END, '"duration_ms":null')),
            ("intensity-string", 'intensity "high"', minimal('"intensity":"high"')),
            ("intensity-boolean", "intensity false", minimal('"intensity":false')),
            ("seq-fraction", "seq 1.5", minimal('"seq":1.5')),
            ("seq-string", 'seq "3"', minimal('"seq":"3"')),
            ("seq-boolean", "seq true", minimal('"seq":true')),
            ("drawing-number", "drawing 5", minimal('"drawing":5')),
            ("sent-at-string", 'sent_at_ms "now"', minimal('"sent_at_ms":"now"')),
        ),
    ]


def json_value_cases() -> list[Case]:
    return [
        *expect(
            "bad_drawing_id",
            ("drawing-empty", "an empty drawing id", minimal('"drawing":""')),
            ("drawing-65", "65 characters", minimal(f'"drawing":"{"d" * 65}"')),
            ("drawing-space", "a space", minimal('"drawing":"my drawing"')),
            ("drawing-non-ascii", "non-ASCII", minimal('"drawing":"dessin-é"')),
            ("drawing-control", "an escaped control character", minimal('"drawing":"a\\u0001"')),
        ),
        *expect(
            "seq_out_of_range",
            ("seq-negative", "seq -1", minimal('"seq":-1')),
            ("seq-too-large", "seq 2^53", minimal('"seq":9007199254740992')),
            ("seq-huge-float", "seq 1e300", minimal('"seq":1e300')),
        ),
        *expect(
            "not_finite",
            ("json-overflow-point", "1e400 in start", js('"start":[1e400,0]', END, DUR)),
            (
                "json-overflow-integer",
                "a 400-digit duration",
                js(START, END, '"duration_ms":' + "9" * 400),
            ),
            ("json-overflow-intensity", "intensity 1e999", minimal('"intensity":1e999')),
            ("json-overflow-sent-at", "sent_at_ms -1e999", minimal('"sent_at_ms":-1e999')),
        ),
        *expect(
            "intensity_out_of_range",
            ("intensity-above", "intensity 1.2", minimal('"intensity":1.2')),
            ("intensity-below", "intensity -0.1", minimal('"intensity":-0.1')),
            ("intensity-barely-above", "intensity 1.0000001", minimal('"intensity":1.0000001')),
        ),
        *expect(
            "sent_at_out_of_range",
            ("sent-at-negative", "sent_at_ms -1", minimal('"sent_at_ms":-1')),
            ("sent-at-far-future", "sent_at_ms 1e300", minimal('"sent_at_ms":1e300')),
            (
                "sent-at-after-2286",
                "sent_at_ms 1 ms above 1e13",
                minimal('"sent_at_ms":10000000000001'),
            ),
        ),
    ]


def grid_cases() -> list[Case]:
    return [
        *expect(
            "outside_grid",
            ("x-equals-columns", "x = 4 on 4 columns (off by one)", "4,0,2,0,1000"),
            ("y-equals-rows", "y = 3 on 3 rows", "0,3,2,0,1000"),
            ("negative-x", "x = -0.5", "-0.5,0,2,0,1000"),
            ("end-outside", "end x = 3.0001", "0,0,3.0001,0,1000"),
            ("beyond-tolerance", "2e-9 beyond the edge", "3.000000002,0,0,0,1000"),
            ("json-end-outside", "end [0,-1]", js(START, '"end":[0,-1]', DUR)),
        ),
        *expect(
            "outside_grid",
            ("larger-grid-outside", "x = 6 on a 4 x 6 sleeve", "6,0,0,0,1000"),
            layout=LRA,
        ),
        *expect(
            "duration_not_positive",
            ("duration-zero", "duration 0", "0,0,2,0,0"),
            ("duration-negative", "duration -5", "0,0,2,0,-5"),
            ("duration-negative-zero", "duration -0", "0,0,2,0,-0"),
            ("duration-underflow", "1e-400 is 0 as a double", "0,0,2,0,1e-400"),
            ("json-duration-zero", "duration_ms 0", js(START, END, '"duration_ms":0')),
        ),
        *expect(
            "duration_too_long",
            ("duration-just-over", "10000.0001 ms", "0,0,2,0,10000.0001"),
            ("json-duration-minute", "a minute", js(START, END, '"duration_ms":60000')),
        ),
        *expect(
            "duration_too_long",
            ("larger-grid-too-long", "8000.5 ms, cap 8000", "0,0,2,0,8000.5"),
            layout=LRA,
        ),
    ]


def order_cases() -> list[Case]:
    """Several problems at once: the first in the documented order is reported."""
    return [
        Case(
            "order-count-before-numbers",
            "four fields, one not a number",
            "a,0,2,0",
            "wrong_field_count",
        ),
        Case(
            "order-left-to-right",
            "field 2 and field 5 bad",
            "0,x,2,0,inf",
            "not_a_number",
        ),
        Case(
            "order-version-before-missing",
            "v 2 and no duration_ms: the version first, another version may need other fields",
            '{"v":2,"start":[0,0],"end":[1,0]}',
            "unknown_version",
        ),
        Case(
            "order-missing-version-first",
            "no v and no start",
            '{"end":[1,0],"duration_ms":100}',
            "missing_field",
        ),
        Case("order-version-only", "only a future version", '{"v":2}', "unknown_version"),
        Case(
            "order-types-before-values",
            "start outside the grid and seq a string",
            js('"start":[9,9]', END, DUR, '"seq":"x"'),
            "wrong_type",
        ),
        Case(
            "order-drawing-first",
            "bad drawing id and start outside",
            js('"start":[9,9]', END, DUR, '"drawing":""'),
            "bad_drawing_id",
        ),
        Case(
            "order-grid-before-duration",
            "start outside and duration 0",
            "9,0,2,0,0",
            "outside_grid",
        ),
    ]


def format_strokes() -> list[tuple[str, str, Stroke]]:
    def s(*numbers: float) -> Stroke:
        return Stroke(
            start=(numbers[0], numbers[1]),
            end=(numbers[2], numbers[3]),
            duration_ms=numbers[4],
        )

    full = Stroke(
        start=(0.5, 1.0),
        end=(2.0, 1.5),
        duration_ms=420.0,
        intensity=0.8,
        drawing="6f1c2a9e-3b7d-4c55-9a1e-2f0b8d4c7e31",
        seq=3,
        sent_at_ms=1732280000123.0,
    )
    return [
        ("integers", "whole numbers: no decimal point", s(0, 0, 2, 0, 1000)),
        ("decimals", "trailing zeros dropped", s(0.5, 1.25, 3, 2, 420.5)),
        (
            "round-4-decimals",
            "rounded to 4 decimals",
            s(0.123456789, 1.99999, 2.5, 1 / 3, 123.456789),
        ),
        (
            "round-half-up",
            "1.03125 is an exact tie: away from zero",
            s(1.03125, 0.00005, 2.00015, 0, 1.00005),
        ),
        ("round-to-integer", "2.99999 -> 3", s(2.99999, 0.99995, 0, 0, 999.99996)),
        ("negative-zero", "-0 is written 0", s(-0.0, -0.00001, 1, 1, 10)),
        ("float-noise", "0.1 + 0.2", s(0.1 + 0.2, 0.7 * 3, 1, 1, 100.0 / 3)),
        ("full", "every field", full),
        (
            "tiny-and-huge",
            "exponent forms in JSON",
            Stroke(
                (1e-7, 0.0000015),
                (3.0, 2.0),
                1.2345678901234568e20,
                intensity=5e-324,
                sent_at_ms=9999999999999.5,
            ),
        ),
        (
            "exponent-duration",
            "1e21 and above written with an exponent",
            Stroke((0, 0), (3.0, 2.0), 1e21),
        ),
        (
            "escaped-drawing",
            "quote and backslash in the drawing id",
            Stroke((0, 0), (1, 1), 100, drawing='a"b\\c', seq=0),
        ),
    ]


def parse_vector(case: Case) -> dict[str, Any]:
    limits = case.layout or PAPER
    layout = Layout(
        rows=int(limits["rows"]),
        columns=int(limits["columns"]),
        spacing_cm=3.0,
        max_stroke_duration_ms=limits["max_stroke_duration_ms"],
    )
    result = parse(case.payload, layout, format=case.format)
    outcome = ACCEPTED if isinstance(result, Accepted) else result.reason
    if outcome != case.outcome:
        raise SystemExit(f"{case.name}: meant to be {case.outcome}, the reference says {result}")
    if isinstance(result, Accepted):
        expected = {
            "accepted": True,
            "format": result.format,
            "stroke": stroke_json(result.stroke),
        }
    else:
        expected = {
            "accepted": False,
            "reason": result.reason,
            "field": result.field,
            "message": result.message,
        }
    return {
        "description": case.description,
        "layout": limits,
        "format": case.format,
        **encode_payload(case.payload),
        "expected": expected,
    }


def encode_payload(payload: Any) -> dict[str, Any]:
    if isinstance(payload, str):
        return {"payload_encoding": "utf-8", "payload": payload}
    if isinstance(payload, bytes):
        return {
            "payload_encoding": "base64",
            "payload": base64.b64encode(payload).decode("ascii"),
        }
    return {"payload_encoding": "json-value", "payload": payload}


def stroke_json(stroke: Stroke) -> dict[str, Any]:
    return {
        "start": list(stroke.start),
        "end": list(stroke.end),
        "duration_ms": stroke.duration_ms,
        "intensity": stroke.intensity,
        "drawing": stroke.drawing,
        "seq": stroke.seq,
        "sent_at_ms": stroke.sent_at_ms,
    }


def cases() -> dict[str, dict[str, Any]]:
    files: dict[str, dict[str, Any]] = {}
    for case in valid_cases():
        files[f"valid/{case.name}.json"] = parse_vector(case)
    invalid = [
        *payload_cases(),
        *legacy_cases(),
        *json_syntax_cases(),
        *json_field_cases(),
        *json_value_cases(),
        *grid_cases(),
        *order_cases(),
    ]
    for case in invalid:
        files[f"invalid/{case.name}.json"] = parse_vector(case)
    uncovered = set(REASONS) - {case.outcome for case in invalid}
    if uncovered:
        raise SystemExit(f"no invalid vector for reason(s): {sorted(uncovered)}")
    for name, description, stroke in format_strokes():
        files[f"format/{name}.json"] = {
            "description": description,
            "stroke": stroke_json(stroke),
            "legacy": format_legacy(stroke),
            "json": format_json(stroke),
        }
    if len(files) != len(valid_cases()) + len(invalid) + len(format_strokes()):
        raise SystemExit("two protocol vectors share a name")
    return files
