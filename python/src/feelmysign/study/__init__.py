"""The recognition study of "Can You Feel My Sign?" (section 6) and its threshold procedure.

A design file (``design_file``), one SQLite file per study (``store``), the
runner shared by the terminal and the researcher's page (``runner``), coding of
free answers (``coding``), export and analysis, QUEST+ thresholds, and a
simulated participant for dry runs. See docs/study.md.
"""

from feelmysign.study.design import Design
from feelmysign.study.design_file import load_design, parse_design
from feelmysign.study.store import StudyStore

__all__ = ["Design", "StudyStore", "load_design", "parse_design"]
