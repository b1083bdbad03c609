"""Backends: what the player drives. ``sim`` records, ``drv2605`` drives the sleeve's chips."""

from feelmysign.backends.base import Backend, GridBackend, check_actuator, check_intensity
from feelmysign.backends.drv2605 import DRV2605L, Drv2605Backend, check_wiring, rtp_level
from feelmysign.backends.emulated_i2c import (
    BusConflictError,
    EmulatedDRV2605L,
    EmulatedI2CBus,
    EmulatedTCA9548A,
    Transaction,
)
from feelmysign.backends.i2c import I2CBus, open_smbus
from feelmysign.backends.scan import (
    ChannelScan,
    LayoutReport,
    ScanResult,
    WireCheck,
    compare_with_layout,
    scan,
)
from feelmysign.backends.sim import Change, SimBackend
from feelmysign.backends.tca9548a import Multiplexers, MuxChannel
from feelmysign.backends.telemetry import ActuatorFrame, ActuatorTelemetry, monotonic_ms

__all__ = [
    "DRV2605L",
    "ActuatorFrame",
    "ActuatorTelemetry",
    "Backend",
    "BusConflictError",
    "Change",
    "ChannelScan",
    "Drv2605Backend",
    "EmulatedDRV2605L",
    "EmulatedI2CBus",
    "EmulatedTCA9548A",
    "GridBackend",
    "I2CBus",
    "LayoutReport",
    "Multiplexers",
    "MuxChannel",
    "ScanResult",
    "SimBackend",
    "Transaction",
    "WireCheck",
    "check_actuator",
    "check_intensity",
    "check_wiring",
    "compare_with_layout",
    "monotonic_ms",
    "open_smbus",
    "rtp_level",
    "scan",
]
