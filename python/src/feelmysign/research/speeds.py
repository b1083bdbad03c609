"""Drawings at three speeds, made from LASA by re-timing its demonstrations.

LASA's demonstrations take 1.3 to 8.7 s (4.5 s at the median): slower than a
shape is drawn on a screen, with 1000 samples each. People draw a shape like
these in about half a second to two seconds, and a pointer reports about 60 to
240 times a second. Each demonstration is therefore re-timed to a set total
duration, keeping its own speed profile (where the hand slowed, it still
slows), and sampled as a 125 Hz pen would sample it: one sample every 8 ms,
positions interpolated along the demonstration, the last sample at the end.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from feelmysign.simplify.recording import Recording
from feelmysign.simplify.segment import Sample

# Total drawing time of one shape at each speed, ms.
SPEEDS_MS: dict[str, float] = {"slow": 2400.0, "normal": 1200.0, "fast": 600.0}
SAMPLE_PERIOD_MS = 8.0  # a 125 Hz pen


def retimed(
    recording: Recording, total_ms: float, period_ms: float = SAMPLE_PERIOD_MS
) -> Recording:
    """The recording's paths drawn in ``total_ms`` each, sampled every ``period_ms``."""
    return replace(recording, paths=tuple(_path(p, total_ms, period_ms) for p in recording.paths))


def _path(samples: tuple[Sample, ...], total_ms: float, period_ms: float) -> tuple[Sample, ...]:
    times = np.array([s.t_ms for s in samples])
    span = times[-1] - times[0]
    if span <= 0:
        return samples
    scaled = (times - times[0]) * (total_ms / span)
    wanted = np.append(np.arange(0.0, total_ms, period_ms), total_ms)
    xs = np.interp(wanted, scaled, [s.x for s in samples])
    ys = np.interp(wanted, scaled, [s.y for s in samples])
    pressure = samples[0].pressure
    return tuple(
        Sample(float(t), float(x), float(y), pressure)
        for t, x, y in zip(wanted, xs, ys, strict=True)
    )
