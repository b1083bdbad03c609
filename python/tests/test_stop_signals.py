"""A stop signal stops, whatever the main thread holds when it comes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from collections.abc import Iterator

import pytest

from feelmysign.services.stop_signals import STOP_SIGNALS, call_on_stop_signals


@pytest.fixture
def restored_handlers() -> Iterator[None]:
    before = {number: signal.getsignal(number) for number in STOP_SIGNALS}
    yield
    for number, handler in before.items():
        signal.signal(number, handler)


HOLDING = """
import os, signal, threading
from feelmysign.services.stop_signals import call_on_stop_signals
stopped = threading.Event()
call_on_stop_signals(stopped.set)
with stopped._cond:  # what Event.wait() holds between its first steps
    os.kill(os.getpid(), signal.SIGTERM)
    for _ in range(1000):  # Python steps, in which the handler runs
        pass
print("stopped" if stopped.wait(10) else "not stopped")
"""


def test_a_signal_while_the_main_thread_holds_the_stop_events_lock_still_stops() -> None:
    # The sleeve's main thread waits on a threading.Event, and its stop sets that Event. A
    # signal that comes while the main thread is inside the Event's wait(), holding the
    # Event's lock, must not make the handler wait for that lock on the same thread: the
    # process would then never stop, by this signal or any later one (its own process, so
    # that such a hang fails here instead of hanging the tests).
    done = subprocess.run(
        [sys.executable, "-c", HOLDING], capture_output=True, text=True, timeout=60
    )
    assert (done.returncode, done.stdout.strip()) == (0, "stopped"), done.stderr


@pytest.mark.parametrize("number", STOP_SIGNALS)
def test_every_stop_signal_stops(restored_handlers: None, number: signal.Signals) -> None:
    stopped = threading.Event()
    call_on_stop_signals(stopped.set)
    os.kill(os.getpid(), number)
    assert stopped.wait(10)
