"""The sleeve's geometry, safety caps and wiring, from one validated TOML file.

(Skeleton: the dataclasses are final; loading and validation are being written.)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

ActuatorType = Literal["ERM", "LRA"]


@dataclass(frozen=True)
class Wire:
    """Where one actuator's DRV2605L hangs: a TCA9548A multiplexer address and channel."""

    row: int
    column: int
    multiplexer: int
    channel: int


@dataclass(frozen=True)
class Layout:
    """A sleeve: ``rows`` x ``columns`` actuators, ``spacing_cm`` apart.

    Grid units: x = column index 0..columns-1, y = row index 0..rows-1.
    ``wiring`` is empty for a sleeve without hardware (the simulator).
    """

    rows: int
    columns: int
    spacing_cm: float
    name: str = "sleeve"
    default_intensity: float = 1.0
    max_intensity: float = 1.0
    max_stroke_duration_ms: float = 10_000.0
    max_on_time_ms: float = 5_000.0
    actuator_type: ActuatorType = "ERM"
    i2c_bus: int = 1
    multiplexers: tuple[int, ...] = ()
    wiring: tuple[Wire, ...] = ()
