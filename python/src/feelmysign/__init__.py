"""feelmysign: draw a shape and have it felt, as it is drawn, on a vibrotactile sleeve."""

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
