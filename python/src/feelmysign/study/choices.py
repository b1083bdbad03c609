"""What a person chooses on the study's command line, with no numpy, scipy or questplus.

``feelmysign --help`` lists these; the modules that compute with them
(``threshold``, ``analysis.psychometric``) import them from here.
"""

from __future__ import annotations

from typing import Literal

Dimension = Literal["length", "duration"]
DIMENSIONS: tuple[Dimension, ...] = ("length", "duration")
DIRECTIONS = {"up": (0.0, -1.0), "down": (0.0, 1.0), "left": (-1.0, 0.0), "right": (1.0, 0.0)}
BOOTSTRAP_SAMPLES = 1000  # bootstrap samples per shape of the analysis's intervals
