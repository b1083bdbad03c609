"""The backend interface the player drives, and the checks and bookkeeping every backend shares.

The player calls a backend from one real-time thread, only when an
actuator's intensity changes. ``Backend`` is what it may rely on;
``GridBackend`` is the base of the two backends (``sim`` and ``drv2605``):
it checks arguments, skips writes that change nothing, keeps the grid of
current intensities, feeds the optional telemetry, and serialises calls with
a lock so that a shutdown from another thread cannot interleave with playback.
"""

from __future__ import annotations

import math
import threading
from abc import ABC, abstractmethod
from types import TracebackType
from typing import Literal, Protocol, TypeVar, runtime_checkable

from feelmysign.backends.telemetry import ActuatorTelemetry
from feelmysign.errors import ParameterError
from feelmysign.layout import Layout
from feelmysign.lifecycle import Closing

_B = TypeVar("_B", bound="Backend")
_G = TypeVar("_G", bound="GridBackend")


@runtime_checkable
class Backend(Protocol):
    """What the player drives: one intensity in [0, 1] per actuator of ``layout``'s grid."""

    @property
    def layout(self) -> Layout: ...

    def open(self) -> None:
        """Check the hardware and get every actuator ready, silent; idempotent."""

    def set_intensity(self, row: int, column: int, intensity: float) -> None:
        """Set one actuator; ParameterError (a ValueError) for a bad actuator or intensity."""

    def all_off(self) -> None:
        """Every actuator off, whatever the backend believes their state to be."""

    def close(self) -> None:
        """All off, then release the hardware; idempotent."""

    def snapshot(self) -> list[list[float]]:
        """A copy of the current intensities, ``[row][column]``."""
        ...

    def __enter__(self: _B) -> _B: ...

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None: ...


def check_intensity(intensity: float) -> float:
    """``intensity`` as a float; ParameterError (a ValueError) unless it is a number in [0, 1]."""
    try:
        value = float(intensity)
    except (TypeError, ValueError):
        value = math.nan
    if not (0.0 <= value <= 1.0):  # also rejects NaN
        raise ParameterError("intensity", intensity, "a number in [0, 1]")
    return value


def check_actuator(layout: Layout, row: int, column: int) -> None:
    """ParameterError (a ValueError) unless (row, column) is an actuator of ``layout``'s grid."""
    grid = f"the grid is {layout.rows} x {layout.columns}"
    if not (isinstance(row, int) and 0 <= row < layout.rows):
        raise ParameterError("row", row, f"an integer in 0..{layout.rows - 1} ({grid})")
    if not (isinstance(column, int) and 0 <= column < layout.columns):
        raise ParameterError("column", column, f"an integer in 0..{layout.columns - 1} ({grid})")


class GridBackend(Closing, ABC):
    """Shared behaviour of the backends; subclasses write to their output in ``_write``.

    Lifecycle: new -> open -> closed. ``set_intensity`` needs an open backend
    (``with backend:`` or ``open()``), so that the slow hardware checks never
    happen inside the real-time thread. ``all_off`` and ``close`` are safe in
    any state.
    """

    def __init__(self, layout: Layout, *, telemetry: ActuatorTelemetry | None = None) -> None:
        if layout.rows < 1 or layout.columns < 1:
            raise ValueError(
                f"a sleeve needs at least 1 row and 1 column, not {layout.rows} x {layout.columns}"
            )
        self._layout = layout
        self._telemetry = telemetry
        self._grid = [[0.0] * layout.columns for _ in range(layout.rows)]
        self._lock = threading.RLock()
        self._state: Literal["new", "open", "closed"] = "new"
        # Between hold_telemetry and release_telemetry: the grid changed and telemetry not told.
        self._holding = False
        self._unsent = False

    @property
    def layout(self) -> Layout:
        return self._layout

    @property
    def is_open(self) -> bool:
        return self._state == "open"

    def open(self) -> None:
        with self._lock:
            if self._state == "open":
                return
            if self._state == "closed":
                raise RuntimeError("this backend is closed; create a new one to play again")
            self._open()
            self._state = "open"

    def set_intensity(self, row: int, column: int, intensity: float) -> None:
        value = check_intensity(intensity)
        check_actuator(self._layout, row, column)
        with self._lock:
            if self._state != "open":
                raise RuntimeError(
                    f"the backend is {self._state}: open it first ('with backend:' or "
                    "backend.open())"
                )
            if self._grid[row][column] == value:
                return
            self._write(row, column, value)
            self._grid[row][column] = value
            if self._telemetry is not None:
                if self._holding:
                    self._unsent = True
                else:
                    self._telemetry.update(self._grid)

    def hold_telemetry(self) -> None:
        """The changes that follow are one step (the player's changes due at one time): the
        telemetry hears of them once, at ``release_telemetry``, after the last is written.
        Telling it copies the grid and wakes its thread, which then competes for the
        interpreter with the writes still to come: a burst's later motors waited for it."""
        self._holding = True

    def release_telemetry(self) -> None:
        """The step is written: the telemetry gets the grid as it now stands (if it changed)."""
        with self._lock:
            self._holding = False
            if self._unsent:
                self._unsent = False
                if self._telemetry is not None:
                    self._telemetry.update(self._grid)

    def all_off(self) -> None:
        with self._lock:
            if self._state != "open":
                return
            try:
                self._all_off()
            finally:
                # What was asked for is "off", even where a chip failed to hear it.
                self._grid = [[0.0] * self._layout.columns for _ in range(self._layout.rows)]
                if self._telemetry is not None:
                    self._telemetry.update(self._grid)

    def close(self) -> None:
        with self._lock:
            if self._state == "closed":
                return
            try:
                self.all_off()  # nothing to switch off unless open
            finally:
                self._state = "closed"
                self._release()

    def snapshot(self) -> list[list[float]]:
        with self._lock:
            return [list(row) for row in self._grid]

    def __enter__(self: _G) -> _G:
        self.open()
        return self

    @abstractmethod
    def _open(self) -> None:
        """Check and prepare the output; every actuator silent afterwards."""

    @abstractmethod
    def _write(self, row: int, column: int, intensity: float) -> None:
        """Output one changed intensity (already checked; differs from the current one)."""

    @abstractmethod
    def _all_off(self) -> None:
        """Switch every actuator off, trying all of them even when one fails."""

    @abstractmethod
    def _release(self) -> None:
        """Free what ``_open`` took (files, the bus); may run more than once."""
