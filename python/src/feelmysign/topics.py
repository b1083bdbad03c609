"""Every MQTT topic feelmysign uses, built in one place (mirrored in ``web/src/mqtt/topics.ts``).

::

    feelmysign/<sleeve-id>/strokes     JSON v1 strokes in (QoS 1)
    feelmysign/<sleeve-id>/control     control messages in: cancel a drawing or everything (QoS 1)
    feelmysign/<sleeve-id>/status      retained: online, layout, version (last will: offline)
    feelmysign/<sleeve-id>/actuators   actuator intensities, for previews
    feelmysign/<sleeve-id>/events      one message per stroke played, adjusted or rejected
    feelmysign/clock                   retained: the broker machine's time (feelmysign.broker_clock)
    deviceOne/line                     legacy text strokes (the paper's sleeve)

A sleeve id is one topic level: letters, digits, ``_`` and ``-`` only (see
``broker.credentials.check_sleeve_id``), so it can never be a wildcard.
"""

from __future__ import annotations

from typing import Final, Literal

TOPIC_ROOT: Final = "feelmysign"
LEGACY_TOPIC: Final = "deviceOne/line"  # the paper's sleeve (appendix A.2)
STROKES: Final = "strokes"
CONTROL: Final = "control"
TelemetryName = Literal["status", "actuators", "events"]
TELEMETRY_NAMES: Final[tuple[TelemetryName, ...]] = ("status", "actuators", "events")
# Retained, from the broker's machine: its time, for a sleeve to check its clock against
# (feelmysign.broker_clock).
CLOCK_TOPIC: Final = f"{TOPIC_ROOT}/clock"
# In an ACL or a subscription: every sleeve's topic of one kind.
ANY_SLEEVE: Final = "+"


def sleeve_topic(sleeve_id: str, name: str) -> str:
    """``feelmysign/<sleeve_id>/<name>``; ``sleeve_id`` may be ``ANY_SLEEVE`` in an ACL."""
    return f"{TOPIC_ROOT}/{sleeve_id}/{name}"


def strokes_topic(sleeve_id: str) -> str:
    return sleeve_topic(sleeve_id, STROKES)


def control_topic(sleeve_id: str) -> str:
    return sleeve_topic(sleeve_id, CONTROL)


def telemetry_topic(sleeve_id: str, name: TelemetryName) -> str:
    return sleeve_topic(sleeve_id, name)
