"""The broker's clock, for a sleeve to check its own against at start.

A sleeve whose clock is more than ``--max-age-ms`` (10 s) behind its senders'
refuses every stroke as ``stale``; a Raspberry Pi has no real-time clock, and
until NTP sets it after a boot its clock is the last shutdown's. MQTT carries no
time, so ``feelmysign broker`` (and ``up``) publishes one retained message on
``feelmysign/clock`` when it starts, from the broker's own machine::

    {"at_ms": 1795705807950, "expiry_s": 315360000}

with MQTT 5's message expiry interval ``expiry_s``. The broker counts that
interval down on its own clock and delivers the remaining seconds with the
message, so a reader knows how long ago the broker took it: the broker
machine's time now is ``at_ms + (expiry_s - remaining_s) s`` (to within the
second the interval is counted in). The sleeve reads it once at start, over a
short MQTT 5 connection of its own, and logs a warning when its clock is off
by more than its ``stale`` limit. A broker that publishes no clock (a hosted
one, a NATS cluster) leaves the clock unchecked, and the sleeve says so.
"""

from __future__ import annotations

import json
import logging
import threading
import time
import uuid
from typing import TYPE_CHECKING, Any

from feelmysign.topics import CLOCK_TOPIC

if TYPE_CHECKING:
    import paho.mqtt.client as mqtt

    from feelmysign.connection import BrokerSettings

log = logging.getLogger(__name__)

# Ten years: far longer than a broker runs, within MQTT's four-byte interval.
CLOCK_EXPIRY_S = 10 * 365 * 24 * 3600
# The retained message comes right after the subscription; on a LAN far within this.
CLOCK_WAIT_S = 3.0
# The interval is counted in whole seconds, rounded down: the middle of that second.
_ROUNDING_MS = 500.0


def publish_clock(client: mqtt.Client, *, timeout_s: float = 5.0) -> None:
    """Publish the clock (retained, QoS 1) on a connected MQTT 5 ``client``; waits for the
    broker to have it."""
    from paho.mqtt.packettypes import PacketTypes
    from paho.mqtt.properties import Properties

    properties = Properties(PacketTypes.PUBLISH)  # type: ignore[no-untyped-call]
    properties.MessageExpiryInterval = CLOCK_EXPIRY_S
    payload = json.dumps({"at_ms": round(time.time() * 1000), "expiry_s": CLOCK_EXPIRY_S})
    info = client.publish(CLOCK_TOPIC, payload, qos=1, retain=True, properties=properties)
    info.wait_for_publish(timeout_s)


def broker_time_ms(payload: bytes, remaining_s: int | None) -> float | None:
    """The broker machine's time now, in ms since 1970, from the clock message and the
    expiry interval it came with; None when either is not what ``publish_clock`` sends."""
    if remaining_s is None:
        return None
    try:
        data = json.loads(payload)
        at_ms, expiry_s = float(data["at_ms"]), float(data["expiry_s"])
    except (ValueError, TypeError, KeyError):
        return None
    if not 0 <= remaining_s <= expiry_s:
        return None
    return at_ms + (expiry_s - remaining_s) * 1000 + _ROUNDING_MS


def read_broker_time_ms(settings: BrokerSettings, *, wait_s: float = CLOCK_WAIT_S) -> float | None:
    """The broker machine's time, read once over a connection of its own; None when the
    broker has no clock, or it could not be read within ``wait_s``; FeelMySignError when no
    broker could be reached."""
    from feelmysign.connection import connect_client
    from feelmysign.errors import FeelMySignError

    arrived = threading.Event()
    read: list[float | None] = []

    def on_message(_client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        remaining = getattr(message.properties, "MessageExpiryInterval", None)
        read.append(broker_time_ms(bytes(message.payload), remaining))
        arrived.set()

    client_id = f"feelmysign-clock-{settings.sleeve_id}-{uuid.uuid4().hex[:8]}"
    try:
        client = connect_client(settings, client_id, timeout_s=wait_s, note=lambda _: None)
    except FeelMySignError as error:
        log.debug("the broker's clock could not be read: %s", error)
        raise
    try:
        client.on_message = on_message
        client.subscribe(CLOCK_TOPIC, qos=1)
        arrived.wait(wait_s)
    finally:
        client.disconnect()
        client.loop_stop()
    return read[0] if read else None


def check_clock(settings: BrokerSettings, *, max_age_ms: float, sleeve_id: str) -> float | None:
    """Compare this machine's clock with the broker's and log what was found: a warning when
    they differ by more than ``max_age_ms`` (every stroke would be ``stale``, or stay fresh
    too long). Returns the difference in ms (this machine minus the broker), or None."""
    from feelmysign.errors import FeelMySignError

    try:
        broker_ms = read_broker_time_ms(settings)
    except FeelMySignError:
        return None  # no broker reached: the sleeve says so itself, and nothing was checked
    if broker_ms is None:
        log.info(
            "sleeve %s: the broker publishes no clock (feelmysign/clock): this machine's clock "
            "was not checked; 'timedatectl' must say 'System clock synchronized: yes'",
            sleeve_id,
        )
        return None
    offset_ms = time.time() * 1000 - broker_ms
    if abs(offset_ms) > max_age_ms:
        way = "ahead of" if offset_ms > 0 else "behind"
        log.warning(
            "sleeve %s: this machine's clock is %.1f s %s the broker's, more than the %g s after "
            "which a stroke is refused as stale: set the time (NTP: 'timedatectl' must say "
            "'System clock synchronized: yes') on this machine or the broker's",
            sleeve_id,
            abs(offset_ms) / 1000,
            way,
            max_age_ms / 1000,
        )
    else:
        log.info("sleeve %s: clock within %.1f s of the broker's", sleeve_id, abs(offset_ms) / 1000)
    return offset_ms
