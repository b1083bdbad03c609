"""Publish strokes to a sleeve at their pace, each acknowledged by the broker before the next.

Used by ``feelmysign send`` and by the study runner (``feelmysign study``),
which both need the same guarantee: when ``StrokeSender.send`` returns, the
broker holds every stroke (QoS 1 PUBACK), or a BrokerConnectionError says why
not. ``on_sent`` is told of each acknowledged stroke with the exact payload.
"""

from __future__ import annotations

import itertools
import json
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Literal

from feelmysign.connection import BrokerSettings
from feelmysign.connection.failures import LOGIN_REFUSED, connect_failure_message
from feelmysign.errors import BrokerConnectionError
from feelmysign.events import Status, StatusFloor
from feelmysign.protocol import format_json, format_legacy
from feelmysign.stroke import Stroke

if TYPE_CHECKING:  # paho is imported where a client is made, not by 'feelmysign --help'
    import paho.mqtt.client as mqtt
    from paho.mqtt.reasoncodes import ReasonCode

Pace = Literal["realtime", "burst"]


@dataclass(frozen=True)
class OutgoingStroke:
    """One stroke to publish: its place in the drawing, its topic, and its format."""

    index: int
    topic: str
    stroke: Stroke
    legacy: bool = False

    def payload(self, sent_at_ms: float | None = None) -> str:
        """The message; stamped ``sent_at_ms`` (a wall-clock ms), else the wall clock now: the
        sleeve measures its latency, and how late the stroke is, from it."""
        if self.legacy:
            return format_legacy(self.stroke)
        stamp = time.time() * 1000 if sent_at_ms is None else sent_at_ms
        return format_json(replace(self.stroke, sent_at_ms=round(stamp)))


class _Acks:
    """PUBACKs by message id, from paho's thread.

    An acknowledgement may arrive before ``publish`` has returned its id, hence a dict.
    A dropped connection does not end the wait: paho's network thread reconnects (to the
    next server, given several) and sends the unacknowledged stroke again, and the sleeve
    drops a repeat by its drawing and seq. Only the timeout ends it, naming the drop.
    """

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._codes: dict[int, ReasonCode] = {}
        self._lost: str | None = None
        # A login refused on a reconnection (the wearer blocked this sender): no use waiting.
        self.refused: ReasonCode | None = None

    def on_publish(
        self, _client: mqtt.Client, _userdata: Any, mid: int, code: ReasonCode, _props: Any
    ) -> None:
        with self._condition:
            self._codes[mid] = code
            self._condition.notify_all()

    def on_disconnect(
        self, _client: mqtt.Client, _userdata: Any, _flags: Any, code: ReasonCode, _props: Any
    ) -> None:
        with self._condition:
            self._lost = str(code)
            self._condition.notify_all()

    def on_refused(self, code: ReasonCode) -> None:
        with self._condition:
            self.refused = code
            self._condition.notify_all()

    def wait(self, mid: int, timeout_s: float) -> ReasonCode | str:
        """The PUBACK's reason code, or why none came: 'timeout', or the last disconnect (at
        once when a reconnection's login was refused: ``refused``)."""
        with self._condition:
            self._condition.wait_for(
                lambda: mid in self._codes or self.refused is not None, max(timeout_s, 0.0)
            )
            if mid in self._codes:
                return self._codes.pop(mid)
            if self.refused is not None:
                return "refused"
            return self._lost if self._lost is not None else "timeout"


def _never() -> bool:
    return False


class StrokeSender:
    """Publishes strokes at their pace and reports each once the broker acknowledged it."""

    def __init__(
        self,
        client: mqtt.Client,
        settings: BrokerSettings,
        *,
        timeout_s: float,
        on_sent: Callable[[OutgoingStroke, str], None] = lambda message, payload: None,
    ) -> None:
        self._client = client
        self._settings = settings
        self._timeout_s = timeout_s
        self._on_sent = on_sent
        self._acks = _Acks()
        client.on_publish = self._acks.on_publish
        client.on_disconnect = self._acks.on_disconnect
        # Kept: whoever set it (the events' subscription) still hears each connection. An
        # earlier sender's wrapper on the same client (the study's, one per trial) is
        # replaced, not wrapped again.
        earlier: Any = client.on_connect
        earlier = getattr(earlier, "wrapped", earlier)

        def on_connect(
            c: mqtt.Client, userdata: Any, flags: Any, code: ReasonCode, props: Any
        ) -> None:
            if code.is_failure and code.value in LOGIN_REFUSED:
                self._acks.on_refused(code)
            if earlier is not None:
                earlier(c, userdata, flags, code, props)

        on_connect.wrapped = earlier  # type: ignore[attr-defined]
        client.on_connect = on_connect

    def login_refused(self) -> str | None:
        """Why the broker cut this sender off, when a reconnection's login was refused (the
        wearer blocked it); None otherwise. Said as ``send`` says a refused login."""
        code = self._acks.refused
        return None if code is None else connect_failure_message(self._settings, code)

    def send(
        self, messages: list[OutgoingStroke], *, pace: Pace, until: Callable[[], bool] = _never
    ) -> int:
        """Publishes ``messages`` at ``pace``; how many went out. None goes out once ``until()``
        is true (checked before each): the sleeve refused one as its wearer paused it."""
        if pace == "burst":
            sent: list[tuple[OutgoingStroke, tuple[str, int]]] = []
            for message in messages:
                if until():
                    break
                sent.append((message, self._publish(message, message.payload())))
            deadline_s = time.monotonic() + self._timeout_s
            for message, (payload, mid) in sent:
                self._confirm(message, payload, mid, deadline_s, len(messages))
            return len(sent)
        offsets_ms = list(itertools.accumulate((m.stroke.duration_ms for m in messages), initial=0))
        return self.send_at(messages, offsets_ms[:-1], until=until)

    def send_at(
        self,
        messages: list[OutgoingStroke],
        offsets_ms: list[float],
        *,
        until: Callable[[], bool] = _never,
    ) -> int:
        """Each message published ``offsets_ms`` after this call, once the previous is acked;
        how many went out before ``until()`` was true (checked before each).

        From the second message on, the pace counts from the moment the first one was
        stamped with its ``sent_at_ms`` rather than from this call: whatever held the first
        one up (a busy machine) holds the rest up as much, so no two strokes leave closer
        together than their offsets say, and their ``sent_at_ms`` show it.

        Each later message is stamped with the moment it was due, not the moment it leaves:
        one held up on the way (a broker away, whose acknowledgement of the one before came
        late) keeps the time the drawing gave it (docs/protocol.md, "a stroke a sender held
        keeps its stamp"), so the sleeve sees how late it is and catches up or skips it,
        rather than taking a burst of them for new strokes.
        """
        start_s = time.monotonic()
        # The first message: monotonic s after its stamp, its offset, and its stamp (wall ms).
        first: tuple[float, float, float] | None = None
        for count, (message, offset_ms) in enumerate(zip(messages, offsets_ms, strict=True)):
            stamp_ms: float | None = None
            if first is None:
                due_s = start_s + offset_ms / 1000
            else:
                first_s, first_offset_ms, first_stamp_ms = first
                due_s = first_s + (offset_ms - first_offset_ms) / 1000
                stamp_ms = first_stamp_ms + (offset_ms - first_offset_ms)
            # Drawing time, not a wait for an event: the pace is the point.
            time.sleep(max(0.0, due_s - time.monotonic()))
            if until():
                return count
            if stamp_ms is None:  # the first: stamped now
                stamp_ms = time.time() * 1000
            payload = message.payload(stamp_ms)
            if first is None:
                # Read after the stamp: the moment it counts from is never before it.
                first = (time.monotonic(), offset_ms, stamp_ms)
            payload, mid = self._publish(message, payload)
            self._confirm(message, payload, mid, time.monotonic() + self._timeout_s, len(messages))
        return len(messages)

    def _publish(self, message: OutgoingStroke, payload: str) -> tuple[str, int]:
        import paho.mqtt.client as mqtt

        info = self._client.publish(message.topic, payload, qos=1)
        # Not connected right now: paho keeps the stroke and sends it once reconnected.
        if info.rc not in (mqtt.MQTT_ERR_SUCCESS, mqtt.MQTT_ERR_NO_CONN):
            raise BrokerConnectionError(
                "closed",
                f"Lost the connection to {self._settings.url} before stroke {message.index + 1} "
                f"could be sent ({mqtt.error_string(info.rc)}); send the drawing again.",
                url=self._settings.url,
            )
        return payload, info.mid

    def _confirm(
        self, message: OutgoingStroke, payload: str, mid: int, deadline_s: float, total: int
    ) -> None:
        answer = self._acks.wait(mid, deadline_s - time.monotonic())
        number = f"stroke {message.index + 1} of {total}"
        url = self._settings.url
        if answer == "timeout":
            raise BrokerConnectionError(
                "timeout",
                f"{url} did not acknowledge {number} within {self._timeout_s:g} s: the broker "
                "may be overloaded or the network slow; try again, or raise --timeout-s.",
                url=url,
            )
        if isinstance(answer, str) and self._acks.refused is not None:
            raise BrokerConnectionError(
                "login-refused",
                f"The broker did not acknowledge {number}: it cut this sender off. "
                + connect_failure_message(self._settings, self._acks.refused),
                url=url,
            )
        if isinstance(answer, str):
            raise BrokerConnectionError(
                "closed",
                f"{url} closed the connection ({answer}) and, reconnecting, did not acknowledge "
                f"{number} within {self._timeout_s:g} s; check the broker's log, then send the "
                "drawing again.",
                url=url,
            )
        if answer.is_failure:
            raise BrokerConnectionError(
                "publish-refused",
                f"{url} refused {number} on {message.topic} ({answer}): user "
                f"{self._settings.username!r} may not publish there. Send with the sender "
                "account (credentials.json's 'sender') and check --id.",
                url=url,
            )
        self._on_sent(message, payload)


def printer(*, json_lines: bool, total: int) -> Callable[[OutgoingStroke, str], None]:
    """An ``on_sent`` that prints one line per stroke: ``[i/n] topic payload``, or JSON."""

    def report(message: OutgoingStroke, payload: str) -> None:
        if json_lines:
            line = json.dumps({"index": message.index, "topic": message.topic, "payload": payload})
        else:
            width = len(str(total))
            line = f"[{message.index + 1:>{width}}/{total}] {message.topic} {payload}"
        print(line, flush=True)

    return report


# A sleeve that listens has its retained status at the broker, sent right after the
# subscription; none within this, none is known (the page waits as long: STATUS_WAIT_MS).
STATUS_WAIT_S = 2.5


def sleeve_floor_from_status(
    client: mqtt.Client, settings: BrokerSettings, *, wait_s: float = STATUS_WAIT_S
) -> StatusFloor | None:
    """The floor the sleeve advertises in its retained status (docs/protocol.md), read on a
    connected ``client``; None when the broker holds no status, or one without a floor (an
    older sleeve), within ``wait_s``."""
    status = sleeve_status(client, settings, wait_s=wait_s)
    return None if status is None else status.floor


def sleeve_status(
    client: mqtt.Client, settings: BrokerSettings, *, wait_s: float = STATUS_WAIT_S
) -> Status | None:
    """The sleeve's retained status (its layout, floor, online), read on a connected
    ``client``; None when the broker holds none, or one not understood, within ``wait_s``."""
    return sleeve_status_and_payload(client, settings, wait_s=wait_s)[0]


def sleeve_status_and_payload(
    client: mqtt.Client, settings: BrokerSettings, *, wait_s: float = STATUS_WAIT_S
) -> tuple[Status | None, bytes | None]:
    """``sleeve_status``, and the status's payload as it came; (None, None) when none came
    within ``wait_s``. A status whose only fault is its wearer's ``controls`` is read without
    them (its ``controls`` None): the payload still has them, for the sender to say so."""
    from feelmysign.events import EventError
    from feelmysign.topics import telemetry_topic

    topic = telemetry_topic(settings.sleeve_id, "status")
    arrived = threading.Event()
    read: list[tuple[Status | None, bytes | None]] = []

    def on_status(_client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        payload = bytes(message.payload)
        try:
            read.append((Status.from_json(payload) if payload else None, payload or None))
        except EventError:
            read.append((_without_controls(payload), payload))

        arrived.set()

    client.message_callback_add(topic, on_status)
    try:
        client.subscribe(topic, qos=1)
        arrived.wait(wait_s)
        client.unsubscribe(topic)
    finally:
        client.message_callback_remove(topic)
    return read[0] if read else (None, None)


def _without_controls(payload: bytes) -> Status | None:
    """A status not understood read without its ``controls``; None when that is not its fault
    (not understood: as from no sleeve)."""
    from feelmysign.events import EventError
    from feelmysign.input_files import loads_json

    try:
        data = loads_json(payload)
        if not isinstance(data, dict) or data.get("controls") is None:
            return None
        return Status.from_json({**data, "controls": None})
    except (EventError, ValueError):
        return None
