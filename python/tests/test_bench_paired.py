"""The latency benchmarks' paired baseline, against a real Mosquitto and a real sleeve process:
a bare receiver of its own (a second sleeve's account, added before the broker starts) beside
the sleeve, its messages alternating with strokes in the same minutes."""

from __future__ import annotations

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
    paired_latencies,
)

pytestmark = pytest.mark.broker


def test_the_bare_receiver_reads_its_own_topic_beside_the_sleeve(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    account = add_bare_account(tmp_path / "broker")
    broker = start_broker(state_dir=tmp_path / "broker")
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
    start_broker: StartBroker, tmp_path: Path
) -> None:
    account = add_bare_account(tmp_path / "broker")
    broker = start_broker(state_dir=tmp_path / "broker")
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
    start_broker: StartBroker, tmp_path: Path
) -> None:
    account = add_bare_account(tmp_path / "broker")
    broker = start_broker(state_dir=tmp_path / "broker")
    c = broker.credentials
    senders = {"over MQTT (TCP)": _client(c, "sender"), "a second TCP sender": _client(c, "sender")}
    strokes = Strokes(c)
    try:
        with _sleeve_process(c, broker.credentials_path), bare_receiver(c, account) as bare:
            measured = interleaved_latencies(senders, bare, strokes, 2)
    finally:
        strokes.close()
        close(*senders.values())
    assert set(measured) == {BARE, *senders}
    assert all(len(values) == 2 and min(values) > 0.0 for values in measured.values()), measured
