"""A command line as a user's fresh shell would run it, for the CLI tests."""

from __future__ import annotations

import os
from pathlib import Path

import pytest


def clean_cli_environment(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """No FEELMYSIGN_* from the developer's shell, and no local broker's credentials file."""
    for name in [name for name in os.environ if name.startswith("FEELMYSIGN_")]:
        monkeypatch.delenv(name)
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
