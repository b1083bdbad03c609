"""Research tools: exact replay here; the rest in their modules, imported when needed.

``lasa`` (the LASA handwriting data set as recordings), ``metrics`` (deviation,
Fréchet, lag, Douglas-Peucker), ``sweep`` (parameter grids), ``evaluate`` and
``plots``. Those load numpy, scipy and matplotlib, so this package does not
import them: every ``feelmysign`` command imports it through ``replay``.
"""

from feelmysign.research.rerun import Rerun, frames_for, mismatch, rerun, run_frames

__all__ = ["Rerun", "frames_for", "mismatch", "rerun", "run_frames"]
