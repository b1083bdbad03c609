"""Rate-limited actuator telemetry: what the sleeve feels, for previews (MQTT ``actuators``).

The player changes intensities from its real-time thread, up to thousands of
times a second; a browser preview needs a few frames a second. The backend
calls :meth:`ActuatorTelemetry.update` on every change: it only stores the
latest grid (a copy, under a short lock) and never calls the publisher. The
publisher runs elsewhere: on the limiter's own thread (:meth:`start`), or from
the caller's loop through :meth:`poll`. Changes between two frames coalesce;
the last state of a burst is always published, one interval after the frame
before it at the latest. The daemon, for instance::

    telemetry = ActuatorTelemetry(
        lambda frame: client.publish(telemetry_topic(sleeve_id, "actuators"),
                                     json.dumps(frame.as_dict())),
        rate_hz=20.0,
    )
    telemetry.start()
    backend = SimBackend(layout, telemetry=telemetry)  # or Drv2605Backend: same preview
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from feelmysign.clock import monotonic_ms
from feelmysign.errors import ParameterError
from feelmysign.lifecycle import Started

_log = logging.getLogger(__name__)

DEFAULT_RATE_HZ = 20.0  # one frame every 50 ms: smooth enough for a preview, cheap on MQTT


@dataclass(frozen=True)
class ActuatorFrame:
    """Every actuator's intensity at ``t_ms`` (the backend clock's time of the latest change).

    ``intensities[row][column]`` in [0, 1]; tuples, so a frame can cross threads safely.
    """

    t_ms: float
    intensities: tuple[tuple[float, ...], ...]

    def as_dict(self) -> dict[str, object]:
        """A JSON-ready form, e.g. for the daemon's ``feelmysign/<id>/actuators`` payload."""
        return {
            "t_ms": self.t_ms,
            "rows": len(self.intensities),
            "columns": len(self.intensities[0]) if self.intensities else 0,
            "intensities": [list(row) for row in self.intensities],
        }


class ActuatorTelemetry(Started):
    """Hands the latest actuator grid to ``publish`` at most ``rate_hz`` times a second.

    ``clock`` returns milliseconds. :meth:`start` runs the publisher on a daemon
    thread, which waits in real time, so use it with the default clock; tests
    inject a clock and call :meth:`poll` instead.
    """

    def __init__(
        self,
        publish: Callable[[ActuatorFrame], None],
        *,
        rate_hz: float = DEFAULT_RATE_HZ,
        clock: Callable[[], float] = monotonic_ms,
    ) -> None:
        if not (math.isfinite(rate_hz) and rate_hz > 0):
            raise ParameterError("rate_hz", rate_hz, "a positive number of frames per second")
        self._publish = publish
        self._interval_ms = 1000.0 / rate_hz
        self._clock = clock
        self._wake = threading.Condition(threading.Lock())
        self._pending: ActuatorFrame | None = None
        self._last_publish_ms: float | None = None
        self._thread: threading.Thread | None = None
        self._stopping = False
        self.changes = 0  # updates received
        self.frames_published = 0
        self.publish_errors = 0

    @property
    def interval_ms(self) -> float:
        return self._interval_ms

    def update(self, grid: Sequence[Sequence[float]]) -> None:
        """Store the latest grid (real-time thread side): cheap, never waits for the publisher."""
        frame = ActuatorFrame(self._clock(), tuple(tuple(row) for row in grid))
        with self._wake:
            self._pending = frame
            self.changes += 1
            self._wake.notify()

    def due_in_ms(self) -> float | None:
        """Milliseconds until :meth:`poll` would publish (0: now), None when nothing is pending."""
        with self._wake:
            return self._due_in_ms_locked(self._clock())

    def poll(self) -> bool:
        """Publish the pending frame if the rate allows; True when a frame was published."""
        with self._wake:
            due_in_ms = self._due_in_ms_locked(self._clock())
            frame = self._take_locked() if due_in_ms is not None and due_in_ms <= 0 else None
        return self._deliver(frame)

    def flush(self) -> bool:
        """Publish the pending frame now, whatever the rate (at shutdown)."""
        with self._wake:
            frame = self._take_locked()
        return self._deliver(frame)

    def start(self) -> None:
        """Publish from a background daemon thread until :meth:`stop`."""
        with self._wake:
            if self._thread is not None:
                return
            self._stopping = False
            self._thread = threading.Thread(
                target=self._run, name="feelmysign-telemetry", daemon=True
            )
        self._thread.start()

    def stop(self) -> None:
        """Stop the thread, then publish whatever is still pending."""
        with self._wake:
            thread, self._thread = self._thread, None
            self._stopping = True
            self._wake.notify()
        if thread is not None:
            thread.join()
        self.flush()

    def _due_in_ms_locked(self, now_ms: float) -> float | None:
        if self._pending is None:
            return None
        if self._last_publish_ms is None:
            return 0.0
        return max(0.0, self._last_publish_ms + self._interval_ms - now_ms)

    def _take_locked(self) -> ActuatorFrame | None:
        frame, self._pending = self._pending, None
        if frame is not None:
            self._last_publish_ms = self._clock()
        return frame

    def _deliver(self, frame: ActuatorFrame | None) -> bool:
        if frame is None:
            return False
        try:
            self._publish(frame)
        except Exception:
            # A preview that fails must never stop the sleeve: count it, log it, go on.
            self.publish_errors += 1
            _log.exception("publishing actuator telemetry failed")
            return False
        self.frames_published += 1
        return True

    def _run(self) -> None:
        while True:
            with self._wake:
                frame = None
                while not self._stopping and frame is None:
                    due_in_ms = self._due_in_ms_locked(self._clock())
                    if due_in_ms is None:
                        self._wake.wait()
                    elif due_in_ms > 0:
                        self._wake.wait(due_in_ms / 1000.0)
                    else:
                        frame = self._take_locked()
                if frame is None:
                    return
            self._deliver(frame)
