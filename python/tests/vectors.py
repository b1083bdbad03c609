"""Read the shared vectors in testdata/ (written by testdata/generate.py)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

TESTDATA = Path(__file__).resolve().parents[2] / "testdata"


def load(part: str) -> list[tuple[str, dict[str, Any]]]:
    """Every vector of one part as (name, case), sorted by name; fails loudly if there are none."""
    paths = sorted((TESTDATA / part).glob("**/*.json"))
    if not paths:
        raise FileNotFoundError(f"no vectors in {TESTDATA / part}; run `make vectors`")
    return [
        (str(p.relative_to(TESTDATA / part).with_suffix("")), json.loads(p.read_text()))
        for p in paths
    ]
