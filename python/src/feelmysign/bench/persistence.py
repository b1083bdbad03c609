"""Broker persistence: what saving after every change costs a stroke's round trip.

``feelmysign broker`` has Mosquitto save its state after every change
(``autosave_on_changes``), so a stroke it acknowledged survives a SIGKILL. This
times, against a real Mosquitto on loopback, a sender publishing strokes with
QoS 1 one after the other, each waiting for its acknowledgement, while a
sleeve's persistent session (a subscriber) receives them: once with saving every
change, once with the former save every 60 s (the baseline, same run).

    python -m feelmysign.bench.persistence [STROKES]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

from feelmysign.bench._mqtt import close
from feelmysign.broker import Broker
from feelmysign.connection import new_client
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic

STROKES = 300
ROUNDS = 3
WAIT_S = 10.0


def _round_trips_ms(broker: Broker, strokes: int) -> list[float]:
    c = broker.credentials
    sleeve = new_client(
        c.settings("sleeve"),
        client_id=f"bench-sleeve-{uuid.uuid4()}",
        persistent_session=True,
    )
    subscribed = threading.Event()
    sleeve.on_subscribe = lambda *_: subscribed.set()
    sleeve.on_connect = lambda client, *_: client.subscribe(strokes_topic(c.sleeve_id), 1)
    sleeve.connect(c.mqtt_host, c.mqtt_port)
    sleeve.loop_start()
    sender = new_client(
        c.settings("sender"),
        client_id=f"bench-sender-{uuid.uuid4()}",
    )
    sender.connect(c.mqtt_host, c.mqtt_port)
    sender.loop_start()
    try:
        if not subscribed.wait(WAIT_S):
            raise RuntimeError("the subscriber did not subscribe")
        times_ms = []
        for seq in range(strokes):
            payload = format_json(Stroke((0.0, 0.0), (1.0, 0.0), 100.0, None, "bench", seq))
            start_ns = time.perf_counter_ns()
            sender.publish(strokes_topic(c.sleeve_id), payload, qos=1).wait_for_publish(WAIT_S)
            times_ms.append((time.perf_counter_ns() - start_ns) / 1e6)
        return times_ms
    finally:
        close(sender, sleeve)


def measure(strokes: int = STROKES, rounds: int = ROUNDS) -> dict[bool, float]:
    """Median acknowledged round trip (ms), best of ``rounds``, by save-every-change."""
    best: dict[bool, float] = {}
    for _ in range(rounds):
        for every_change in (False, True):
            with (
                tempfile.TemporaryDirectory() as state,
                Broker(
                    state_dir=Path(state), port=0, ws_port=0, save_every_change=every_change
                ) as broker,
            ):
                median_ms = statistics.median(_round_trips_ms(broker, strokes))
            best[every_change] = min(best.get(every_change, float("inf")), median_ms)
    return best


def report(strokes: int = STROKES) -> list[str]:
    best = measure(strokes)
    baseline, saving = best[False], best[True]
    return [
        f"Broker persistence: QoS 1 stroke acknowledged, median of {strokes}, best of {ROUNDS}",
        f"  saved every 60 s (baseline)   {baseline:7.3f} ms   1.00x",
        f"  saved after every change      {saving:7.3f} ms   {saving / baseline:.2f}x",
    ]


if __name__ == "__main__":
    for line in report(int(sys.argv[1]) if len(sys.argv) > 1 else STROKES):
        print(line)
