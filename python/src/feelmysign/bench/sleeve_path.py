"""The sleeve's own path, from a stroke's message to its first motor command, without a broker.

Feeds stroke messages of the sleeve bench's lengths (1, 3, 10 and 30 cm, see
:mod:`feelmysign.bench.sleeve`) to the daemon's message handler, one at a time
to an idle sleeve, on this thread: the code a stroke meets in the sleeve, with
the player's thread left out so that every run takes the same path. Each stroke
is cancelled once its handler returns, off the measured path.

Prints the CPU time of this thread (not the wall clock: other processes do not
count) from receipt to the first actuator write and for the whole handler, per
length. The machine's noise still shows in it; for decisions, count
instructions, which do not vary from run to run: under valgrind, with the
sleeve's clock slowed as much as valgrind slows the program (``SLOW``), so
that the handler sees the clock readings it sees natively::

    SLOW=100 valgrind --tool=callgrind --dump-before=math_comb \\
        --dump-before=math_perm --dump-before=math_lcm \\
        python -m feelmysign.bench.sleeve_path 30

Every dump then holds one stretch: one triggered by ``math_perm`` from a
message's receipt (``math.comb``) to its first actuator write (``math.perm``),
one triggered by ``math_lcm`` the rest of its handler (up to ``math.lcm``).
"""

from __future__ import annotations

import gc
import math
import os
import statistics
import sys
import tempfile
import time
import uuid
from typing import Any

import paho.mqtt.client as mqtt

import feelmysign.daemon
from feelmysign.backends.sim import SimBackend
from feelmysign.bench.sleeve import LENGTHS, PAPER
from feelmysign.clock import wall_ms
from feelmysign.connection import BrokerSettings
from feelmysign.control import Cancel
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.layout import Layout
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic

WIDE = Layout(rows=3, columns=12, spacing_cm=3.0)  # the bench's 30 cm sleeve
WARM_UP = 5  # strokes first, unmeasured
SLEEVE_ID = "path"


def _slow() -> float:
    return float(os.environ.get("SLOW", "1"))


class _Marking(SimBackend):
    """Marks its first write after each receipt (``math.perm``, for callgrind) and its time."""

    first_at_ns: int | None = None

    def set_intensity(self, row: int, column: int, intensity: float) -> None:
        if self.first_at_ns is None:
            math.perm(2, 1)
            self.first_at_ns = time.thread_time_ns()
        super().set_intensity(row, column, intensity)


def run(label: str, shape: Any, layout: Layout, count: int) -> str:
    slow = _slow()

    def clock_ms() -> float:
        return time.monotonic_ns() / 1e6 / slow

    # The daemon reads its receipt time from both_ms, the player from its clock: both slowed.
    feelmysign.daemon.both_ms = lambda: (clock_ms(), wall_ms())  # type: ignore[attr-defined]
    backend = _Marking(layout)
    state = tempfile.mkdtemp()
    options = SleeveOptions(
        sleeve_id=SLEEVE_ID,
        rate_per_s=1e6,
        burst=10**6,
        controls_path=os.path.join(state, "controls.json"),
    )
    settings = BrokerSettings(host="localhost", port=1883, sleeve_id=SLEEVE_ID)
    sleeve = Sleeve(settings, layout, backend, options)
    player = sleeve.player
    player._clock = clock_ms
    # The player's state as started, without its thread: this thread plays the first commands.
    backend.open()
    player._running = True
    start, end, duration_ms = shape
    topic = strokes_topic(SLEEVE_ID).encode()
    gc.freeze()
    first_us: list[float] = []
    whole_us: list[float] = []
    for k in range(count + WARM_UP):
        drawing = f"path-{uuid.uuid4()}"
        message = mqtt.MQTTMessage(mid=k + 1, topic=topic)
        message.payload = format_json(Stroke(start, end, duration_ms, None, drawing, 0)).encode()
        message.qos = 1
        backend.first_at_ns = None
        math.comb(2, 1)
        started_ns = time.thread_time_ns()
        sleeve._on_message(None, None, message)  # type: ignore[arg-type]
        ended_ns = time.thread_time_ns()
        math.lcm(2, 1)
        if k >= WARM_UP and backend.first_at_ns is not None:
            first_us.append((backend.first_at_ns - started_ns) / 1e3)
            whole_us.append((ended_ns - started_ns) / 1e3)
        # Idle again, off the measured path: the stroke cancelled, its commitments dropped.
        player.cancel(Cancel(drawing), 0.0)
        with player._play_lock:
            player._take_inbox()
            player._apply_cancels()
            player._timeline.complete()
        player._timeline.duty_cycle.clear()
        while not sleeve._outbox.empty():
            sleeve._outbox.get()
        backend.all_off()
        gc.collect()
    backend.close()
    return (
        f"{label:>6}: receipt -> first command {statistics.median(first_us):7.1f} us CPU (p50), "
        f"whole handler {statistics.median(whole_us):7.1f} us (n={len(first_us)})"
    )


def main(argv: list[str]) -> None:
    """``python -m feelmysign.bench.sleeve_path [N [LENGTH ...]]``: N strokes (default 100)
    of each length, or of the lengths named (``1cm``, ``30cm``...)."""
    count = int(argv[0]) if argv else 100
    wanted = argv[1:]
    for label, shape, _, grid in LENGTHS:
        if wanted and label.replace(" ", "") not in wanted:
            continue
        print(run(label, shape, WIDE if grid else PAPER, count), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
