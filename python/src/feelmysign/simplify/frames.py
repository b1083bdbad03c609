"""Animation frames from recorded samples: what a drawing loop at ``fps`` would have seen."""

from __future__ import annotations

from collections.abc import Sequence

from feelmysign.simplify.segment import Sample


def frames_from_samples(samples: Sequence[Sample], fps: float) -> list[Sample]:
    """One frame every 1000/fps ms from the first sample, holding the latest sample seen.

    The first sample (the press) is the first frame and the last sample (the
    release) the last, so a path's ends are never lost between two frames.
    """
    if not samples:
        return []
    period_ms = 1000.0 / fps
    t0 = samples[0].t_ms
    frames: list[Sample] = [samples[0]]
    index = 0
    k = 1
    while True:
        t_ms = t0 + k * period_ms
        if t_ms > samples[-1].t_ms:
            break
        while index + 1 < len(samples) and samples[index + 1].t_ms <= t_ms:
            index += 1
        held = samples[index]
        frames.append(Sample(t_ms, held.x, held.y, held.pressure))
        k += 1
    if index < len(samples) - 1:
        frames.append(samples[-1])
    return frames
