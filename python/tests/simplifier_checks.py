"""What the tests of both simplifiers (angle, window) check the same way.

The vectors' comparison, the random pointer walk the properties draw, and the
properties every simplifier keeps through the shared segment rules: segments
join from the press to the release, and a dropped one says why.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import pytest
from hypothesis import strategies as st

from feelmysign.simplify import Sample, Segment, simplify_paths
from feelmysign.simplify.registry import Params as SimplifierParams
from feelmysign.simplify.segment import NOT_ENOUGH_DISTANCE, NOT_ENOUGH_DURATION
from feelmysign.stroke import Point

CANVAS_WIDTH_PX = 800
CANVAS_HEIGHT_PX = 600


def run(params: SimplifierParams, paths: list[list[Sample]]) -> list[tuple[int, Segment]]:
    return [(p.path, p.segment) for p in simplify_paths(params, paths)]


def check_vector(
    name: str, case: dict[str, Any], params: SimplifierParams, paths: list[list[Sample]]
) -> None:
    """Every segment of a vector (path, dropped reason, ends, times) within its tolerance."""
    actual = run(params, paths)
    expected = case["expected"]["segments"]
    assert len(actual) == len(expected), name
    for (path, segment), want in zip(actual, expected, strict=True):
        assert path == want["path"] and segment.dropped == want["dropped"]
        assert segment.merged == want.get("merged", 0), name
        got = [
            *segment.start,
            *segment.end,
            segment.start_ms,
            segment.end_ms,
            segment.emitted_at_ms,
            # The window simplifier's: how long the sleeve is to play it (the angle's: as drawn).
            segment.duration_ms,
        ]
        wanted = [
            *want["start"],
            *want["end"],
            want["start_ms"],
            want["end_ms"],
            want["emitted_at_ms"],
            want.get("duration_ms", want["end_ms"] - want["start_ms"]),
        ]
        assert got == pytest.approx(wanted, abs=case["tolerance"])


def random_walk(draw: st.DrawFn, *, margin_px: float, min_step_ms: float = 0.0) -> list[Sample]:
    """A pointer path of 2 to 151 samples, kept within margin_px of the 800 x 600 canvas."""
    count = draw(st.integers(1, 150))
    steps = draw(
        st.lists(
            st.tuples(st.floats(-40, 40), st.floats(-40, 40), st.floats(min_step_ms, 30)),
            min_size=count,
            max_size=count,
        )
    )
    low_x, high_x = -margin_px, CANVAS_WIDTH_PX + margin_px
    low_y, high_y = -margin_px, CANVAS_HEIGHT_PX + margin_px
    x, y, t_ms = draw(st.floats(low_x, high_x)), draw(st.floats(low_y, high_y)), 0.0
    samples = [Sample(t_ms, x, y)]
    for dx, dy, dt in steps:
        x, y, t_ms = min(max(x + dx, low_x), high_x), min(max(y + dy, low_y), high_y), t_ms + dt
        samples.append(Sample(t_ms, x, y))
    return samples


def assert_joined_from_press_to_release(
    params: SimplifierParams,
    samples: list[Sample],
    *,
    release_within: float = 0.0,
    rests: bool = False,
    release_on_last: bool = False,
) -> None:
    """Segments start at the press, end at the release (within release_within), and join.

    With ``release_on_last`` (the window simplifier's last piece merged at release into the
    stroke before it) the release lies within release_within of the last segment, not its end.

    With ``rests`` (the window simplifier's rest_ms and max_stroke_ms) a rest or a crawl is not
    played: a segment may start
    after the one before ends, the first after the press, the last end before the release."""
    segments = [s for _, s in run(params, [samples])]
    assert segments, "a path always gives at least one segment (sent or dropped)"
    mapping = params.mapping
    assert segments[0].start == mapping.to_grid(samples[0].x, samples[0].y)
    release = mapping.to_grid(samples[-1].x, samples[-1].y)
    last = segments[-1]
    if release_on_last:
        assert _distance_to(release, last.start, last.end) <= release_within
    else:
        assert math.dist(last.end, release) <= release_within
    if rests:
        assert segments[0].start_ms >= samples[0].t_ms
        assert segments[-1].end_ms <= samples[-1].t_ms
    else:
        assert segments[0].start_ms == samples[0].t_ms
        if release_on_last:  # the last piece, drawn after the last segment, merged into it
            assert segments[-1].end_ms <= samples[-1].t_ms
        else:
            assert segments[-1].end_ms == samples[-1].t_ms
    for before, after in itertools.pairwise(segments):
        assert after.start == before.end
        if rests:
            assert after.start_ms >= before.end_ms
        else:
            assert after.start_ms == before.end_ms


def _distance_to(point: tuple[float, float], start: Point, end: Point) -> float:
    """Distance from a point to the segment start -> end (its nearest point)."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    qx, qy = point[0] - start[0], point[1] - start[1]
    length_sq = dx * dx + dy * dy
    t = 0.0 if length_sq == 0 else min(max((qx * dx + qy * dy) / length_sq, 0.0), 1.0)
    return math.hypot(qx - t * dx, qy - t * dy)


def assert_dropped_say_why(params: SimplifierParams, samples: list[Sample]) -> None:
    """Sent strokes meet the minimums, a dropped one names the first it misses."""
    floor_ms = max(getattr(params, "floor_ms", 0.0), params.min_duration_ms)
    for _, segment in run(params, [samples]):
        if segment.dropped is None:
            assert segment.length >= params.min_length
            assert segment.duration_ms >= params.min_duration_ms
            # The window simplifier sends no stroke the sleeve must slow: one drawn briefer
            # than the floor lasts the floor, any other as long as it was drawn.
            assert segment.duration_ms >= floor_ms
            assert segment.duration_ms in (segment.drawn_ms, floor_ms)
            if segment.drawn_ms < floor_ms:
                assert segment.duration_ms == floor_ms
        elif segment.dropped == NOT_ENOUGH_DISTANCE:
            assert segment.length < params.min_length
        else:
            assert segment.dropped == NOT_ENOUGH_DURATION
            assert segment.duration_ms < params.min_duration_ms
        assert segment.emitted_at_ms >= segment.end_ms


def write_recording(case: dict[str, Any], path: Path) -> Path:
    """A vector's paths, canvas and sleeve written as a recording for ``feelmysign simplify``."""
    params = case["params"]
    document = {
        "canvas": {"width_px": params["canvas_width_px"], "height_px": params["canvas_height_px"]},
        "paths": [
            [{"t_ms": t, "x": x, "y": y, "pressure": p} for t, x, y, p in samples]
            for samples in case["paths"]
        ],
        "sleeve": {"rows": params["rows"], "columns": params["columns"]},
    }
    path.write_text(json.dumps(document))
    return path


def simplify_flags(algorithm: str, params: dict[str, Any], numbers: tuple[str, ...]) -> list[str]:
    """The ``feelmysign simplify`` options that ask for a vector's parameters: the ``numbers``
    named, and --stretch when the vector stretches."""
    flags = ["--algorithm", algorithm]
    for name in numbers:
        flags += ["--" + name.replace("_", "-"), repr(params[name])]
    return flags + (["--stretch"] if params["stretch"] else [])


# A square on a 900 x 600 canvas, corner to corner, closed.
SQUARE_CORNERS_PX = [(150, 100), (750, 100), (750, 500), (150, 500), (150, 100)]


def square_path(sample_ms: float) -> list[Sample]:
    """The square drawn with 40 samples a side, ``sample_ms`` apart, ending on its first corner."""
    points = [
        (x0 + (x1 - x0) * k / 40, y0 + (y1 - y0) * k / 40)
        for (x0, y0), (x1, y1) in itertools.pairwise(SQUARE_CORNERS_PX)
        for k in range(40)
    ] + [SQUARE_CORNERS_PX[-1]]
    return [Sample(i * sample_ms, x, y) for i, (x, y) in enumerate(points)]


def assert_four_strokes_on_the_corners(params: SimplifierParams, segments: list[Segment]) -> None:
    """The square's four sides, all sent, each from one corner to the next."""
    grid = [params.mapping.to_grid(x, y) for x, y in SQUARE_CORNERS_PX]
    assert [s.dropped for s in segments] == [None] * 4
    for segment, (a, b) in zip(segments, itertools.pairwise(grid), strict=True):
        assert segment.start == pytest.approx(a) and segment.end == pytest.approx(b)
