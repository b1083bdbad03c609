"""feelmysign: draw a shape and have it felt, as it is drawn, on a vibrotactile sleeve.

Names are imported when first used: a sleeve restarted after a crash imports this
package before it switches its motors off, and must not wait for the rest.
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing itself costs a start-up import; mypy reads this name as True
if TYPE_CHECKING:
    from feelmysign.errors import FeelMySignError, HardwareError, LayoutError, StrokeError
    from feelmysign.layout import Layout, Wire
    from feelmysign.schedule import Adjustment, Command, Schedule
    from feelmysign.stroke import Stroke

__version__ = "0.1.0"
__all__ = [
    "Adjustment",
    "Command",
    "FeelMySignError",
    "HardwareError",
    "Layout",
    "LayoutError",
    "Schedule",
    "Stroke",
    "StrokeError",
    "Wire",
    "__version__",
]

_WHERE = {
    "FeelMySignError": "feelmysign.errors",
    "HardwareError": "feelmysign.errors",
    "LayoutError": "feelmysign.errors",
    "StrokeError": "feelmysign.errors",
    "Layout": "feelmysign.layout",
    "Wire": "feelmysign.layout",
    "Adjustment": "feelmysign.schedule",
    "Command": "feelmysign.schedule",
    "Schedule": "feelmysign.schedule",
    "Stroke": "feelmysign.stroke",
}


def __getattr__(name: str) -> object:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
