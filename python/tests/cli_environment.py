"""A command line as a user's fresh shell would run it, for the CLI tests."""

from __future__ import annotations

import os
from pathlib import Path

import pytest


def clean_cli_environment(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """No FEELMYSIGN_* from the developer's shell, and no local broker's credentials file
    (the session's lock folder kept: conftest.py)."""
    kept = ("FEELMYSIGN_LOCK_DIR",)
    for name in [n for n in os.environ if n.startswith("FEELMYSIGN_") and n not in kept]:
        monkeypatch.delenv(name)
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
