"""Signals that stop a command which may have motors on: Ctrl-C, SIGTERM and SIGHUP alike.

SIGHUP matters: closing the ssh session that runs the sleeve sends it, and a
DRV2605L in real-time mode keeps its last level until told otherwise.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Callable
from types import FrameType

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def call_on_stop_signals(stop: Callable[[], None]) -> None:
    """Run ``stop`` (which must only ask to stop, and may be asked again) when any stop
    signal arrives.

    ``stop`` runs on a thread of its own, not in the signal handler. A Python handler runs on
    the main thread between two of its steps, whatever that thread holds: a ``stop`` that
    sets a ``threading.Event`` would wait for ever on the Event's lock if the signal came
    while the main thread was inside that Event's ``wait()`` holding it. The handler only
    writes a byte to a pipe, which takes no lock.
    """
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)

    def relay() -> None:
        while os.read(read_fd, 1):
            stop()

    threading.Thread(target=relay, name="feelmysign-stop-signals", daemon=True).start()

    def handler(signum: int, frame: FrameType | None) -> None:
        # Thousands of signals not yet relayed: one more changes nothing.
        with contextlib.suppress(BlockingIOError):
            os.write(write_fd, b"s")

    for stop_signal in STOP_SIGNALS:
        signal.signal(stop_signal, handler)


def interrupt_on_stop_signals() -> None:
    """Make SIGTERM and SIGHUP raise KeyboardInterrupt, as Ctrl-C does, so ``finally`` runs."""

    def handler(signum: int, frame: FrameType | None) -> None:
        raise KeyboardInterrupt(signal.Signals(signum).name)

    for stop_signal in STOP_SIGNALS[1:]:
        signal.signal(stop_signal, handler)
