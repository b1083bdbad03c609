"""Signals that stop a command which may have motors on: Ctrl-C, SIGTERM and SIGHUP alike.

SIGHUP matters: closing the ssh session that runs the sleeve sends it, and a
DRV2605L in real-time mode keeps its last level until told otherwise.
"""

from __future__ import annotations

import signal
from collections.abc import Callable
from types import FrameType

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def call_on_stop_signals(stop: Callable[[], None]) -> None:
    """Run ``stop`` (which must only ask to stop) when any stop signal arrives."""

    def handler(signum: int, frame: FrameType | None) -> None:
        stop()

    for stop_signal in STOP_SIGNALS:
        signal.signal(stop_signal, handler)


def interrupt_on_stop_signals() -> None:
    """Make SIGTERM and SIGHUP raise KeyboardInterrupt, as Ctrl-C does, so ``finally`` runs."""

    def handler(signum: int, frame: FrameType | None) -> None:
        raise KeyboardInterrupt(signal.Signals(signum).name)

    for stop_signal in STOP_SIGNALS[1:]:
        signal.signal(stop_signal, handler)
