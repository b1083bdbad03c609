"""Send a trial's strokes to the sleeve and collect what the sleeve says it did with them.

One MQTT connection with the sender's login: strokes go out through the same
``StrokeSender`` as ``feelmysign send`` (QoS 1, at drawing pace, each
acknowledged by the broker), and the sleeve's ``events`` topic is read for the
events of this drawing (played, adjusted with its latency and duration, or
rejected with the reason), which are stored with the trial.
"""

from __future__ import annotations

import json
import threading
import time
import uuid
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.connection import BrokerSettings, connect_client
from feelmysign.events import Event, EventError, Played, Rejected, StatusFloor, event_from_json
from feelmysign.sending import OutgoingStroke, StrokeSender, sleeve_floor_from_status
from feelmysign.stroke import Stroke
from feelmysign.topics import telemetry_topic

# Beyond the drawing's own duration: the sleeve's queue, its latency and the event's trip.
EVENTS_GRACE_S = 5.0
MAX_FELT_WAIT_S = 30.0  # the sleeve's own cap on queued strokes


class _Events:
    """The sleeve's events by drawing id, from paho's thread."""

    def __init__(self) -> None:
        self._condition = threading.Condition()
        # Each event typed, and as it came: the study file stores what the sleeve said.
        self._by_drawing: dict[str, list[tuple[Event, dict[str, Any]]]] = {}

    def on_message(self, _client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        try:
            data = json.loads(message.payload)
            event = event_from_json(data)
        except (ValueError, EventError):
            return  # not ours to judge: not one of the sleeve's events
        drawing = getattr(event, "drawing", None)
        if drawing is None:
            return  # about no stroke (an error): no trial waits for it
        with self._condition:
            self._by_drawing.setdefault(drawing, []).append((event, data))
            self._condition.notify_all()

    def wait(
        self, drawing: str, count: int, timeout_s: float
    ) -> list[tuple[Event, dict[str, Any]]]:
        """The drawing's events once each of its ``count`` strokes has a final one (or timeout):
        played (or adjusted) or rejected."""

        def done() -> bool:
            seen = {
                e.seq
                for e, _ in self._by_drawing.get(drawing, ())
                if isinstance(e, Played | Rejected)
            }
            return len(seen) >= count

        with self._condition:
            self._condition.wait_for(done, timeout_s)
            return list(self._by_drawing.pop(drawing, []))


class SleeveLink:
    """``with SleeveLink(settings) as link: events = link.play(strokes)``."""

    def __init__(self, settings: BrokerSettings, *, timeout_s: float = 10.0) -> None:
        self._settings = settings
        self._timeout_s = timeout_s
        self._events = _Events()
        self._lock = threading.Lock()  # one trial on the sleeve at a time
        self._client: mqtt.Client | None = None

    def __enter__(self) -> SleeveLink:
        client = connect_client(
            self._settings, f"feelmysign-study-{uuid.uuid4().hex[:12]}", timeout_s=self._timeout_s
        )
        topic = telemetry_topic(self._settings.sleeve_id, "events")
        client.on_message = self._events.on_message
        # Subscribed again on every reconnection: a clean session forgets subscriptions.
        client.on_connect = lambda c, *_: c.subscribe(topic, qos=1)
        client.subscribe(topic, qos=1)
        self._client = client
        return self

    def __exit__(self, *exc: object) -> None:
        if self._client is not None:
            self._client.disconnect()
            self._client.loop_stop()

    def floor(self) -> StatusFloor | None:
        """The floor the sleeve advertises in its retained status (with its wearer's limits,
        when it was started with them); None when the broker holds no status with one."""
        assert self._client is not None, "use SleeveLink in a with block"
        return sleeve_floor_from_status(self._client, self._settings)

    def play(self, strokes: list[Stroke]) -> list[dict[str, Any]]:
        """Publish ``strokes`` (one drawing) at their pace; the sleeve's events for them."""
        assert self._client is not None, "use SleeveLink in a with block"
        with self._lock:
            drawing = strokes[0].drawing or ""
            topic = self._settings.strokes_topic
            messages = [OutgoingStroke(i, topic, s) for i, s in enumerate(strokes)]
            sender = StrokeSender(self._client, self._settings, timeout_s=self._timeout_s)
            started_s = time.monotonic()
            sender.send(messages, pace="realtime")
            total_s = sum(s.duration_ms for s in strokes) / 1000
            left_s = max(0.0, started_s + total_s - time.monotonic()) + EVENTS_GRACE_S
            events = self._events.wait(drawing, len(strokes), left_s)
            _until_felt([event for event, _ in events])
            return [data for _, data in events]


def _until_felt(events: list[Event]) -> None:
    """Return once the last stroke has finished on the skin, not when it started: the
    participant is asked only after the whole shape was felt."""
    ends_ms = [e.first_command_at_ms + e.duration_ms for e in events if isinstance(e, Played)]
    if ends_ms:
        time.sleep(min(MAX_FELT_WAIT_S, max(0.0, max(ends_ms) / 1000 - time.time())))
