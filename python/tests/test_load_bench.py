"""The load bench's own code, on a few sleeves: worker processes, the outcome of every
stroke, and the figures' lines. ``make load`` runs it at N = 20, 100 and 200."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from test_cli_bad_input import TIMEOUT_S, assert_one_error

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


@pytest.mark.parametrize(
    ("counts", "says"),
    [
        (["0"], "N: 0 is out of range; give a whole number from 1 to 1000"),
        (["20", "abc"], "N: 'abc' is not a whole number"),
        (["1001"], "1001 is out of range"),
        (["--strokes", "5"], "unrecognized arguments: --strokes"),
    ],
)
def test_a_bad_n_is_one_error_line_before_anything_starts(counts: list[str], says: str) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "feelmysign.bench.load", *counts],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert done.returncode == 2 and done.stdout == "", done.stdout
    assert_one_error(done, says, "--help")


def test_the_counts_default_to_20_100_and_200() -> None:
    assert load.parse_counts([]) == (20, 100, 200)
    assert load.parse_counts([" 5", "7"]) == (5, 7)
