"""The topic names every client relies on (the page mirrors them in web/src/mqtt/topics.ts)."""

from __future__ import annotations

from feelmysign.topics import (
    ANY_SLEEVE,
    LEGACY_TOPIC,
    TELEMETRY_NAMES,
    strokes_topic,
    telemetry_topic,
)


def test_strokes_and_telemetry_live_under_the_sleeve_id() -> None:
    assert strokes_topic("arm2") == "feelmysign/arm2/strokes"
    assert [telemetry_topic("arm2", name) for name in TELEMETRY_NAMES] == [
        "feelmysign/arm2/status",
        "feelmysign/arm2/actuators",
        "feelmysign/arm2/events",
    ]


def test_any_sleeve_is_a_single_level_wildcard_for_acls() -> None:
    assert strokes_topic(ANY_SLEEVE) == "feelmysign/+/strokes"


def test_the_legacy_topic_is_the_paper_s() -> None:
    assert LEGACY_TOPIC == "deviceOne/line"
