"""After a 10 s outage of the broker mid-drawing, the sleeve is back in real time at once.

The sender keeps drawing in real time through the outage (its client queues the
strokes and sends them when the broker is back). The sleeve refuses what is
older than ``max_age_ms`` (``stale``), skips what it is too late for (``late``)
and plays the rest no later than ``max_lag_ms`` after it was due.
"""

from __future__ import annotations

import time
from pathlib import Path

from conftest import StartBroker
from delivery import by_seq, delivery, played, stroke, wait_for

from feelmysign.pace import MAX_LAG_MS

DURATION_MS = 200.0
BEFORE_S, OUTAGE_S, AFTER_S = 3.0, 10.0, 5.0
SETTLE_S = 1.5  # once both are back: within this the sleeve must play every stroke on time


def test_the_sleeve_is_back_in_real_time_after_an_outage(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    with delivery(start_broker, tmp_path) as (broker, watcher, sleeve, sender):
        c = broker.credentials
        sent_at_s: list[float] = []
        back_s: float | None = None
        start_s = time.monotonic()
        restarted_wall_ms: float | None = None
        connections = 0
        while (now_s := time.monotonic()) - start_s < BEFORE_S + OUTAGE_S + AFTER_S:
            seq = len(sent_at_s)
            if broker.running and restarted_wall_ms is None and now_s - start_s >= BEFORE_S:
                broker.stop()
            elif not broker.running and now_s - start_s >= BEFORE_S + OUTAGE_S:
                restarted_wall_ms = time.time() * 1000
                connections = sender.connections
                broker = start_broker(
                    state_dir=tmp_path / "state", port=c.mqtt_port, ws_port=c.ws_port
                )
            elif (
                back_s is None
                and restarted_wall_ms is not None
                and watcher.is_online(restarted_wall_ms)
                and sender.connections > connections
            ):
                back_s = now_s
            sent_at_s.append(time.monotonic())
            sender.publish(
                seq, stroke(sender.drawing, seq, DURATION_MS, sent_at_ms=time.time() * 1000)
            )
            # Drawing time, not a wait for an event: the pace is the point.
            time.sleep(max(0.0, start_s + (seq + 1) * DURATION_MS / 1000 - time.monotonic()))
        assert back_s is not None
        count = len(sent_at_s)
        wait_for(
            lambda: len(by_seq(watcher.snapshot(), sender.drawing)) == count,
            "an event for every stroke",
        )
        events = by_seq(watcher.snapshot(), sender.drawing)
        reasons = [e.get("reason") for group in events.values() for e in group]
        assert {"late", "stale"} & set(reasons), "the outage left nothing to catch up"
        lags = [e["lag_ms"] for e in played(watcher.snapshot())]
        assert len(lags) >= (BEFORE_S + AFTER_S) * 1000 / DURATION_MS / 2
        assert max(lags) <= MAX_LAG_MS
        for seq, at_s in enumerate(sent_at_s):
            kinds = [e["type"] for e in events[seq]]
            assert kinds.count("played") + kinds.count("adjusted") <= 1, (seq, events[seq])
            if at_s >= back_s + SETTLE_S:
                assert "played" in kinds or "adjusted" in kinds, (seq, events[seq])
        assert sleeve.changes()
        after = [e for e in played(watcher.snapshot()) if sent_at_s[e["seq"]] >= BEFORE_S + start_s]
        print(  # the figures, for `pytest -s tests/test_delivery_outage.py`
            f"\noutage {OUTAGE_S:g} s: {reasons.count('stale')} stale, {reasons.count('late')} "
            f"late, {len(after)} of the strokes sent since the outage played; lag of those: "
            f"max {max((e['lag_ms'] for e in after), default=0):.0f} ms; both back "
            f"{(back_s - start_s - BEFORE_S - OUTAGE_S):.2f} s after the broker"
        )
