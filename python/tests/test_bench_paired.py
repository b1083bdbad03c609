"""The latency benchmarks' paired baseline, against a real Mosquitto and a real sleeve process:
a bare receiver of its own (a second sleeve's account, added before the broker starts) beside
the sleeve, its messages alternating with strokes in the same minutes; and how far chance
moves a ratio of paired samples."""

from __future__ import annotations

import statistics
from pathlib import Path

import pytest
from conftest import StartBroker

from feelmysign.bench._mqtt import close
from feelmysign.bench.relay import BARE, interleaved_latencies
from feelmysign.bench.sleeve import (
    SHORT,
    Strokes,
    _client,
    _sleeve_process,
    add_bare_account,
    bare_receiver,
    p99,
    paired_interval,
    paired_latencies,
)
from feelmysign.broker import Broker
from feelmysign.broker.credentials import Account


@pytest.fixture
def paired_broker(start_broker: StartBroker, tmp_path: Path) -> tuple[Broker, Account]:
    """A broker whose state holds the bare receiver's account, added before it starts."""
    account = add_bare_account(tmp_path / "broker")
    return start_broker(state_dir=tmp_path / "broker"), account


def test_the_bare_receiver_reads_its_own_topic_beside_the_sleeve(
    paired_broker: tuple[Broker, Account],
) -> None:
    broker, account = paired_broker
    c = broker.credentials
    sender = _client(c, "sender")
    try:
        with bare_receiver(c, account) as bare:
            # Each call checks that what came is the message it sent (else it raises).
            latencies = [bare.latency_ms(sender) for _ in range(3)]
    finally:
        close(sender)
    # Wall times of two processes of this machine: the receipt follows the publish.
    assert all(0.0 < ms < 5000.0 for ms in latencies), latencies


def test_strokes_and_bare_messages_alternate_at_each_length(
    paired_broker: tuple[Broker, Account],
) -> None:
    broker, account = paired_broker
    c = broker.credentials
    sender = _client(c, "sender")
    strokes = Strokes(c)
    try:
        with _sleeve_process(c, broker.credentials_path), bare_receiver(c, account) as bare:
            paired, events = paired_latencies(SHORT, 2, strokes, bare, sender)
    finally:
        strokes.close()
        close(sender)
    assert len(paired) == 2 and all(ms > 0.0 for ms in paired)
    assert len({e.drawing for _, e in events}) == 2
    # The sleeve's first command follows the publish, and its own share is part of that.
    for published_ms, event in events:
        assert event.first_command_at_ms - published_ms >= event.latency_ms > 0.0


def test_the_relay_groups_senders_and_baseline_are_measured_round_by_round(
    paired_broker: tuple[Broker, Account],
) -> None:
    broker, account = paired_broker
    c = broker.credentials
    senders = {"one TCP sender": _client(c, "sender"), "another": _client(c, "sender")}
    strokes = Strokes(c)
    try:
        with _sleeve_process(c, broker.credentials_path), bare_receiver(c, account) as bare:
            measured = interleaved_latencies(senders, bare, senders["another"], strokes, 2)
    finally:
        strokes.close()
        close(*senders.values())
    assert set(measured) == {BARE, *senders}
    assert all(len(values) == 2 and min(values) > 0.0 for values in measured.values()), measured


def test_a_ratio_that_chance_cannot_move_has_a_point_interval() -> None:
    baseline = [0.5 + 0.01 * i for i in range(100)]
    assert paired_interval(baseline, baseline, p99) == (1.0, 1.0)
    low, high = paired_interval([2 * x for x in baseline], baseline, statistics.median)
    assert low == pytest.approx(2.0) and high == pytest.approx(2.0)


def test_two_disturbed_samples_decide_a_p99_and_the_interval_shows_it() -> None:
    baseline = [0.5] * 100
    measured = [1.0] * 98 + [20.0, 30.0]  # the p99 of 100 is the second highest
    assert p99(measured) / p99(baseline) == 40.0
    low, high = paired_interval(measured, baseline, p99)
    assert low <= 2.0 and high >= 40.0  # resamples without them, and with them
    # Their medians are not moved by them.
    assert paired_interval(measured, baseline, statistics.median) == (2.0, 2.0)


def test_pairs_stay_pairs_when_resampled() -> None:
    # Each measured sample is its baseline's double, whatever the baseline: every resample too.
    # Resampled apart, their second highest would rarely be the same draw's.
    baseline = [0.3] * 97 + [5.0, 9.0, 20.0]
    low, high = paired_interval([2 * x for x in baseline], baseline, p99)
    assert low == pytest.approx(2.0) and high == pytest.approx(2.0)
    with pytest.raises(ValueError):
        paired_interval([1.0], [1.0, 2.0], p99)
