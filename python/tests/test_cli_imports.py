"""Building the ``feelmysign`` parser imports no heavy module: ``--help`` answers at once.

Every subcommand registers its options at start-up (``feelmysign --help`` lists
them all); the study, the research tools and MQTT are imported by the
subcommand that runs. A module-level import added to a subcommand, or to a
module its options name, fails this test, which says what pulled the module in.
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

# Numerics, plots and statistics (the study and research tools), and MQTT (paho).
HEAVY_PACKAGES = (
    "numpy",
    "scipy",
    "matplotlib",
    "statsmodels",
    "pandas",
    "questplus",
    "paho",
    "gpiod",  # only a layout with an enable line, and only once its backend opens
)
# The study's command-line choices are the one module of the study package parsing needs.
LIGHT_STUDY_MODULES = ("feelmysign.study", "feelmysign.study.choices")

PROBE = """
import json, sys
from feelmysign.cli import build_parser
build_parser()
parsed = sorted(sys.modules)
import feelmysign.study.analysis  # the probe sees an import: numpy, scipy, the study
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
    # The probe can see a heavy import: the study's analysis brings numpy and scipy.
    assert {"numpy", "scipy", "feelmysign.study.analysis"} <= set(heavy(modules["after"]))
    loaded = heavy(modules["parser"])
    assert not loaded, (
        f"building the parser imported {loaded[:10]}: import them in the subcommand's handler; "
        "see `python -X importtime -c 'from feelmysign.cli import build_parser; build_parser()'`"
    )


# --- the early all-off ------------------------------------------------------------------------
# A sleeve restarted after a crash switches its motors off before anything else: what it
# imports until then is paid for in motor-on time. The probe starts the sleeve as the
# console script and the systemd unit do (``from feelmysign.cli import main; main()``) and
# notes every module loaded when the early pass reaches for the bus and when it writes.

EARLY_PROBE = """
import sys
import feelmysign.early_off as early  # what importing feelmysign.cli imports anyway

seen = []
open_bus, switch_off = early._open_bus, early.switch_off

def spy_open(*args):
    seen.append(("bus", sorted(sys.modules)))
    return open_bus(*args)

def spy_switch_off(*args):
    seen.append(("write", sorted(sys.modules)))
    return switch_off(*args)

early._open_bus, early.switch_off = spy_open, spy_switch_off
from feelmysign.cli import main

code = main(sys.argv[1:])  # the start-up goes on, and stops at the missing credentials
print(repr(seen))
sys.exit(code)
"""
PAPER = str(Path(__file__).resolve().parents[2] / "deploy" / "layouts" / "paper-sleeve.toml")
# Never before the all-off: MQTT, the TOML reader, logging, argparse, the research tools,
# typing and pathlib (each several milliseconds on a Raspberry Pi), the layout's reader
# and the daemon.
NOT_BEFORE_ALL_OFF = (
    "paho",
    "numpy",
    "tomllib",
    "logging",
    "argparse",
    "typing",
    "pathlib",
    "dataclasses",
    "smbus2",
    "ctypes",
    "feelmysign.layout",
    "feelmysign.daemon",
    "feelmysign.broker",
    "feelmysign.research",
    "gpiod",  # the pull-down holds an enable line low after a crash: the early pass needs none
)
# A real bus needs no JSON either; the emulated bus is a JSON file.
NOT_BEFORE_REAL_BUS = ("json", "re")
# What the full layout reader brings, on a first start only (no memo of the layout yet).
FIRST_START_READS = (
    "tomllib",
    "typing",
    "dataclasses",
    "re",
    "json",
    "feelmysign.layout",
)


def early_modules(arguments: list[str], env: dict[str, str]) -> list[tuple[str, list[str]]]:
    done = subprocess.run(
        [sys.executable, "-c", EARLY_PROBE, "sleeve", "--backend", "drv2605", *arguments],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert done.returncode == 1, done.stderr  # the credentials file does not exist
    seen: list[tuple[str, list[str]]] = ast.literal_eval(done.stdout.strip().splitlines()[-1])
    return seen


def loaded(modules: list[str], packages: tuple[str, ...]) -> list[str]:
    return [m for m in modules if any(m == p or m.startswith(p + ".") for p in packages)]


@pytest.mark.parametrize("memo", [False, True], ids=["first start", "memo of the layout"])
def test_the_early_all_off_on_a_real_bus_comes_before_any_heavy_import(
    tmp_path: Path, memo: bool
) -> None:
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "state")}
    arguments = ["--layout", PAPER, "--credentials", str(tmp_path / "none.json")]
    if memo:
        early_modules(arguments, env)  # the first start writes the memo
    seen = early_modules(arguments, env)
    # No /dev/i2c-1 here: the pass reaches for the bus, and the open fails.
    assert [step for step, _ in seen] == ["bus"], seen
    modules = seen[0][1]
    assert "feelmysign.backends.all_off" in modules  # the probe sees our imports
    too_early = loaded(modules, NOT_BEFORE_ALL_OFF + NOT_BEFORE_REAL_BUS)
    if not memo:  # the first start reads the TOML (only) after a miss, then reaches the bus
        too_early = [m for m in too_early if m not in loaded(modules, FIRST_START_READS)]
    assert not too_early, (
        f"imported before the early all-off: {too_early[:12]}; see `python -X importtime "
        f".venv/bin/feelmysign sleeve --backend drv2605 --layout {PAPER}`"
    )


def test_the_early_all_off_on_the_emulated_bus_writes_before_any_heavy_import(
    tmp_path: Path,
) -> None:
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path / "state")}
    state = tmp_path / "bus.json"
    setup = "from feelmysign.cli import main; import sys; sys.exit(main(sys.argv[1:]))"
    for _ in range(2):  # the bus with its chips, then (its early pass) the layout's memo
        subprocess.run(
            [sys.executable, "-c", setup, "off", "--layout", PAPER, "--emulate-state", str(state)],
            check=True,
            env=env,
            capture_output=True,
            timeout=120,
        )
    arguments = ["--layout", PAPER, "--emulate-state", str(state)]
    seen = early_modules([*arguments, "--credentials", str(tmp_path / "none.json")], env)
    assert [step for step, _ in seen] == ["bus", "write"], seen
    for step, modules in seen:
        too_early = loaded(modules, NOT_BEFORE_ALL_OFF)
        assert not too_early, f"imported before the early all-off ({step}): {too_early[:12]}"
