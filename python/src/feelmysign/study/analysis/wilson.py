"""Wilson score interval for a binomial proportion (Wilson 1927; Brown, Cai & DasGupta 2001
recommend it over the Wald interval for the small n and extreme p of a study like this)."""

from __future__ import annotations

import math

from scipy.stats import norm


def wilson_interval(correct: int, total: int, level: float = 0.95) -> tuple[float, float]:
    """(low, high) for ``correct`` of ``total``; (0, 1) when there is no trial."""
    if total <= 0:
        return 0.0, 1.0
    z = float(norm.ppf(0.5 + level / 2))
    p = correct / total
    denominator = 1 + z * z / total
    centre = (p + z * z / (2 * total)) / denominator
    half = z * math.sqrt(p * (1 - p) / total + z * z / (4 * total * total)) / denominator
    return max(0.0, centre - half), min(1.0, centre + half)
