"""The duty-cycle cap counts the drive a motor gets, after the intensity cap, not the drive a
stroke asks for: a real ``feelmysign sleeve`` (2 x 6, emulated bus) capped at 0.5, strokes sent
by ``feelmysign send`` asking for 1.0."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest
from builder_sleeve import start_sleeve, two_by_six_layout
from sleeve_watch import SleeveWatch, online

from feelmysign.bench.restart_off import feelmysign_command
from feelmysign.broker import Broker
from feelmysign.layout import load_layout

WAIT_S = 120.0
MAX_INTENSITY = 0.5
STROKE_MS = 1000.0
WINDOW_MS = 60000.0
# 1.1 strokes of full drive a minute: a stroke asked at 1.0 and counted so, a second one
# would be refused; driven at 0.5 (a quarter of the energy), four fit and a fifth does not.
BUDGET_MS = 1.1 * STROKE_MS

pytestmark = pytest.mark.broker


def test_strokes_above_the_intensity_cap_count_at_the_drive_applied(
    broker: Broker, tmp_path: Path
) -> None:
    layout_file = two_by_six_layout(
        tmp_path / "hot.toml",
        max_intensity=MAX_INTENSITY,
        window_ms=WINDOW_MS,
        max_duty_cycle=BUDGET_MS / WINDOW_MS,
        max_stroke_duration_ms=STROKE_MS,
    )
    assert load_layout(layout_file).max_intensity == MAX_INTENSITY
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    # Five strokes that stay on the motor at (0, 0), each on it alone for its whole second.
    strokes = ["0,0,0,0,1000"] * 5
    with SleeveWatch(broker.credentials, "status", "events", "actuators") as watcher:
        sleeve = start_sleeve(broker.credentials_path, layout_file, tmp_path / "bus.json")
        try:
            watcher.next(online, "the sleeve online")
            sent = subprocess.run(
                [
                    *feelmysign_command(),
                    *("send", "--credentials", str(broker.credentials_path), *strokes),
                    *("--intensity", "1.0", "--pace", "realtime", "--wait"),
                ],
                capture_output=True,
                text=True,
                timeout=WAIT_S,
                env=env,
                check=False,
            )
        finally:
            sleeve.terminate()
            _, errors = sleeve.communicate(timeout=WAIT_S)
    assert "Traceback" not in errors, errors
    assert sent.returncode == 1, sent.stdout + sent.stderr  # the fifth is refused
    events = [e for e in watcher.received("events") if e.get("type") != "status"]
    played = [e["seq"] for e in events if e["type"] in ("played", "adjusted")]
    refused = [e for e in events if e["type"] == "safety"]
    assert played == [0, 1, 2, 3], events
    assert [(e["seq"], e["reason"], e["row"], e["column"]) for e in refused] == [
        (4, "duty_cycle", 0, 0)
    ], events
    # What the window would have held: five seconds at 0.5, a quarter of full drive each.
    driven = 5 * STROKE_MS * MAX_INTENSITY**2 / WINDOW_MS
    assert refused[0]["duty_cycle"] == pytest.approx(driven, abs=1e-3), refused
    # (strokes that queued on a loaded machine are said in brackets: played faster)
    said = re.search(r"played 4 of 5 strokes( \([^)]*\))?, refused 1 \(duty_cycle\)", sent.stderr)
    assert said is not None, sent.stderr
    frames = watcher.received("actuators")
    assert max(max(map(max, f["intensities"])) for f in frames) == pytest.approx(MAX_INTENSITY)
