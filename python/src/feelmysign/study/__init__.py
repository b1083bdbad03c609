"""The recognition study of "Can You Feel My Sign?" (section 6) and its threshold procedure.

A design file (``design_file``), one SQLite file per study (``store``), the
runner shared by the terminal and the researcher's page (``runner``), coding of
free answers (``coding``), export and analysis, QUEST+ thresholds, and a
simulated participant for dry runs. See docs/study.md.

Its names are imported when first used: ``feelmysign --help`` imports only
``choices``, not numpy, scipy, matplotlib or questplus.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from feelmysign.study.design import Design
    from feelmysign.study.design_file import load_design, parse_design
    from feelmysign.study.store import StudyStore

__all__ = ["Design", "StudyStore", "load_design", "parse_design"]
_HOMES = {
    "Design": "design",
    "StudyStore": "store",
    "load_design": "design_file",
    "parse_design": "design_file",
}


def __getattr__(name: str) -> Any:
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)
