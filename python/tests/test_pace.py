"""The pace policy: stale strokes refused, a stalled sleeve skips back to real time."""

from __future__ import annotations

import pytest

from feelmysign.pace import LATE, STALE, PacePolicy, Verdict

DURATION_MS = 200.0


class Sleeve:
    """Plays back to back like the player, on a clock ``skew_ms`` ahead of the sender's."""

    def __init__(self, policy: PacePolicy, skew_ms: float = 0.0) -> None:
        self.policy = policy
        self.skew_ms = skew_ms
        self.tail_ms = float("-inf")

    def receive(self, seq: int, sent_at_ms: float, delay_ms: float) -> Verdict:
        received_ms = sent_at_ms + self.skew_ms + delay_ms
        start_ms = max(received_ms, self.tail_ms)
        verdict = self.policy.check(
            drawing="d",
            seq=seq,
            sent_at_ms=sent_at_ms,
            received_wall_ms=received_ms,
            start_wall_ms=start_ms,
            duration_ms=DURATION_MS,
        )
        if verdict.reason is None:
            self.tail_ms = start_ms + DURATION_MS
        return verdict


@pytest.mark.parametrize("skew_ms", [0.0, -4_000.0, 3_000.0])
def test_a_drawing_in_real_time_plays_whole_whatever_the_clocks(skew_ms: float) -> None:
    sleeve = Sleeve(PacePolicy(), skew_ms)
    verdicts = [sleeve.receive(k, 1e6 + k * DURATION_MS, 5.0 + k % 3) for k in range(50)]
    assert [v.reason for v in verdicts] == [None] * 50
    assert max(v.lag_ms or 0.0 for v in verdicts) <= 3.0


def test_a_drawing_sent_at_once_plays_back_to_back() -> None:
    sleeve = Sleeve(PacePolicy())
    verdicts = [sleeve.receive(k, 1e6, 5.0) for k in range(40)]  # 8 s of strokes, one instant
    assert all(v.reason is None and v.lag_ms == pytest.approx(0.0) for v in verdicts)


def test_after_a_stall_the_backlog_is_skipped_down_to_real_time() -> None:
    policy = PacePolicy(max_lag_ms=1_000.0)
    sleeve = Sleeve(policy)
    for k in range(10):
        assert sleeve.receive(k, 1e6 + k * DURATION_MS, 5.0).reason is None
    # Strokes 10..59 (10 s) were held by a stalled network and all arrive at once.
    back_ms = 1e6 + 60 * DURATION_MS
    backlog = [
        sleeve.receive(k, sent_ms, back_ms - sent_ms)
        for k, sent_ms in ((k, 1e6 + k * DURATION_MS) for k in range(10, 60))
    ]
    skipped = [v for v in backlog if v.reason == LATE]
    assert len(skipped) >= 45 and all(v.lag_ms and v.lag_ms > policy.catch_up_ms for v in skipped)
    played = [v for v in backlog if v.reason is None]
    assert played and all((v.lag_ms or 0.0) <= policy.catch_up_ms for v in played)
    assert "skips strokes" in skipped[0].message
    assert "held on the way" in skipped[0].message and "queued" not in skipped[0].message
    # And what is drawn after the stall plays on time.
    after = [sleeve.receive(k, 1e6 + k * DURATION_MS, 5.0) for k in range(60, 70)]
    assert all(v.reason is None and (v.lag_ms or 0.0) <= policy.catch_up_ms for v in after)


def test_a_stroke_late_behind_another_drawing_is_said_to_be_queued_not_held() -> None:
    # It came at once, but another drawing holds the sleeve for 3 s: its message says so.
    verdict = PacePolicy(max_lag_ms=1_000.0).check(
        drawing="b",
        seq=0,
        sent_at_ms=1e6,
        received_wall_ms=1e6 + 5.0,
        start_wall_ms=1e6 + 3_005.0,
        duration_ms=DURATION_MS,
    )
    assert verdict.reason == LATE and verdict.lag_ms == pytest.approx(3_000.0)
    assert "wait 3.00 s behind the strokes queued" in verdict.message
    assert "held on the way" not in verdict.message


def test_strokes_older_than_the_maximum_age_are_stale() -> None:
    policy = PacePolicy(max_age_ms=10_000.0)
    verdict = policy.check(
        drawing=None,
        sent_at_ms=1e6,
        received_wall_ms=1e6 + 10_001.0,
        start_wall_ms=1e6 + 10_001.0,
        duration_ms=DURATION_MS,
    )
    assert verdict.reason == STALE and verdict.age_ms == pytest.approx(10_001.0)
    assert "clock" in verdict.message and "10 s" in verdict.message


@pytest.mark.parametrize(
    ("ahead_ms", "stale"), [(10_001.0, True), (3_600_000.0, True), (9_999.0, False)]
)
def test_strokes_stamped_further_ahead_than_the_maximum_age_are_stale(
    ahead_ms: float, stale: bool
) -> None:
    """A stroke stamped ahead of the sleeve's clock cannot be told old: one held in the broker
    all night, by a sender whose clock runs an hour fast, would play when the sleeve comes on."""
    verdict = PacePolicy(max_age_ms=10_000.0).check(
        drawing="d",
        sent_at_ms=1e12 + ahead_ms,
        received_wall_ms=1e12,
        start_wall_ms=1e12,
        duration_ms=DURATION_MS,
    )
    assert (verdict.reason == STALE) is stale, verdict
    assert verdict.age_ms == pytest.approx(-ahead_ms)
    if stale:
        assert "ahead of the sleeve's clock" in verdict.message and "NTP" in verdict.message


def test_strokes_without_a_send_time_are_never_refused() -> None:
    verdict = PacePolicy(max_age_ms=100.0, max_lag_ms=10.0).check(
        drawing="d", sent_at_ms=None, received_wall_ms=1e9, start_wall_ms=2e9, duration_ms=1.0
    )
    assert verdict == Verdict()


def test_a_stroke_after_later_ones_is_due_at_its_own_time_and_moves_nothing() -> None:
    # A broker that failed over delivers stroke 3 again after 4..9 played: under the
    # cluster's pace it plays; it is measured against its own send time, not the line's,
    # and the strokes after it keep to their own time line.
    policy = PacePolicy(max_age_ms=60_000.0, max_lag_ms=30_000.0)
    sleeve = Sleeve(policy)
    for k in (0, 1, 2, 4, 5, 6, 7, 8, 9):
        assert sleeve.receive(k, 1e6 + k * DURATION_MS, 5.0).reason is None
    redelivered = sleeve.receive(3, 1e6 + 3 * DURATION_MS, 10_000.0)
    assert redelivered.reason is None
    assert redelivered.lag_ms == pytest.approx(10_000.0 - 5.0)
    after = [sleeve.receive(k, 1e6 + k * DURATION_MS, 5.0) for k in range(60, 70)]
    assert all(v.reason is None and v.lag_ms == pytest.approx(0.0) for v in after)
    # Under the default pace the same copy is late, and only it: no catch-up follows.
    policy = PacePolicy()
    sleeve = Sleeve(policy)
    for k in (0, 1, 2, 4, 5):
        assert sleeve.receive(k, 1e6 + k * DURATION_MS, 5.0).reason is None
    assert sleeve.receive(3, 1e6 + 3 * DURATION_MS, 5_000.0).reason == LATE
    assert sleeve.receive(6, 1e6 + 6 * DURATION_MS, 5.0).reason is None
