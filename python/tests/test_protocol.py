"""The stroke protocol: shared vectors, then examples, then properties over random payloads."""

from __future__ import annotations

import base64
import inspect
import json
import math
import re
import sys
from pathlib import Path
from typing import Any
from unittest.mock import patch

import pytest
from hypothesis import given
from hypothesis import strategies as st
from vectors import load

from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.protocol import (
    GRID_TOLERANCE,
    MAX_DRAWING_ID_CHARS,
    MAX_PAYLOAD_BYTES,
    MAX_SENT_AT_MS,
    MAX_SEQ,
    REASONS,
    Accepted,
    Rejected,
    format_json,
    format_legacy,
    parse,
    stroke_to_dict,
    validate_stroke,
)
from feelmysign.stroke import Stroke

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)
VECTORS = load("protocol")
PARSE_VECTORS = [(n, c) for n, c in VECTORS if n.startswith(("valid/", "invalid/"))]
FORMAT_VECTORS = [(n, c) for n, c in VECTORS if n.startswith("format/")]
DOCS = Path(__file__).resolve().parents[2] / "docs" / "protocol.md"


def vector_payload(case: dict[str, Any]) -> object:
    encoding = case["payload_encoding"]
    if encoding == "base64":
        return base64.b64decode(case["payload"])
    assert encoding in ("utf-8", "json-value"), encoding
    return case["payload"]


def vector_layout(case: dict[str, Any]) -> Layout:
    limits = case["layout"]
    return Layout(
        rows=limits["rows"],
        columns=limits["columns"],
        spacing_cm=3.0,
        max_stroke_duration_ms=limits["max_stroke_duration_ms"],
    )


def stroke_from_vector(data: dict[str, Any]) -> Stroke:
    return Stroke(
        start=(data["start"][0], data["start"][1]),
        end=(data["end"][0], data["end"][1]),
        duration_ms=data["duration_ms"],
        intensity=data["intensity"],
        drawing=data["drawing"],
        seq=data["seq"],
        sent_at_ms=data["sent_at_ms"],
    )


# --- shared vectors -----------------------------------------------------------------------


@pytest.mark.parametrize(("name", "case"), PARSE_VECTORS, ids=[n for n, _ in PARSE_VECTORS])
def test_parse_vector(name: str, case: dict[str, Any]) -> None:
    result = parse(vector_payload(case), vector_layout(case), format=case["format"])
    expected = case["expected"]
    if expected["accepted"]:
        assert isinstance(result, Accepted), result
        assert result.format == expected["format"]
        assert result.stroke == stroke_from_vector(expected["stroke"])
    else:
        assert isinstance(result, Rejected), result
        assert (result.reason, result.field) == (expected["reason"], expected["field"])
        assert result.message == expected["message"]


@pytest.mark.parametrize(("name", "case"), FORMAT_VECTORS, ids=[n for n, _ in FORMAT_VECTORS])
def test_format_vector(name: str, case: dict[str, Any]) -> None:
    stroke = stroke_from_vector(case["stroke"])
    assert format_legacy(stroke) == case["legacy"]
    assert format_json(stroke) == case["json"]


def test_vectors_cover_every_reason_and_both_formats() -> None:
    reasons = {c["expected"]["reason"] for n, c in PARSE_VECTORS if n.startswith("invalid/")}
    assert reasons == set(REASONS)
    invalid = [n for n, _ in PARSE_VECTORS if n.startswith("invalid/")]
    assert len(invalid) >= 40
    formats = {c["expected"]["format"] for n, c in PARSE_VECTORS if n.startswith("valid/")}
    assert formats == {"legacy", "json"}


def test_docs_explain_every_reason() -> None:
    text = DOCS.read_text(encoding="utf-8")
    missing = [code for code in REASONS if f"`{code}`" not in text]
    assert not missing, f"docs/protocol.md does not list {missing}"


# --- examples -----------------------------------------------------------------------------


def test_legacy_example_of_the_paper() -> None:
    result = parse(b"0,0,2,0,1000", PAPER)
    assert result == Accepted(
        Stroke(start=(0.0, 0.0), end=(2.0, 0.0), duration_ms=1000.0), "legacy"
    )


def test_json_example_of_the_architecture() -> None:
    payload = (
        '{"v":1,"drawing":"d-1","seq":3,"start":[0.5,1.0],"end":[2.0,1.5],'
        '"duration_ms":420,"intensity":0.8,"sent_at_ms":1732280000123}'
    )
    result = parse(payload, PAPER)
    assert isinstance(result, Accepted) and result.format == "json"
    assert result.stroke == Stroke((0.5, 1.0), (2.0, 1.5), 420.0, 0.8, "d-1", 3, 1732280000123.0)


@pytest.mark.parametrize("payload", [bytearray(b"0,0,2,0,1000"), memoryview(b"0,0,2,0,1000")])
def test_bytes_like_payloads_are_text(payload: object) -> None:
    assert isinstance(parse(payload, PAPER), Accepted)


def test_a_string_that_is_not_unicode_is_not_text() -> None:
    result = parse("0,0,2,0,1000\udcff", PAPER)
    assert isinstance(result, Rejected) and result.reason == "not_text"
    assert "character 12" in result.message


def test_size_counts_utf8_bytes_not_characters() -> None:
    assert isinstance(parse("é" * (MAX_PAYLOAD_BYTES // 2), PAPER), Rejected)
    too_long = parse("é" * (MAX_PAYLOAD_BYTES // 2 + 1), PAPER)
    assert isinstance(too_long, Rejected) and too_long.reason == "too_long"
    assert f"{MAX_PAYLOAD_BYTES + 2} bytes" in too_long.message


def test_an_unknown_format_argument_is_a_programming_error() -> None:
    with pytest.raises(ValueError, match="'auto', 'legacy' or 'json'"):
        parse("0,0,2,0,1000", PAPER, format="xml")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("payload", "needles"),
    [
        ("4,0,2,0,1000", ["start (4, 0)", "0..3", "0..2", "scale the drawing"]),
        ("0,0,2,0,20000", ["20000", "at most 10000 ms", "Split the stroke"]),
        ("0,0,2,0,0", ["duration_ms is 0", "more than 0 ms"]),
        ('{"v":1,"start":[0,0],"end":[1,1],"duration_ms":5,"intensity":3}', ["3", "0 (off)"]),
        ("0,0,2,0,1000,1", ["6 comma-separated", "exactly 5", "use the JSON format"]),
        ('{"v":3,"start":[0,0],"end":[1,1],"duration_ms":5}', ["3", "only version 1"]),
        ('{"v":1,"start":[0,0],"end":[1,1],"duration_ms":5,"seq":-2}', ["-2", "from 0 to"]),
    ],
)
def test_messages_name_the_value_the_range_and_what_to_do(payload: str, needles: list[str]) -> None:
    result = parse(payload, PAPER)
    assert isinstance(result, Rejected)
    for needle in needles:
        assert needle in result.message


def test_long_bad_values_are_cut_in_messages() -> None:
    result = parse("x" * 400 + ",0,2,0,1000", PAPER)
    assert isinstance(result, Rejected) and result.reason == "not_a_number"
    assert '"' + "x" * 40 + '"...' in result.message
    assert len(result.message) < 200


def test_validate_stroke_clamps_points_within_the_tolerance() -> None:
    stroke = Stroke((-GRID_TOLERANCE / 2, 2 + GRID_TOLERANCE / 2), (3.0, 0.0), 100.0)
    checked = validate_stroke(stroke, PAPER)
    assert isinstance(checked, Stroke)
    assert checked.start == (0.0, 2.0) and math.copysign(1.0, checked.start[0]) == 1.0


def test_validate_stroke_checks_fields_a_legacy_message_cannot_carry() -> None:
    bad_seq = validate_stroke(Stroke((0, 0), (1, 1), 100.0, seq=-1), PAPER)
    assert isinstance(bad_seq, Rejected) and bad_seq.reason == "seq_out_of_range"
    bad_id = validate_stroke(Stroke((0, 0), (1, 1), 100.0, drawing="x" * 65), PAPER)
    assert isinstance(bad_id, Rejected) and bad_id.field == "drawing"


@pytest.mark.parametrize(
    ("stroke", "reason"),
    [
        (Stroke((math.nan, 0.0), (1.0, 1.0), 100.0), "not_finite"),
        (Stroke((0.0, 0.0), (1.0, 1.0), 0.0), "duration_not_positive"),
        (Stroke((0.0, 0.0), (1.0, 1.0), 100.0, intensity=1.5), "intensity_out_of_range"),
        (Stroke((0.0, 0.0), (1.0, 1.0), 100.0, drawing="has space"), "bad_drawing_id"),
    ],
)
def test_formatting_refuses_strokes_no_sleeve_accepts(stroke: Stroke, reason: str) -> None:
    for formatter in (format_legacy, format_json):
        with pytest.raises(StrokeError) as caught:
            formatter(stroke)
        assert caught.value.reason == reason


def test_legacy_drops_what_it_cannot_carry() -> None:
    stroke = Stroke((0.5, 1.0), (2.0, 1.5), 420.0, 0.8, "d", 3, 17.0)
    assert format_legacy(stroke) == "0.5,1,2,1.5,420"
    assert list(stroke_to_dict(Stroke((0, 0), (1, 1), 5.0))) == ["start", "end", "duration_ms"]


def test_nesting_too_deep_for_the_stack_is_rejected_not_raised() -> None:
    # Leave the decoder too little stack for 250 levels (Python 3.11 counts C and Python
    # frames together; later versions may decode it, which is fine: only raising is not).
    depth = len(inspect.stack(0))
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(depth + 60)
    try:
        result = parse("[" * 250 + "]" * 250, PAPER)
    finally:
        sys.setrecursionlimit(limit)
    assert isinstance(result, Rejected) and result.reason in ("invalid_json", "not_an_object")


# --- properties ---------------------------------------------------------------------------

FORMATS = st.sampled_from(["auto", "legacy", "json"])
JSON_SCALARS = (
    st.none()
    | st.booleans()
    | st.integers()
    | st.integers(min_value=10**300, max_value=10**400)
    | st.floats()
    | st.text(max_size=20)
)
JSON_VALUES = st.recursive(
    JSON_SCALARS,
    lambda children: (
        st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=8), children, max_size=4)
    ),
    max_leaves=16,
)
NUMBERISH = st.one_of(
    st.floats().map(repr),
    st.integers().map(str),
    st.sampled_from(["", " ", "-", "+.", "1e", "1_0", "0x1", "NaN", "-inf", "１", "1e-400"]),
    st.just("9" * 400),
    st.text(max_size=8),
)
FIELD_VALUES = st.one_of(
    JSON_VALUES,
    st.lists(st.floats() | st.integers(), min_size=2, max_size=2),
    st.floats(min_value=-1, max_value=5),
)
STROKE_OBJECTS = st.fixed_dictionaries(
    {},
    optional={
        key: FIELD_VALUES | st.just(1)
        for key in ("v", "drawing", "seq", "start", "end", "duration_ms", "intensity", "sent_at_ms")
    },
)
PAYLOADS = st.one_of(
    st.binary(max_size=600),
    st.text(max_size=600),
    JSON_VALUES,
    JSON_VALUES.map(json.dumps),
    STROKE_OBJECTS.map(json.dumps),
    st.lists(NUMBERISH, min_size=0, max_size=7).map(",".join),
)


def check_result(result: Accepted | Rejected, layout: Layout) -> None:
    if isinstance(result, Rejected):
        assert result.reason in REASONS
        assert result.message and "\n" not in result.message
        assert len(result.message) < 400
        return
    stroke = result.stroke
    for x, y in (stroke.start, stroke.end):
        assert 0 <= x <= layout.columns - 1 and 0 <= y <= layout.rows - 1
    assert 0 < stroke.duration_ms <= layout.max_stroke_duration_ms
    assert stroke.intensity is None or 0 <= stroke.intensity <= 1
    assert stroke.seq is None or 0 <= stroke.seq <= MAX_SEQ
    assert stroke.sent_at_ms is None or 0 <= stroke.sent_at_ms <= MAX_SENT_AT_MS
    assert stroke.drawing is None or len(stroke.drawing) <= MAX_DRAWING_ID_CHARS
    assert stroke.drawing is None or re.fullmatch(r"[!-~]+", stroke.drawing)


@given(PAYLOADS, FORMATS)
def test_parse_never_raises_and_accepts_only_playable_strokes(payload: object, fmt: str) -> None:
    check_result(parse(payload, PAPER, format=fmt), PAPER)  # type: ignore[arg-type]


PLAIN_NUMBERS = (
    st.integers(min_value=-2, max_value=12)
    | st.floats(min_value=-1, max_value=13)
    | st.sampled_from([-0.0, 3, 3.0, 1e-320, math.inf, math.nan, 10**400, 2**53])
)
PLAIN_STROKE_OBJECTS = st.fixed_dictionaries(
    {
        "v": st.sampled_from([1, 1.0, True, 2]),
        "start": st.lists(PLAIN_NUMBERS, min_size=2, max_size=2),
        "end": st.lists(PLAIN_NUMBERS, min_size=2, max_size=2),
        "duration_ms": PLAIN_NUMBERS | st.floats(min_value=0, max_value=20_000),
    },
    optional={
        "drawing": st.none() | st.text(max_size=70) | st.integers(),
        "seq": st.none() | st.integers(min_value=-1, max_value=2**54) | st.just(3.0),
        "intensity": st.none() | PLAIN_NUMBERS | st.booleans(),
        "sent_at_ms": st.none() | PLAIN_NUMBERS | st.sampled_from([1.7e12, 10**16, 1e300]),
    },
)


@given(PLAIN_STROKE_OBJECTS, st.sampled_from([PAPER, Layout(rows=3, columns=12, spacing_cm=3.0)]))
def test_json_read_with_the_grid_is_the_field_by_field_read(
    document: dict[str, Any], layout: Layout
) -> None:
    # parse takes a quick way for a stroke plainly valid on the grid: the same verdict, the
    # same stroke (-0.0 made 0.0, ints made floats) as reading, checking and clamping it.
    text = json.dumps(document)
    result = parse(text, layout, format="json")
    with patch("feelmysign.protocol._plain_json", return_value=None) as plain:
        slow = parse(text, layout, format="json")
    assert result == slow
    if isinstance(result, Accepted) and isinstance(slow, Accepted):
        assert plain.called
        for got, want in zip(
            (*result.stroke.start, *result.stroke.end),
            (*slow.stroke.start, *slow.stroke.end),
            strict=True,
        ):
            assert type(got) is float and math.copysign(1, got) == math.copysign(1, want)


@given(st.text(max_size=100))
def test_auto_reads_non_json_text_as_legacy(text: str) -> None:
    if text.strip(" \t\r\n\ufeff")[:1] in ("{", "["):
        return
    auto, legacy = parse(text, PAPER), parse(text, PAPER, format="legacy")
    assert auto == legacy


DRAWING_ID_CHARS = st.characters(min_codepoint=0x21, max_codepoint=0x7E)


@st.composite
def playable_strokes(draw: st.DrawFn, layout: Layout = PAPER) -> Stroke:
    def coordinate(count: int) -> float:
        return draw(st.floats(min_value=0, max_value=count - 1))

    return Stroke(
        start=(coordinate(layout.columns), coordinate(layout.rows)),
        end=(coordinate(layout.columns), coordinate(layout.rows)),
        duration_ms=draw(st.floats(min_value=1e-3, max_value=layout.max_stroke_duration_ms)),
        intensity=draw(st.none() | st.floats(min_value=0, max_value=1)),
        drawing=draw(st.none() | st.text(DRAWING_ID_CHARS, min_size=1, max_size=64)),
        seq=draw(st.none() | st.integers(min_value=0, max_value=MAX_SEQ)),
        sent_at_ms=draw(st.none() | st.floats(min_value=0, max_value=MAX_SENT_AT_MS)),
    )


@given(playable_strokes())
def test_json_round_trip_is_exact(stroke: Stroke) -> None:
    text = format_json(stroke)
    assert json.loads(text)["v"] == 1 and len(text.encode()) <= MAX_PAYLOAD_BYTES
    assert parse(text, PAPER) == Accepted(stroke, "json")


# At most 4 decimals, no trailing zeros, no exponent, no sign (strokes lie in the grid).
LEGACY_NUMBER = r"(0|[1-9][0-9]*)(\.[0-9]{0,3}[1-9])?"


@given(playable_strokes())
def test_legacy_round_trip_keeps_four_decimals(stroke: Stroke) -> None:
    text = format_legacy(stroke)
    assert re.fullmatch(rf"{LEGACY_NUMBER}(,{LEGACY_NUMBER}){{4}}", text), text
    result = parse(text, PAPER)
    assert isinstance(result, Accepted) and result.format == "legacy"
    sent = (*stroke.start, *stroke.end, stroke.duration_ms)
    read = (*result.stroke.start, *result.stroke.end, result.stroke.duration_ms)
    for before, after in zip(sent, read, strict=True):
        assert abs(before - after) <= 0.5e-4 + 1e-9 * max(1.0, before)
    assert format_legacy(result.stroke) == text


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=0, exclude_min=True))
def test_json_numbers_read_back_as_the_same_double(value: float) -> None:
    # A duration: the one number the writer takes at any positive size (no sleeve's cap).
    text = format_json(Stroke((0, 0), (1, 1), value))
    written = text.split('"duration_ms":')[1].rstrip("}")
    assert float(written) == value
    assert not written.endswith(".0")


def test_a_stroke_refused_for_its_values_is_named_by_its_drawing_and_seq() -> None:
    # The sleeve's event names it, so its sender's page and terminal find which stroke it was.
    outside = '{"v":1,"drawing":"d-1","seq":7,"start":[0,0],"end":[0,9],"duration_ms":300}'
    refused = parse(outside, PAPER)
    assert isinstance(refused, Rejected) and refused.reason == "outside_grid"
    assert (refused.drawing, refused.seq) == ("d-1", 7)
    # Not when the name is what is wrong: the event then carries no id it could be matched by.
    bad_seq = '{"v":1,"drawing":"d-1","seq":-1,"start":[0,0],"end":[0,1],"duration_ms":300}'
    refused = parse(bad_seq, PAPER)
    assert isinstance(refused, Rejected) and refused.field == "seq"
    assert (refused.drawing, refused.seq) == (None, None)
