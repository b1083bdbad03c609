"""Helpers of the study tests: the paper's design, and a fresh study file from it."""

from __future__ import annotations

from pathlib import Path

from feelmysign.study import StudyStore, load_design

REPO = Path(__file__).resolve().parents[2]
PAPER_DESIGN = REPO / "deploy" / "studies" / "paper.toml"


def new_study(tmp_path: Path, design_path: Path = PAPER_DESIGN) -> StudyStore:
    return StudyStore.create(tmp_path / "study.sqlite", design_path, load_design(design_path))
