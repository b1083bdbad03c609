"""Every invalid protocol vector through ``feelmysign validate``: a reason, exit 1, no traceback."""

from __future__ import annotations

import json
from typing import Any

import pytest
from vectors import load

from feelmysign.cli import main

PAPER_LIMITS = {"rows": 3, "columns": 4, "max_stroke_duration_ms": 10000.0}


def _cli_cases() -> list[tuple[str, dict[str, Any]]]:
    """Text payloads checked against the paper sleeve's limits (what the CLI checks by default)."""
    return [
        (name, case)
        for name, case in load("protocol")
        if name.startswith("invalid/")
        and case["payload_encoding"] == "utf-8"
        and case["layout"] == PAPER_LIMITS
        and case["payload"][:1] != "-"  # read as an option; covered with '--' in test_cli_validate
    ]


CASES = _cli_cases()


def test_at_least_thirty_kinds_of_bad_payload() -> None:
    assert len(CASES) >= 30
    assert len({case["expected"]["reason"] for _, case in CASES}) >= 12


@pytest.mark.parametrize(("name", "case"), CASES, ids=[n for n, _ in CASES])
def test_rejected_with_the_vector_reason(
    name: str, case: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["validate", "--json", "--format", case["format"], case["payload"]])
    verdict = json.loads(capsys.readouterr().out)
    assert code == 1
    assert verdict["ok"] is False
    assert verdict["reason"] == case["expected"]["reason"]
    assert verdict["message"]
