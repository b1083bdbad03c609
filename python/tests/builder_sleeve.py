"""A maker's sleeve for the tests: 2 rows x 6 columns of LRAs, 2.5 cm apart, on two
TCA9548A multiplexers, run as a real ``feelmysign sleeve`` process on the emulated bus."""

from __future__ import annotations

import subprocess
from pathlib import Path

from feelmysign.bench.restart_off import feelmysign_command

TWO_BY_SIX = """
name = "maker-2x6"
rows = 2
columns = 6
spacing_cm = 2.5
actuator_type = "LRA"
default_intensity = {default_intensity}

[safety]
max_intensity = {max_intensity}
max_stroke_duration_ms = {max_stroke_duration_ms}
duty_cycle_window_ms = {window_ms}
max_duty_cycle = {max_duty_cycle}

[i2c]
bus = 1
multiplexers = [0x70, 0x71]
wiring = [
{wiring}
]
"""


def two_by_six_layout(
    path: Path,
    *,
    max_intensity: float = 1.0,
    window_ms: float = 60000,
    max_duty_cycle: float = 0.5,
    max_stroke_duration_ms: float = 10000,
) -> Path:
    """The 2 x 6 layout file: row 0 on multiplexer 0x70, row 1 on 0x71, channels 0..5."""
    wiring = ",\n".join(
        f"  {{ row = {row}, column = {column}, multiplexer = {0x70 + row}, channel = {column} }}"
        for row in range(2)
        for column in range(6)
    )
    path.write_text(
        TWO_BY_SIX.format(
            max_intensity=max_intensity,
            default_intensity=min(0.8, max_intensity),
            window_ms=window_ms,
            max_duty_cycle=max_duty_cycle,
            max_stroke_duration_ms=max_stroke_duration_ms,
            wiring=wiring,
        )
    )
    return path


def start_sleeve(
    credentials_path: Path, layout: Path, state: Path, *extra: str, stderr: int | None = None
) -> subprocess.Popen[str]:
    """``feelmysign sleeve`` on ``layout``, its chips emulated with registers in ``state``."""
    return subprocess.Popen(
        [
            *feelmysign_command(),
            "sleeve",
            *("--backend", "drv2605", "--emulate-state", str(state)),
            *("--layout", str(layout), "--credentials", str(credentials_path), "--no-legacy"),
            *extra,
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE if stderr is None else stderr,
        text=True,
    )
