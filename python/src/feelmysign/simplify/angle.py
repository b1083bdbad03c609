"""The angle simplifier: the online algorithm of "Can You Feel My Sign?" (section 4.4, B.4).

Every ``check_frames`` frames it compares the direction of the line drawn so
far (start -> pointer) with the direction of the latest movement (pointer at
the last check -> pointer). When they differ by more than ``max_angle_deg`` the
line up to the last check is finished and a new one begins there. Pure and
streaming: ``push`` one animation frame at a time (canvas pixels, with its real
time), ``end`` on release; both return the segments finished by that call.

Where the paper's pseudo-code is ambiguous the reading taken keeps consecutive
strokes joined end to start; each choice is written down in docs/research.md:

1. Counters start at zero on press, so the first check comes ``check_frames``
   frames after it (and passes: start and last check are the same point).
2. A failed check (``recover`` on) finishes start -> last check, and the new
   line begins at the last check with the movement since then as its first
   checked leg. With ``recover`` off the new line begins at the pointer and the
   movement since the last check is not sent (the paper's gaps).
3. ``frame_max`` cuts the line at the pointer and restarts checking there.
4. On release, a last check decides whether the rest is one line or two.
5. A finished line too short (grid units) or too brief (ms) is dropped with
   its reason; it still ends where the next one starts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from feelmysign.simplify.mapping import CanvasMapping
from feelmysign.simplify.params import ParamSpec, SharedParams, param, specs_of
from feelmysign.simplify.segment import Sample, Segment, finish_segment

# Movements shorter than this (pixels) have no direction.
STILL_PX = 1e-9


@dataclass(frozen=True)
class _AngleOwn:
    """The paper's own parameters of its algorithm (appendix B.1), with its defaults."""

    check_frames: int = param(
        5,
        2,
        600,
        help="frames between two checks (the paper's checkFrame)",
        label="Check frames",
        unit="frames",
        paper="checkFrame",
        short="chk",
    )
    max_angle_deg: float = param(
        20.0,
        1,
        179,
        help="largest turn, in degrees, that continues a line",
        label="Max angle",
        unit="°",
        paper="maxAngleDifDeg",
        detail_levels=(60, 45, 30, 20, 12),
        short="deg",
    )
    frame_max: int = param(
        0,
        0,
        36_000,
        help="longest line in frames; 0 = no limit",
        label="Frame max",
        unit="frames",
        paper="frameMax",
        short="fmax",
    )
    fps: float = param(
        60.0,
        1,
        1000,
        help="frames per second of the drawing loop",
        label="Frames per second",
        unit="fps",
        paper="fps",
    )
    recover: bool = param(
        True,
        help="start a new line at the last check (no gaps)",
        label="Recover",
        paper="recover",
    )


@dataclass(frozen=True)
class AngleParams(SharedParams, _AngleOwn):
    """The paper's parameters (appendix B.1) with its defaults, named with their units."""


ANGLE_PARAMS: dict[str, ParamSpec] = specs_of(AngleParams)

# The grid ``feelmysign evaluate`` sweeps without --sweep: around the paper's defaults (check 5
# frames, 20 degrees), small enough for all 210 LASA demonstrations in a minute or two.
SWEEPS = ("max_angle_deg=10:40:10", "check_frames=5:15:5")


def describe(params: AngleParams) -> str:
    """The settings that shape the strokes, in a few words."""
    return (
        f"angle: check every {params.check_frames} frames, max {params.max_angle_deg:g} deg, "
        f"{params.fps:g} fps"
    )


@dataclass
class _Line:
    """The line being drawn: where it starts and where its last passed check was."""

    start: Sample
    last: Sample
    frames_since_check: int = 0
    frames_in_line: int = 0


@dataclass
class AngleSimplifier:
    params: AngleParams = field(default_factory=AngleParams)
    _line: _Line | None = None
    _pointer: Sample | None = None
    _cos_max: float = field(init=False)
    _mapping: CanvasMapping = field(init=False)

    def __post_init__(self) -> None:
        self._cos_max = math.cos(math.radians(self.params.max_angle_deg))
        self._mapping = self.params.mapping

    @property
    def drawing(self) -> bool:
        """True between the first frame of a path and ``end``."""
        return self._line is not None

    def push(self, frame: Sample) -> list[Segment]:
        """One animation frame while the pointer is down; the first frame of a path is the press."""
        self._pointer = frame
        line = self._line
        if line is None:
            self._line = _Line(start=frame, last=frame)
            return []
        out: list[Segment] = []
        line.frames_since_check += 1
        line.frames_in_line += 1
        if line.frames_since_check >= self.params.check_frames:
            self._check(line, frame, out)
        if self.params.frame_max and line.frames_in_line > self.params.frame_max:
            out.append(self._finish(line.start, frame))
            self._line = _Line(start=frame, last=frame)
        return out

    def end(self) -> list[Segment]:
        """Release: the rest of the path as one line, or two if it turned since the last check."""
        line, pointer = self._line, self._pointer
        self._line = None
        if line is None or pointer is None:
            return []
        if line.last is not line.start and self._turned(line, pointer):
            return [self._finish(line.start, line.last), self._finish(line.last, pointer)]
        return [self._finish(line.start, pointer)]

    def _check(self, line: _Line, frame: Sample, out: list[Segment]) -> None:
        if self._turned(line, frame):
            out.append(self._finish(line.start, line.last))
            if self.params.recover:
                line.start, line.frames_in_line = line.last, line.frames_since_check
            else:
                line.start, line.frames_in_line = frame, 0
        line.last = frame
        line.frames_since_check = 0

    def _turned(self, line: _Line, frame: Sample) -> bool:
        """Whether start -> frame and last check -> frame differ by more than the maximum angle."""
        ux, uy = frame.x - line.start.x, frame.y - line.start.y
        vx, vy = frame.x - line.last.x, frame.y - line.last.y
        moved = math.sqrt(vx * vx + vy * vy)
        if moved <= STILL_PX:
            return False  # the pointer rested since the last check: no new direction
        line_so_far = math.sqrt(ux * ux + uy * uy)
        if line_so_far <= STILL_PX:
            return True  # it moved, back onto the line's start: a full reversal
        return (ux * vx + uy * vy) / (line_so_far * moved) < self._cos_max

    def _finish(self, start: Sample, end: Sample) -> Segment:
        return finish_segment(
            self._mapping.to_grid(start.x, start.y),
            self._mapping.to_grid(end.x, end.y),
            start.t_ms,
            end.t_ms,
            self._pointer.t_ms if self._pointer else end.t_ms,
            min_length=self.params.min_length,
            min_duration_ms=self.params.min_duration_ms,
        )
