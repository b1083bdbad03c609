"""Backends: what the player drives. ``sim`` records, ``drv2605`` drives the sleeve's chips.

Names are imported when first used: a sleeve restarted after a crash imports
:mod:`feelmysign.backends.all_off` (and so this package) before it switches its
motors off, and must not wait for the simulator, the scanner and the emulator.
``feelmysign.backends.scan`` is the scanner's module; its ``scan`` function is
imported from there.
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing itself costs a start-up import; mypy reads this name as True
if TYPE_CHECKING:
    from feelmysign.backends.base import (
        Backend,
        GridBackend,
        check_actuator,
        check_intensity,
    )
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
    )
    from feelmysign.backends.sim import RecordedChange, SimBackend
    from feelmysign.backends.tca9548a import Multiplexers, MuxChannel
    from feelmysign.backends.telemetry import ActuatorFrame, ActuatorTelemetry

_WHERE = {
    "Backend": "base",
    "GridBackend": "base",
    "check_actuator": "base",
    "check_intensity": "base",
    "DRV2605L": "drv2605",
    "Drv2605Backend": "drv2605",
    "check_wiring": "drv2605",
    "rtp_level": "drv2605",
    "BusConflictError": "emulated_i2c",
    "EmulatedDRV2605L": "emulated_i2c",
    "EmulatedI2CBus": "emulated_i2c",
    "EmulatedTCA9548A": "emulated_i2c",
    "Transaction": "emulated_i2c",
    "I2CBus": "i2c",
    "open_smbus": "i2c",
    "ChannelScan": "scan",
    "LayoutReport": "scan",
    "ScanResult": "scan",
    "WireCheck": "scan",
    "compare_with_layout": "scan",
    "RecordedChange": "sim",
    "SimBackend": "sim",
    "Multiplexers": "tca9548a",
    "MuxChannel": "tca9548a",
    "ActuatorFrame": "telemetry",
    "ActuatorTelemetry": "telemetry",
}
__all__ = [
    "DRV2605L",
    "ActuatorFrame",
    "ActuatorTelemetry",
    "Backend",
    "BusConflictError",
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
    "RecordedChange",
    "ScanResult",
    "SimBackend",
    "Transaction",
    "WireCheck",
    "check_actuator",
    "check_intensity",
    "check_wiring",
    "compare_with_layout",
    "open_smbus",
    "rtp_level",
]


def __getattr__(name: str) -> object:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value
