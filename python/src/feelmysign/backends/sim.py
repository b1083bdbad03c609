"""The simulator backend: records what the sleeve would have felt, change by change.

It has the hardware backend's interface (``--backend sim``), so the player
never knows which one it drives. Every change is kept with its time on an
injected clock, relative to when the backend was opened; with ``record`` it is
also appended to a JSON-lines file, one line per change and flushed line by
line, so that a crash loses at most the line being written. ``wall_ms`` is the
same moment on the wall clock (ms since the Unix epoch), to line a record up
with the sleeve's events and the sender's ``sent_at_ms``; ``drawing`` and
``seq`` name the stroke whose command made the change (null for a change no
stroke made, such as the all-off at exit, and for legacy strokes). Only changes
are lines: a stroke that starts where the one before it ends, on the motors
that one still drives at the same intensity, takes them over without a line of
its own (its first line is its next change, or its motors going off):

    {"t_ms": 12.5, "wall_ms": 1795410070998.5, "row": 0, "column": 3, "intensity": 0.8,
     "drawing": "3f2a9c1e-...", "seq": 4}
"""

from __future__ import annotations

import json
import os
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from feelmysign.backends.base import GridBackend
from feelmysign.backends.telemetry import ActuatorTelemetry
from feelmysign.clock import monotonic_ms, wall_ms
from feelmysign.errors import ParameterError
from feelmysign.layout import Layout

DEFAULT_KEEP_CHANGES = 100_000  # about an hour of dense drawing; the record file keeps everything
_T_DECIMALS = 3  # microseconds: finer than any clock the player is measured against


@dataclass(frozen=True)
class RecordedChange:
    """One actuator's intensity changed at ``t_ms`` after the backend was opened.

    What the sleeve did, as the simulator saw it: not :class:`feelmysign.timeline.Change`,
    the player's order to change an intensity at a planned time on its own clock (with the
    stroke that ordered it). A recorded change is measured from the backend's opening, so
    its time includes the player's lateness; the two stay apart so that a record is never
    mistaken for the plan it is compared with.
    """

    t_ms: float
    row: int
    column: int
    intensity: float

    def as_dict(self) -> dict[str, float | int]:
        return {
            "t_ms": self.t_ms,
            "row": self.row,
            "column": self.column,
            "intensity": self.intensity,
        }


class SimBackend(GridBackend):
    """Keeps the intensity grid, the recent changes, and optionally a JSON-lines record.

    ``clock`` returns milliseconds; ``keep_changes`` bounds the changes held in
    memory (None = unbounded), so a sleeve that runs for days does not grow.
    """

    def __init__(
        self,
        layout: Layout,
        *,
        clock: Callable[[], float] = monotonic_ms,
        record: str | os.PathLike[str] | None = None,
        telemetry: ActuatorTelemetry | None = None,
        keep_changes: int | None = DEFAULT_KEEP_CHANGES,
        wall_clock: Callable[[], float] = wall_ms,
    ) -> None:
        super().__init__(layout, telemetry=telemetry)
        if keep_changes is not None and keep_changes < 0:
            raise ParameterError("keep_changes", keep_changes, "0 or more, or None to keep all")
        self._clock = clock
        self._record_path = Path(record) if record is not None else None
        self._record: TextIO | None = None
        self._changes: deque[RecordedChange] = deque(maxlen=keep_changes)
        self._changes_lock = threading.Lock()
        self._start_ms = 0.0
        self._wall_clock = wall_clock
        self._wall_start_ms = 0.0
        self._source: tuple[object, object] = (None, None)

    @property
    def record_path(self) -> Path | None:
        return self._record_path

    @property
    def changes(self) -> list[RecordedChange]:
        """The recorded changes, oldest first (at most ``keep_changes``)."""
        with self._changes_lock:
            return list(self._changes)

    def _open(self) -> None:
        if self._record_path is not None:
            # Line buffering: every change reaches the file when its line ends.
            self._record = self._record_path.open("w", encoding="utf-8", buffering=1)
        self._start_ms = self._clock()
        self._wall_start_ms = self._wall_clock()

    def _write(self, row: int, column: int, intensity: float) -> None:
        t_ms = round(self._clock() - self._start_ms, _T_DECIMALS)
        change = RecordedChange(t_ms, row, column, intensity)
        with self._changes_lock:
            self._changes.append(change)
        if self._record is not None:
            # The wall clock read once, at opening: a clock step cannot reorder the record.
            wall_ms = round(self._wall_start_ms + t_ms, _T_DECIMALS)
            drawing, seq = self._source
            line = {"t_ms": t_ms, "wall_ms": wall_ms, **change.as_dict()}
            self._record.write(json.dumps({**line, "drawing": drawing, "seq": seq}) + "\n")
        self._source = (None, None)  # one note, one change: the next write is told anew

    def note_source(self, drawing: object, seq: object) -> None:
        """The stroke (``drawing``, ``seq``) whose command the next change is, for the record.

        Called by the player before each write; the hardware backend has no record and
        no such method.
        """
        self._source = (drawing, seq)

    def _all_off(self) -> None:
        for row, intensities in enumerate(self.snapshot()):
            for column, intensity in enumerate(intensities):
                if intensity != 0.0:
                    self._write(row, column, 0.0)

    def _release(self) -> None:
        if self._record is not None:
            self._record.close()
            self._record = None
