"""A sleeve-only install as a Raspberry Pi gets it: ``make sleeve`` into a folder of its own,
the sleeve run from there against a real Mosquitto on the emulated bus, and the systemd unit
``make sleeve-unit`` writes for that install checked by ``systemd-analyze verify``."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest
from builder_sleeve import two_by_six_layout
from sleeve_watch import SleeveWatch, online

from feelmysign.broker import Broker
from feelmysign.stroke import Stroke

REPOSITORY = Path(__file__).resolve().parents[2]
WAIT_S = 600.0  # pip resolves and builds the package: minutes on a busy machine
# What the page, the research tools and the tests need, and a sleeve never does.
NOT_FOR_A_SLEEVE = ("npm", "node", "chromium", "mvn", "playwright", "vite", "numpy", "pytest")


def make(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["make", "--no-print-directory", *argv],
        cwd=REPOSITORY,
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        check=False,
    )


def test_make_sleeve_asks_for_nothing_the_page_needs() -> None:
    planned = make("-n", "sleeve", "SLEEVE_PREFIX=/tmp/not-made", "SLEEVE_SUDO=")
    assert planned.returncode == 0, planned.stderr
    assert "pip install" in planned.stdout and "./python" in planned.stdout
    assert "python3-venv i2c-tools" in planned.stdout
    words = planned.stdout.replace("'", " ").replace('"', " ").split()
    assert not [w for w in words if any(w.startswith(n) for n in NOT_FOR_A_SLEEVE)], words
    assert "[research" not in planned.stdout and "[dev" not in planned.stdout


@pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")
def test_a_sleeve_installed_by_make_sleeve_plays_and_its_unit_verifies(
    broker: Broker, tmp_path: Path
) -> None:
    prefix = tmp_path / "opt-feelmysign"
    # SLEEVE_SUDO= : the test's own folder needs no sudo; the packages are there already
    # (make test's system packages include the sleeve's).
    installed = make("sleeve", f"SLEEVE_PREFIX={prefix}", "SLEEVE_SUDO=")
    assert installed.returncode == 0, installed.stdout + installed.stderr
    packages = subprocess.run(
        [str(prefix / "bin" / "python"), "-m", "pip", "list", "--format=freeze"],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout.lower()
    assert "feelmysign==" in packages and "paho-mqtt==" in packages and "smbus2==" in packages
    assert not [n for n in NOT_FOR_A_SLEEVE if f"\n{n}==" in f"\n{packages}"], packages
    assert not (REPOSITORY / "python" / "build").exists()  # no build folder left behind

    layout = two_by_six_layout(tmp_path / "layout.toml")
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    with SleeveWatch(broker.credentials, "status", "events") as watcher:
        sleeve = subprocess.Popen(
            [
                str(prefix / "bin" / "feelmysign"),
                *("sleeve", "--backend", "drv2605", "--layout", str(layout)),
                *("--emulate-state", str(tmp_path / "bus.json")),
                *("--credentials", str(broker.credentials_path), "--no-legacy"),
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        try:
            watcher.next(online, "the installed sleeve online")
            watcher.send(Stroke((0.0, 0.0), (5.0, 1.0), 600.0, 0.8, "installed", 0))
            played = watcher.next(lambda n, b: b.get("drawing") == "installed", "its answer")
            assert played["type"] == "played", played
        finally:
            sleeve.terminate()
            _, errors = sleeve.communicate(timeout=60)
    assert sleeve.returncode == 0 and "Traceback" not in errors, errors

    if shutil.which("systemd-analyze") is None:
        pytest.skip("systemd-analyze is missing (Debian package systemd, in make's system list)")
    units = tmp_path / "units"
    units.mkdir()
    unit = make(
        "sleeve-unit", f"SLEEVE_PREFIX={prefix}", f"SLEEVE_UNIT_DIR={units}", "SLEEVE_SUDO="
    )
    assert unit.returncode == 0, unit.stdout + unit.stderr
    written = units / "feelmysign-sleeve.service"
    assert f"ExecStart={prefix}/bin/feelmysign sleeve" in written.read_text()
    verified = subprocess.run(
        ["systemd-analyze", "verify", str(written)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert verified.returncode == 0, verified.stdout + verified.stderr
    assert "feelmysign-sleeve.service" not in verified.stderr, verified.stderr
