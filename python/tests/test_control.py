"""The control message against the shared vectors (testdata/control)."""

from __future__ import annotations

from typing import Any

import pytest
from vectors import load

from feelmysign.control import CANCEL_ALL, Cancel, format_control, parse_control
from feelmysign.protocol import Rejected

CASES = load("control")
VALID = [(n, c) for n, c in CASES if n.startswith("valid/")]
INVALID = [(n, c) for n, c in CASES if n.startswith("invalid/")]
FORMAT = [(n, c) for n, c in CASES if n.startswith("format/")]


def test_every_group_has_vectors() -> None:
    assert VALID and INVALID and FORMAT


@pytest.mark.parametrize(("name", "case"), VALID, ids=[n for n, _ in VALID])
def test_valid(name: str, case: dict[str, Any]) -> None:
    assert parse_control(case["payload"]) == Cancel(case["cancel"])
    # Bytes, as MQTT delivers them, read the same.
    assert parse_control(case["payload"].encode()) == Cancel(case["cancel"])


@pytest.mark.parametrize(("name", "case"), INVALID, ids=[n for n, _ in INVALID])
def test_invalid(name: str, case: dict[str, Any]) -> None:
    refused = parse_control(case["payload"])
    assert isinstance(refused, Rejected)
    assert (refused.reason, refused.field) == (case["reason"], case["field"])


@pytest.mark.parametrize(("name", "case"), FORMAT, ids=[n for n, _ in FORMAT])
def test_format(name: str, case: dict[str, Any]) -> None:
    assert format_control(Cancel(case["cancel"])) == case["text"]


def test_what_a_cancel_matches() -> None:
    assert Cancel(CANCEL_ALL).matches("d1") and Cancel(CANCEL_ALL).matches(None)
    assert Cancel("d1").matches("d1")
    assert not Cancel("d1").matches("d2") and not Cancel("d1").matches(None)


def test_bytes_that_are_not_utf8_are_not_text() -> None:
    refused = parse_control(b"\xff\xfe")
    assert isinstance(refused, Rejected) and refused.reason == "not_text"


def test_a_sender_cannot_format_a_bad_id() -> None:
    with pytest.raises(ValueError, match="not a drawing id"):
        format_control(Cancel("a b"))
