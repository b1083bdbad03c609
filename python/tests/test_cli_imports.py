"""Building the ``feelmysign`` parser imports no heavy module: ``--help`` answers at once.

Every subcommand registers its options at start-up (``feelmysign --help`` lists
them all); the study, the research tools and MQTT are imported by the
subcommand that runs. A module-level import added to a subcommand, or to a
module its options name, fails this test, which says what pulled the module in.
"""

from __future__ import annotations

import json
import subprocess
import sys

# Numerics, plots and statistics (the study and research tools), and MQTT (paho).
HEAVY_PACKAGES = ("numpy", "scipy", "matplotlib", "statsmodels", "pandas", "questplus", "paho")
# The study's command-line choices are the one module of the study package parsing needs.
LIGHT_STUDY_MODULES = ("feelmysign.study", "feelmysign.study.choices")

PROBE = """
import json, sys
from feelmysign.cli import build_parser
build_parser()
parsed = sorted(sys.modules)
import feelmysign.study.threshold  # the probe sees an import: numpy, questplus, research
print(json.dumps({"parser": parsed, "after": sorted(sys.modules)}))
"""


def heavy(modules: list[str]) -> list[str]:
    return [
        name
        for name in modules
        if name.split(".")[0] in HEAVY_PACKAGES
        or name.startswith("feelmysign.research")
        or (name.startswith("feelmysign.study") and name not in LIGHT_STUDY_MODULES)
    ]


def test_building_the_parser_imports_no_heavy_module() -> None:
    done = subprocess.run(
        [sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=120, check=True
    )
    modules = json.loads(done.stdout)
    # The probe can see a heavy import: the study's threshold module brings numpy and questplus.
    assert {"numpy", "questplus", "feelmysign.study.threshold"} <= set(heavy(modules["after"]))
    loaded = heavy(modules["parser"])
    assert not loaded, (
        f"building the parser imported {loaded[:10]}: import them in the subcommand's handler; "
        "see `python -X importtime -c 'from feelmysign.cli import build_parser; build_parser()'`"
    )
