"""The load bench's own code, on a few sleeves: worker processes, the outcome of every
stroke, and the figures' lines. ``make load`` runs it at N = 20, 100 and 200."""

from __future__ import annotations

from pathlib import Path

import pytest

from feelmysign.bench import load
from feelmysign.bench.load_hosts import STROKES
from feelmysign.broker.credentials import Account

pytestmark = pytest.mark.broker

COUNT = 3


def test_every_stroke_of_a_small_load_run_is_received_then_played_or_reported(
    tmp_path: Path,
) -> None:
    with load.mosquitto(COUNT, tmp_path) as target:
        base = load.baseline(target)
        played = load.sleeves(target)
    assert base.sent == played.sent == COUNT * STROKES
    assert (base.lost, base.unacknowledged, len(base.latencies_ms)) == (0, 0, base.sent)
    # A busy machine may make a sleeve refuse a stroke as late; it is reported, not lost.
    assert played.lost == 0 and played.twice == 0 and played.unacknowledged == 0
    assert len(played.latencies_ms) + sum(played.refused.values()) == played.sent
    assert all(latency > 0 for latency in played.latencies_ms)
    assert played.cpu_s > 0
    line = load._line("publish -> played (sleeve)", played, base)
    assert f"played {len(played.latencies_ms)}/{played.sent}, lost 0" in line


def test_clients_start_on_every_server_of_a_cluster_in_turn() -> None:
    urls = ("mqtt://a:1", "mqtt://b:2", "mqtt://c:3")
    target = load.Target("cluster", urls, Account("sender", "unused"), {})
    assert target.url_for(0) == "mqtt://a:1,mqtt://b:2,mqtt://c:3"
    assert target.url_for(4) == "mqtt://b:2,mqtt://c:3,mqtt://a:1"
