"""The sleeve daemon: strokes in over MQTT, the player out, telemetry back.

Unlike the paper's sleeve, it never disconnects to play: it stays subscribed
(QoS 1, a persistent session under a stable client id, subscriptions made in
the on-connect handler so they come back after every reconnect) and hands
each stroke to the player, which plays it while the next ones arrive.

Topics (all but the legacy one under ``feelmysign/<id>/``): ``strokes`` (JSON
v1 in), the legacy topic (``deviceOne/line``, text in), ``status`` (retained,
with a last will that marks the sleeve offline), ``actuators`` (telemetry for
previews, rate-limited) and ``events`` (one JSON message per stroke: played,
adjusted or rejected, with the reason and the latency figures).

The message handler cannot raise: every failure becomes a counted, reported
``rejected`` event, and the strokes around it play on.

Delivery: a stroke is acknowledged to the broker (PUBACK, paho's manual
acknowledgement) only once the sleeve is done with it: played, or refused with
an event. The acknowledgement follows the event out on the same connection, so
a broker that has the acknowledgement has the event too. A stroke the sleeve
received but had not played when it died (``kill -9``, a power cut) was never
acknowledged, and the broker delivers it again when the sleeve returns; so is
one still waiting at a clean stop (reported ``stopped``). Redeliveries of a
stroke already played are dropped by ``drawing``/``seq`` (the player).

Pace: ``feelmysign.pace`` refuses strokes older than ``max_age_ms`` (``stale``)
and skips those the sleeve is too late for after a stall (``late``).
"""

from __future__ import annotations

import gc
import hashlib
import hmac
import json
import logging
import queue
import ssl
import sys
import threading
import time
from collections import Counter, OrderedDict, deque
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from feelmysign import __version__
from feelmysign.backends.base import Backend
from feelmysign.backends.telemetry import ActuatorTelemetry
from feelmysign.clock import both_ms, wall_ms
from feelmysign.connection import (
    RECONNECT_MAX_S,
    BrokerSettings,
    connect_failure_message,
    new_client,
)
from feelmysign.control import Cancel, parse_control
from feelmysign.errors import FeelMySignError
from feelmysign.events import (
    Cancelled,
    ErrorEvent,
    Event,
    LostChip,
    Played,
    Rejected,
    Safety,
    Status,
    StatusHardware,
    StatusLayout,
    StrokeRef,
    delivery_delay_ms,
)
from feelmysign.fates import Fate
from feelmysign.layout import Layout
from feelmysign.pace import MAX_AGE_MS, MAX_LAG_MS
from feelmysign.player import SPIN_MS, WEARER, PlannedStroke, Player, cancelled
from feelmysign.protocol import (
    CANCELLED,
    CRASHED,
    DO_NOT_DISTURB,
    DUPLICATE,
    HELD,
    PAUSED,
    STOPPED,
)
from feelmysign.service_manager import ServiceManager, WatchdogFeeder
from feelmysign.services.drawing_log import DrawingSummaries
from feelmysign.sleeve.admission import BURST, RATE_PER_S, Admission, Refused, duplicate_message
from feelmysign.sleeve.controls import (
    NOT_PAUSED,
    ControlsState,
    WearerControls,
    controls_path,
    describe,
    refusal_for,
)
from feelmysign.sleeve.pace_memory import Interrupted, PaceMemory, pace_path
from feelmysign.topics import LEGACY_TOPIC, control_topic, strokes_topic, telemetry_topic
from feelmysign.wearer import Wearer, sleeve_floor

if TYPE_CHECKING:  # paho is imported where a client is made, not by 'feelmysign --help'
    import paho.mqtt.client as mqtt

log = logging.getLogger(__name__)

KEEPALIVE_S = 15
# A stroke delayed on its way by more than this (events.delivery_delay_ms) is logged: a higher
# bar than the page's and the terminal's (events.DELAYED_MS), to keep the sleeve's journal quiet.
LOG_DELAYED_MS = 1000.0
# How often the journal looks for drawings that are over (services.drawing_log.QUIET_S).
JOURNAL_CHECK_S = 0.25
# Cancelled drawings remembered, so that their later strokes do not start them again.
STOP_POLL_S = 0.5  # how soon a stop signal stops the sleeve, however it arrived
NETWORK_STOP_S = 5.0  # a network thread ends within its 1 s select after a disconnect
# CONNACK reasons that retrying cannot fix: MQTT 5's "Bad user name or password" and
# "Not authorized" (paho reports MQTT 3.1.1's return codes 4 and 5 as these).
LOGIN_REFUSED_CODES = (134, 135)
# Rejections after which the broker must deliver the stroke again: the sleeve did not play it
# and is going away, not refusing it.
NOT_ACKNOWLEDGED = frozenset({STOPPED, "player_stopped"})
# Marks the log records that say the sleeve lost or cannot reach its broker: a program
# that reports these itself in its own words (``feelmysign up``) filters them out.
CONNECTION_STATE = {"connection_state": True}
# While the broker stays out of reach, how often the sleeve says so again: once when it
# begins, then a line a minute (paho retries every RECONNECT_MAX_S at most, and a line per
# attempt would bury the wearer's log).
UNREACHABLE_REMINDER_S = 60.0
# A broker that closes the connection within this long of each login, this many times in a row,
# refuses something the sleeve sends there (its retained status, a message's size): said once.
SHORT_CONNECTION_S = 5.0
SHORT_CONNECTIONS = 3
CLIENT_ID_DIGEST_HEX = 32  # 128 bits of the HMAC: not guessable
# Safety events after which the status's ``hardware`` changed: published again with them.
HARDWARE_EVENTS = frozenset({"chip_lost", "chip_back"})
# The wearer's stop stops every drawing "under way": one with a stroke arriving in this last
# while (or one playing or waiting). Longer than a pen rests mid-drawing; a drawing that is
# over sends no more strokes, so stopping it too changes nothing. A new drawing (a new id)
# plays.
DRAWING_UNDER_WAY_MS = 10_000.0
# Drawings remembered with their last stroke's arrival, for the wearer's stop.
REMEMBERED_ARRIVALS = 64
# Strokes refused "paused" during one pause, remembered: a long press (a stop) that follows
# tells their senders the drawing was stopped.
REMEMBERED_PAUSED = 1024
# The wearer's refusals (a pause, "do not disturb"): logged once per drawing, not per stroke.
WEARER_REFUSALS = frozenset({PAUSED, DO_NOT_DISTURB})


def sleeve_client_id(sleeve_id: str, password: str | None) -> str:
    """The sleeve's MQTT client id, ``feelmysign-sleeve-<id>-<32 hex digits>``.

    The broker lets any logged-in client take over the session of a client id, so a
    sender's login could kick the sleeve off by using its id. The suffix is an HMAC of the
    id under the sleeve's password: only a holder of the sleeve's password can name the
    sleeve's session. (Without a password, the plain ``feelmysign-sleeve-<id>``.)
    """
    if not password:
        return f"feelmysign-sleeve-{sleeve_id}"
    digest = hmac.new(
        password.encode(), f"feelmysign client id {sleeve_id}".encode(), hashlib.sha256
    ).hexdigest()
    return f"feelmysign-sleeve-{sleeve_id}-{digest[:CLIENT_ID_DIGEST_HEX]}"


@dataclass
class _Ack:
    """A QoS 1 stroke to acknowledge once, on the connection it came in on."""

    mid: int
    connection: int
    sent: bool = False


@dataclass(frozen=True)
class _Publish:
    topic: str
    payload: str
    qos: int
    retain: bool
    # An event, for the journal: summed up on the publishing thread, off the player's.
    event: Event | None = None


_Outgoing = _Publish | _Ack


@dataclass(frozen=True)
class SleeveOptions:
    sleeve_id: str
    legacy_topic: str | None = LEGACY_TOPIC
    rate_per_s: float = RATE_PER_S
    burst: int = BURST
    strict: bool = False
    backend_name: str = "sim"
    max_age_ms: float = MAX_AGE_MS
    max_lag_ms: float = MAX_LAG_MS
    # The player spins (busy-waits) this long before each motor command, for sub-millisecond
    # timing on a machine of its own; 0 where many sleeves share the processors (the load
    # bench), which cannot all spin.
    spin_ms: float = SPIN_MS
    # The wearer's measured limits (feelmysign.wearer), advertised in the status's floor.
    wearer: Wearer | None = None
    # Where the wearer's controls are kept (None: the sleeve's state directory, see
    # feelmysign.sleeve.controls.controls_path).
    controls_path: str | None = None


class Sleeve:
    """Run with ``run()`` (blocks until ``stop()``); every motor is off when it returns."""

    def __init__(
        self,
        settings: BrokerSettings,
        layout: Layout,
        backend: Backend,
        options: SleeveOptions,
        *,
        player: Player | None = None,
        telemetry: ActuatorTelemetry | None = None,
    ) -> None:
        self._settings = settings
        self._backend = backend  # its lost chips and enable line go into the status
        self._telemetry = telemetry  # flushed at stop, so previews see the final all-off
        self._layout = layout
        self._options = options
        self._id = options.sleeve_id
        self._outbox: queue.SimpleQueue[_Outgoing | None] = queue.SimpleQueue()
        # Catching up never plays a stroke briefer than the floor the status advertises: the
        # motors' own, or the wearer's measured shortest felt duration when that is longer.
        self._player = player or Player(
            backend,
            layout,
            on_event=self._event,
            spin_ms=options.spin_ms,
            floor_ms=sleeve_floor(layout, options.wearer).min_duration_ms,
            sleeve_id=options.sleeve_id,
        )
        self._admission = Admission(
            layout,
            strict=options.strict,
            rate_per_s=options.rate_per_s,
            burst=options.burst,
            max_age_ms=options.max_age_ms,
            max_lag_ms=options.max_lag_ms,
        )
        # The pace's time lines kept from before a crash or kill: strokes the broker held
        # while the sleeve was down are late by how long they were held, not a new time line.
        self._pace_memory = PaceMemory(pace_path(self._id))
        self._admission.remember(self._pace_memory.load(options.max_age_ms))
        # The strokes the sleeve's last process was playing when it ended: cut short by that,
        # said once the publishing thread runs (see _report_interrupted).
        self._interrupted = self._pace_memory.interrupted()
        # For the wearer's stop: the drawings lately seen (drawing -> the monotonic ms of its
        # last stroke's arrival), the strokes refused during the present pause, and the
        # drawings stopped (drawing -> when, wall clock: the admission's cancel of it).
        self._arrivals: OrderedDict[str, float] = OrderedDict()
        self._arrivals_lock = threading.Lock()
        self._refused_paused: deque[StrokeRef] = deque(maxlen=REMEMBERED_PAUSED)
        self._wearer_stops: dict[str, float] = {}
        self._was_paused = False
        # The drawings whose refusal for the wearer's pause or DND was logged (one line each).
        self._quiet_refusals: set[tuple[str, object]] = set()
        # The wearer's pause, stop, ceiling and "do not disturb": in force before the player
        # starts (a sleeve restarted while paused never plays a stroke).
        self.controls = WearerControls(
            options.controls_path or controls_path(options.sleeve_id),
            max_intensity=layout.max_intensity,
            apply=self._apply_controls,
            stop=self._wearer_stop,
        )
        self.controls.subscribe(self._controls_changed)
        if self.controls.state() != NOT_PAUSED:  # kept from before a restart: said once
            log.info(
                "sleeve %s: the wearer's controls at start: %s",
                self._id,
                describe(self.controls.state()),
            )
        self._connection = 0  # counts connections: an acknowledgement is valid on its own only
        self._stopped = threading.Event()
        self._connected = threading.Event()
        self._fatal: FeelMySignError | None = None
        # When the last login was taken (monotonic s), how many connections in a row the
        # broker closed within SHORT_CONNECTION_S of it, and whether that was said.
        self._connected_at: float | None = None  # None: no login since the last loss
        self._short_connections = 0
        self._short_said = False
        # Since when the broker is out of reach (monotonic s; None: it is not), and when
        # that was last said.
        self._unreachable_since: float | None = None
        self._unreachable_said_at = 0.0
        self.counts: Counter[str] = Counter()
        self._counts_lock = threading.Lock()  # counted from the network and player threads
        # One log line per drawing once it is over (strokes played, refused, start delay):
        # what the journal shows of a sleeve at work. Kept by the publishing thread (the
        # lock: the last lines are written at the stop, by whoever stops).
        self._journal = DrawingSummaries()
        self._journal_lock = threading.Lock()
        self._journal_checked_s = 0.0
        self._client = self._make_client()
        self._network: threading.Thread | None = None
        self._control_topic = control_topic(self._id)  # compared with every message's topic

    @property
    def player(self) -> Player:
        return self._player

    @property
    def connected(self) -> threading.Event:
        """Set once the broker has granted the sleeve's subscriptions (not at CONNACK: a
        stroke sent between the two, or a broker that stops between them, would miss it);
        cleared when the connection drops."""
        return self._connected

    # --- life cycle --------------------------------------------------------------

    def run(self) -> None:
        """Connect, play, and keep going through broker restarts until ``stop()``."""
        publisher = threading.Thread(
            target=self._publish_loop, name="feelmysign-events", daemon=True
        )
        publisher.start()
        self._player.start()  # every motor off (the backend's open), then the player's thread
        self._report_interrupted()
        manager = ServiceManager.from_environment()
        feeder = WatchdogFeeder(manager, self._player.alive) if manager is not None else None
        if feeder is not None:
            feeder.start()
        try:
            self._client.connect_async(self._settings.host, self._settings.port, KEEPALIVE_S)
            self._client.loop_start()
            # Our own handle on paho's network thread: see _stop_network.
            self._network = self._client._thread
            log.info("sleeve %s: connecting to %s", self._id, self._settings.urls)
            # What start-up made stays for the sleeve's life: kept out of the collector's
            # scans, so a full collection during a stroke's receipt is short.
            gc.freeze()
            # Woken now and then, never blocked for good: a stop signal's Python handler runs
            # only when the main thread runs bytecode, and one that reaches another thread
            # (or whose wake-up is lost) would otherwise wait here for ever.
            while not self._stopped.wait(STOP_POLL_S):
                pass
            if self._fatal is not None:
                raise self._fatal
        finally:
            if feeder is not None:
                feeder.stop()
            self._shutdown(publisher)

    def stop(self) -> None:
        self._stopped.set()

    def _shutdown(self, publisher: threading.Thread) -> None:
        self.controls.close()
        try:
            unplayed = self._player.stop()  # motors off first, whatever happens to the network
            for stroke in self._player.cut_by_stop:
                self._event(
                    Safety(
                        reason=STOPPED,
                        row=0,
                        column=0,
                        message=(
                            "cut short, after its played event: the sleeve stopped while it "
                            "played (every motor off)"
                        ),
                        stroke=stroke.ref,
                    )
                )
            for stroke in unplayed:
                message = "the sleeve stopped before this stroke could play"
                self._reject(STOPPED, message, stroke.ref)
        finally:
            if self._telemetry is not None:
                # Every motor is off: that frame goes out (after any older one) before the
                # outbox closes, so a preview does not keep showing a motor on.
                self._telemetry.stop()
            self._outbox.put(None)  # the events still queued go out before the goodbye
            publisher.join(timeout=5.0)
            # Kept after a clean stop too: a service restarted in the middle of a drawing takes
            # its time line back, as after a crash, and skips what the broker held too long.
            self._pace_memory.save()
            self._write_journal(every_drawing=True)
            self._say_goodbye()

    def _say_goodbye(self) -> None:
        try:
            if self._client.is_connected():
                info = self._client.publish(
                    telemetry_topic(self._id, "status"),
                    self._status(online=False),
                    qos=1,
                    retain=True,
                )
                info.wait_for_publish(timeout=2.0)
            self._client.disconnect()
        except (RuntimeError, ValueError, OSError) as error:
            log.warning("sleeve %s: could not say goodbye to the broker: %s", self._id, error)
        finally:
            self._stop_network()

    def _stop_network(self) -> None:
        """Wait for paho's network thread, which ends by itself after ``disconnect()``.

        paho's ``loop_stop()`` reads its thread twice (``!= self._thread``, then
        ``self._thread.join()``), and that thread sets it to None as it ends: called
        right after ``disconnect()`` it raised AttributeError about one stop in a
        thousand. So join our own handle, and ask the thread to stop only if it is
        still running (the disconnect failed), when it cannot be ending on its own.
        """
        network, self._network = self._network, None
        if network is None:
            return
        network.join(timeout=NETWORK_STOP_S)
        if network.is_alive():
            self._client.loop_stop()

    # --- MQTT ----------------------------------------------------------------------

    def _make_client(self) -> mqtt.Client:
        client = new_client(
            self._settings,
            client_id=sleeve_client_id(self._id, self._settings.password),
            persistent_session=True,
        )
        client.manual_ack_set(True)  # acknowledged once played or refused, not on receipt
        client.will_set(
            telemetry_topic(self._id, "status"), self._status(online=False), qos=1, retain=True
        )
        client.on_connect = self._on_connect
        client.on_connect_fail = self._on_connect_fail
        client.on_disconnect = self._on_disconnect
        client.on_subscribe = self._on_subscribe
        client.on_message = self._on_message
        return client

    def _on_connect(
        self, client: mqtt.Client, userdata: Any, flags: Any, reason: Any, properties: Any
    ) -> None:
        if reason.is_failure:
            message = (
                f"the broker at {self._settings.url} refused the sleeve: {reason}; check the "
                "username and password (or --credentials) and that this user may use the "
                f"topics of sleeve {self._id}"
            )
            if getattr(reason, "value", None) in LOGIN_REFUSED_CODES:
                self._fatal = FeelMySignError(message)
                self._stopped.set()
            log.error(message)
            return
        self._connection += 1
        self._unreachable_since = None
        self._connected_at = time.monotonic()
        subscriptions = [(strokes_topic(self._id), 1), (control_topic(self._id), 1)]
        if self._options.legacy_topic:
            subscriptions.append((self._options.legacy_topic, 1))
        client.subscribe(subscriptions)
        client.publish(
            telemetry_topic(self._id, "status"), self._status(online=True), qos=1, retain=True
        )
        self._count("connections")  # `up` tells the terminal when the sleeve is back
        resumed = bool(getattr(flags, "session_present", False))
        session = "resumed" if resumed else "new"
        # With several servers, the one reached (failover moves it between attempts).
        server = replace(self._settings, host=client.host, port=client.port, fallbacks=())
        log.info("sleeve %s: connected to %s (%s session)", self._id, server.url, session)
        if not resumed and self._connection > 1:
            # This process had a session there: the broker forgot it, and with it every
            # stroke it held for the sleeve, acknowledged to its sender or not.
            log.warning(
                "sleeve %s: the broker at %s no longer had the sleeve's session: strokes it "
                "held for the sleeve while it was away are lost (their senders get no answer "
                "for them). A broker restarted without 'persistence true', or one that "
                "expires sessions sooner than the sleeve can be away, does this "
                "(docs/deploy.md, Topics and ACL).",
                self._id,
                server.url,
            )

    def _on_connect_fail(self, client: mqtt.Client, userdata: Any) -> None:
        now = time.monotonic()
        since = self._unreachable_since
        # paho calls this in the handler of the attempt's OSError: a TLS failure is said as
        # such (the certificate's own reason and what to do), as the senders say it.
        error = sys.exc_info()[1]
        if since is None and isinstance(error, ssl.SSLError):
            self._unreachable_since = self._unreachable_said_at = now
            log.warning(
                "sleeve %s: cannot connect to the broker: %s Retrying every %g s at most.",
                self._id,
                connect_failure_message(self._settings, error),
                RECONNECT_MAX_S,
                extra=CONNECTION_STATE,
            )
        elif since is None:
            self._unreachable_since = self._unreachable_said_at = now
            log.warning(
                "sleeve %s: cannot reach the broker at %s (nothing answers, or the host is "
                "unknown); retrying every %g s at most. Start one with 'feelmysign broker' or "
                "check --broker.",
                self._id,
                self._settings.url,
                RECONNECT_MAX_S,
                extra=CONNECTION_STATE,
            )
        elif now - self._unreachable_said_at >= UNREACHABLE_REMINDER_S:
            self._unreachable_said_at = now
            log.warning(
                "sleeve %s: still cannot reach the broker at %s after %.0f s; retrying every "
                "%g s at most",
                self._id,
                self._settings.url,
                now - since,
                RECONNECT_MAX_S,
                extra=CONNECTION_STATE,
            )

    def _on_subscribe(
        self, client: mqtt.Client, userdata: Any, mid: int, reasons: Any, properties: Any
    ) -> None:
        # Brokers that check access at subscription refuse it here. (Mosquitto 2.0 grants
        # every subscription and filters at delivery, so there a sleeve with the wrong id
        # simply receives nothing.)
        if any(reason.is_failure for reason in reasons):
            names = [strokes_topic(self._id)]
            if self._options.legacy_topic:
                names.append(self._options.legacy_topic)
            self._fatal = FeelMySignError(
                f"the broker at {self._settings.url} refused the subscription to "
                f"{' and '.join(names)} for user {self._settings.username!r}: the broker's access "
                f"list does not let this user read sleeve {self._id}'s strokes; check --id, "
                "--legacy-topic and the credentials (a 'feelmysign broker' sleeve account reads "
                "only its own sleeve's topics and deviceOne/line)"
            )
            log.error("%s", self._fatal)
            self._stopped.set()
            return
        self._connected.set()

    def _on_disconnect(
        self, client: mqtt.Client, userdata: Any, flags: Any, reason: Any, properties: Any
    ) -> None:
        self._connected.clear()
        logged_in = self._connected_at is not None
        if not self._stopped.is_set():
            self._count_short_connection()
        # paho can report one loss twice (a keep-alive timeout): said once.
        if not self._stopped.is_set() and self._unreachable_since is None:
            # The loss is said here; attempts that fail after it are said once a minute.
            self._unreachable_since = self._unreachable_said_at = time.monotonic()
            if logged_in:
                log.warning(
                    "sleeve %s: lost the broker (%s); reconnecting",
                    self._id,
                    reason,
                    extra=CONNECTION_STATE,
                )
            else:
                log.warning(
                    "sleeve %s: the broker at %s closed the connection before taking the "
                    "login (%s); retrying",
                    self._id,
                    self._settings.url,
                    reason,
                    extra=CONNECTION_STATE,
                )

    def _count_short_connection(self) -> None:
        """A loss soon after a login, again and again: the broker closes the connection for
        something the sleeve publishes there at once. Said once, with the usual causes."""
        connected_at, self._connected_at = self._connected_at, None
        if connected_at is not None and time.monotonic() - connected_at >= SHORT_CONNECTION_S:
            self._short_connections = 0
            return
        self._short_connections += 1  # closed soon after its login, or before any
        if self._short_connections < SHORT_CONNECTIONS or self._short_said:
            return
        self._short_said = True
        log.error(
            "sleeve %s: the broker at %s closed the connection within %g s of each of the last "
            "%d logins (or before their answer): it refuses something the sleeve sends as it "
            "connects. Usually the broker takes no retained messages (Mosquitto: "
            "retain_available false; the sleeve's status and its last will are retained), or "
            "none as large as the sleeve's status and events (up to about 1 KiB; Mosquitto: "
            "max_packet_size), or its access list denies this user a topic of sleeve %s; see "
            "docs/deploy.md, 'Topics and ACL', and the broker's log",
            self._id,
            self._settings.url,
            SHORT_CONNECTION_S,
            self._short_connections,
            self._id,
        )

    def _on_message(self, client: mqtt.Client, userdata: Any, message: mqtt.MQTTMessage) -> None:
        received_at_ms, received_wall_ms = both_ms()
        # The garbage collector can wait until the stroke's first motor command is out: a
        # collection that a message's allocations would set off in the middle of its
        # receipt runs when the handler returns instead (collecting is never skipped).
        collecting = gc.isenabled()
        if collecting:
            gc.disable()
        ack = _Ack(message.mid, self._connection) if message.qos > 0 else None
        try:
            self._handle(message, ack, received_at_ms, received_wall_ms)
        except Exception as error:  # the handler must never take the sleeve down
            log.exception("sleeve %s: unexpected error handling a message", self._id)
            ref = StrokeRef(message.topic, received_at_ms=received_wall_ms)
            self._reject("internal_error", f"unexpected error: {error}", ref, ack)
        finally:
            if collecting:
                gc.enable()
            # Counted once the stroke's first motor command is out (read by `up` and the load
            # bench, never needed on the way to it).
            self._count("received")

    def _handle(
        self,
        message: mqtt.MQTTMessage,
        ack: _Ack | None,
        received_at_ms: float,
        received_wall_ms: float,
    ) -> None:
        name = message.topic
        if name == self._control_topic and not message.retain:
            ref = StrokeRef(name, received_at_ms=received_wall_ms)
            self._control(message.payload, ref, received_wall_ms, ack)
            return
        verdict = self._admission.admit(  # positional: one keyword less to match each
            message.payload,
            name,
            name == self._options.legacy_topic,  # legacy
            message.retain,  # retained
            ack is not None,  # holdable: acknowledged later
            received_at_ms,
            received_wall_ms,
            self._player,  # the queue
        )
        if not isinstance(verdict, Refused):
            outline, ref = verdict
            planned = PlannedStroke(outline, received_at_ms, ref)
            if ack is not None:
                planned.acknowledge = lambda: self._outbox.put(ack)
            refusal = self._player.submit(planned)
            self._arrived(ref.drawing, received_at_ms)
            if refusal is None:
                return
            if refusal.reason == CANCELLED and refusal.cancelled_at_ms is not None:
                at_ms = refusal.cancelled_at_ms
                self._event(cancelled(ref, at_ms, started=False, by=refusal.by), ack)
            else:
                self._reject(refusal.reason, refusal.message, ref, ack)
            return
        ref = verdict.ref
        self._arrived(ref.drawing, received_at_ms)
        if verdict.reason == CANCELLED and verdict.cancelled_at_ms is not None:
            at_ms = verdict.cancelled_at_ms
            by = WEARER if self._wearer_stops.get(ref.drawing) == at_ms else None  # type: ignore[arg-type]
            self._event(cancelled(ref, at_ms, started=False, by=by), ack)
        elif verdict.reason != HELD:
            self._reject(verdict.reason, verdict.message, ref, ack)
        elif not self._hold(ref, ack):
            # The original started (or was dropped) since: this copy is a duplicate.
            self._reject(DUPLICATE, duplicate_message(ref.drawing, ref.seq), ref, ack)

    def _arrived(self, drawing: object, received_at_ms: float) -> None:
        """A stroke of ``drawing`` arrived (whatever became of it): under way, for the wearer's
        stop."""
        if not isinstance(drawing, str):
            return
        arrivals = self._arrivals
        with self._arrivals_lock:
            arrivals[drawing] = received_at_ms
            arrivals.move_to_end(drawing)
            if len(arrivals) > REMEMBERED_ARRIVALS:
                arrivals.popitem(last=False)

    def _hold(self, ref: StrokeRef, ack: _Ack | None) -> bool:
        """The copy waits with its original, acknowledged when that one plays: False when the
        original is no longer waiting (it started meanwhile)."""
        drawing, seq = ref.drawing, ref.seq
        if ack is None or not self._player.hold(drawing, seq, lambda: self._outbox.put(ack)):
            return False
        self._count("redelivered")
        log.info(
            "sleeve %s: stroke %s of drawing %s came again while it waits to play",
            self._id,
            seq,
            drawing,
        )
        return True

    def _control(
        self, payload: object, ref: StrokeRef, received_wall_ms: float, ack: _Ack | None
    ) -> None:
        result = parse_control(payload)
        if not isinstance(result, Cancel):
            self._reject(result.reason, result.message, ref, ack)
            return
        if not result.everything:
            self._admission.cancelled.cancel(result.drawing, received_wall_ms)
        what = "every drawing" if result.everything else f"drawing {result.drawing}"
        log.info("sleeve %s: cancel %s", self._id, what)
        self._player.cancel(result, received_wall_ms)
        if ack is not None:
            self._outbox.put(ack)

    # --- the wearer's controls ----------------------------------------------------------

    def _apply_controls(self, state: ControlsState) -> None:
        """The wearer's controls in force: the ceiling on every stroke from now on (planned
        at it, and no motor driven above it), and a pause or "do not disturb" cuts what
        plays in the player's next pass and refuses every stroke until it ends."""
        self._admission.ceiling = state.ceiling
        self._player.set_ceiling(state.ceiling)
        received_wall_ms = wall_ms()
        if state.paused != self._was_paused:
            # A new pause (or its end): the strokes refused for the last one are its own.
            self._refused_paused.clear()
            self._was_paused = state.paused
        self._quiet_refusals.clear()  # a change is logged: the next refusal is said again
        self._player.refuse(refusal_for(state, received_wall_ms), received_wall_ms)

    def _wearer_stop(self) -> None:
        """Stop every drawing under way, as a sender's Stop stops its own: what plays is cut,
        what waits dropped (``cancelled`` by the wearer), and every later stroke of those
        drawings refused as ``cancelled`` by the wearer; a new drawing plays. Strokes of them
        refused ``paused`` during this pause (the first edge of a long press pauses) are told
        ``cancelled`` by the wearer too, so that the stop is what their sender hears last."""
        now_ms, now_wall_ms = both_ms()
        with self._arrivals_lock:
            recent = [
                drawing
                for drawing, at_ms in self._arrivals.items()
                if now_ms - at_ms <= DRAWING_UNDER_WAY_MS
            ]
        # The player's set first: from here no stroke of these drawings is placed.
        stopped = self._player.stop_drawings(recent, now_wall_ms)
        for drawing in stopped:
            self._wearer_stops[drawing] = now_wall_ms
            self._admission.cancelled.cancel(drawing, now_wall_ms)
        for drawing in list(self._wearer_stops):  # as many as the admission remembers
            if drawing not in self._admission.cancelled:
                self._wearer_stops.pop(drawing, None)
        told = [ref for ref in list(self._refused_paused) if ref.drawing in stopped]
        self._refused_paused.clear()
        for ref in told:
            self._event(cancelled(ref, now_wall_ms, started=False, by=WEARER))
        log.info(
            "sleeve %s: the wearer stopped %s",
            self._id,
            f"drawing{'s' if len(stopped) > 1 else ''} {', '.join(sorted(stopped))}"
            if stopped
            else "what played (no drawing under way)",
        )

    def _controls_changed(self, state: ControlsState) -> None:
        log.info("sleeve %s: the wearer's controls: %s", self._id, describe(state))
        self._outbox.put(
            _Publish(telemetry_topic(self._id, "status"), self._status(online=True), 1, True)
        )

    # --- what the sleeve tells the world -----------------------------------------------

    def _reject(self, reason: str, message: str, ref: StrokeRef, ack: _Ack | None = None) -> None:
        """Report a stroke that will not play; acknowledge it after the event unless the
        sleeve is only going away (then the broker must deliver it again)."""
        original_played = None
        if reason == DUPLICATE:
            # The copy's sender learns whether the stroke was felt: a copy of a played stroke
            # leaves it played (once), a copy of a refused one leaves it refused.
            original_played = self._player.started(ref.drawing, ref.seq)
            message = duplicate_message(ref.drawing, ref.seq, original_played)
        if reason in WEARER_REFUSALS:
            # Once per drawing while the wearer's choice lasts: a drawing sent to a paused
            # sleeve would otherwise fill the journal a line a stroke.
            key = (reason, ref.drawing)
            if key not in self._quiet_refusals:
                self._quiet_refusals.add(key)
                log.info(
                    "sleeve %s: refusing the strokes of drawing %s (%s): %s",
                    self._id,
                    ref.drawing,
                    reason,
                    message,
                )
        else:
            log.info("sleeve %s: rejected a stroke (%s): %s", self._id, reason, message)
        rejected = Rejected(
            reason=reason, message=message, stroke=ref, original_played=original_played
        )
        if reason in NOT_ACKNOWLEDGED:
            ack = None
        elif ack is not None:
            # Settled: a copy the broker delivers again gets no second verdict.
            self._player.remember(ref.drawing, ref.seq)
        self._event(rejected, ack)

    def _event(self, event: Event, ack: _Ack | None = None) -> None:
        """Called from the player thread too: only queues, never touches the network.

        A stroke's acknowledgement goes out after the event about it (same queue, same
        connection).
        """
        if isinstance(event, Played):
            self._count("played")
            self._say_if_delayed(event)
        elif isinstance(event, Rejected):  # by the sleeve, or by the player for a pause
            self._count("rejected", f"rejected:{event.reason}")
            if event.reason == PAUSED and isinstance(event.stroke.drawing, str):
                self._refused_paused.append(event.stroke)
        elif isinstance(event, Cancelled):
            self._count("cancelled")
        elif isinstance(event, Safety) and event.reason == "duty_cycle":
            self._count("capped")
        elif isinstance(event, Safety) and event.reason in HARDWARE_EVENTS:
            self._count(event.reason)
            # After the event: a reader that sees the status change has the event about it.
            # The journal takes it too: a stroke a lost chip cut is cut short, not played.
            self._outbox.put(
                _Publish(telemetry_topic(self._id, "events"), event.dumps(), 1, False, event)
            )
            self._outbox.put(
                _Publish(telemetry_topic(self._id, "status"), self._status(online=True), 1, True)
            )
            if ack is not None:
                self._outbox.put(ack)
            return
        if isinstance(event, ErrorEvent) and event.reason == "player_crashed":
            self._fatal = FeelMySignError(
                "the player stopped on an unexpected error (see the log); every motor is off"
            )
            self._stopped.set()
        self._outbox.put(
            _Publish(telemetry_topic(self._id, "events"), event.dumps(), 1, False, event)
        )
        if ack is not None:
            self._outbox.put(ack)

    def _report_interrupted(self) -> None:
        """The strokes the sleeve's last process was playing when it ended (``kill -9``, a
        crash, a power cut): each reported cut short (``safety`` ``crashed``, after the
        ``played`` event that process published), once the broker is reached. Not in this
        process's journal: it never played them."""
        for interrupted in self._interrupted:
            event = crashed_event(interrupted)
            self._count("crashed")
            log.warning(
                "sleeve %s: stroke %s of drawing %s was cut short when the sleeve's last "
                "process ended (%s)",
                self._id,
                "?" if event.seq is None else event.seq + 1,
                event.drawing,
                played_words(interrupted),
            )
            self._outbox.put(_Publish(telemetry_topic(self._id, "events"), event.dumps(), 1, False))
        self._interrupted = []

    def _say_if_delayed(self, event: Played) -> None:
        """A stroke felt long after it was sent (held by the broker, a slow network): logged, with
        its delay. Not ``late``, the refusal of a stroke the sleeve is too far behind for."""
        delay_ms = delivery_delay_ms(event)
        if delay_ms is not None and delay_ms > LOG_DELAYED_MS:
            log.warning(
                "sleeve %s: stroke %s of drawing %s delayed by %.1f s (it waited at the broker "
                "or on the way)",
                self._id,
                # Counted from 1, as the page and send's lines count strokes.
                "?" if event.seq is None else event.seq + 1,
                event.drawing,
                delay_ms / 1000,
            )

    def _count(self, *names: str) -> None:
        with self._counts_lock:
            for name in names:
                self.counts[name] += 1

    def publish_actuators(self, frame: dict[str, Any]) -> None:
        """Telemetry for previews: best effort (QoS 0), never retained."""
        self._outbox.put(
            _Publish(telemetry_topic(self._id, "actuators"), json.dumps(frame), 0, False)
        )

    def stroke_totals(self) -> dict[Fate, int]:
        """Every stroke the sleeve answered, by its fate (feelmysign.fates): a stroke counted once,
        a copy delivered again changing nothing, one cut short (by a stop or a lost chip) not
        played, one the duty-cycle cap kept from playing refused. What its stop line says."""
        with self._journal_lock:
            return self._journal.totals()

    def _write_journal(self, *, every_drawing: bool = False) -> None:
        """Log the drawings that are over (every one, at the end)."""
        now_s = time.monotonic()
        self._journal_checked_s = now_s
        with self._journal_lock:
            lines = self._journal.finished(now_s, all_of_them=every_drawing)
        for line in lines:
            log.info("sleeve %s: %s", self._id, line)

    def _publish_loop(self) -> None:
        while True:
            # While a stroke plays, the note of it is brought up to date at its end and now
            # and then (feelmysign.sleeve.pace_memory): the sleeve's sign of life.
            wait_s = min(JOURNAL_CHECK_S, self._pace_memory.keep_up())
            try:
                item = self._outbox.get(timeout=wait_s)
            except queue.Empty:
                self._write_journal()  # quiet: a good moment to look
                self._pace_memory.save()  # and to keep the time lines
                continue
            if time.monotonic() - self._journal_checked_s >= JOURNAL_CHECK_S:
                self._write_journal()
            if item is None:
                break
            if isinstance(item, _Ack):
                self._acknowledge(item)
                continue
            event = item.event
            if isinstance(event, Played):
                # Noted as playing before its played event leaves (and before its
                # acknowledgement, which follows it): a process that dies mid-stroke leaves the
                # note, and the next one says the stroke was cut short.
                self._pace_memory.playing(event)
            elif isinstance(event, Cancelled | Safety):
                self._pace_memory.settled(event.stroke)  # said cut: not for the next process
            try:
                self._client.publish(item.topic, item.payload, qos=item.qos, retain=item.retain)
            except (RuntimeError, ValueError, OSError) as error:
                log.warning("sleeve %s: could not publish on %s: %s", self._id, item.topic, error)
            if event is not None:
                with self._journal_lock:
                    self._journal.add(event, time.monotonic())

    def _acknowledge(self, ack: _Ack) -> None:
        # Once only: a message id is reused by the broker as soon as it is acknowledged. And
        # on the connection the stroke came in on only: after a reconnect the broker sends it
        # again, and that copy is acknowledged (as a duplicate) instead.
        if ack.sent or ack.connection != self._connection:
            return
        ack.sent = True
        try:
            self._client.ack(ack.mid, 1)
        except (RuntimeError, ValueError, OSError) as error:
            log.warning("sleeve %s: could not acknowledge a stroke: %s", self._id, error)

    def _status(self, *, online: bool) -> str:
        return Status(
            online=online,
            sleeve_id=self._id,
            version=__version__,
            backend=self._options.backend_name,
            legacy_topic=self._options.legacy_topic,
            layout=StatusLayout.of(self._layout),
            at_ms=round(time.time() * 1000),
            floor=sleeve_floor(self._layout, self._options.wearer),
            hardware=self._hardware() if online else None,
            controls=self.controls.state() if online else None,
        ).dumps()

    def _hardware(self) -> StatusHardware | None:
        """The motors' hardware now: chips lost, the enable line (the drv2605 backend only)."""
        lost: dict[tuple[int, int], str] | None = getattr(self._backend, "lost", None)
        if lost is None:
            return None
        chips = []
        for row, column in sorted(lost):
            wire = self._backend.wire((row, column)) if hasattr(self._backend, "wire") else None
            chips.append(
                LostChip(
                    row=row,
                    column=column,
                    multiplexer=None if wire is None else f"0x{wire.multiplexer:02X}",
                    channel=None if wire is None else wire.channel,
                )
            )
        enable = getattr(self._backend, "enable", None)
        silenced = bool(getattr(self._backend, "silenced", False))
        return StatusHardware(
            state="silenced" if silenced else "degraded" if chips else "ok",
            lost=tuple(chips),
            enable=None if enable is None else "high" if enable.high else "low",
        )


def played_words(interrupted: Interrupted) -> str:
    """How much of an interrupted stroke was played, as far as the note tells."""
    at_least_s = interrupted.played_at_least_ms / 1000
    return (
        f"it had played at least {at_least_s:.1f} s of its "
        f"{interrupted.duration_ms / 1000:.1f} s, and at most until the process ended"
    )


def crashed_event(interrupted: Interrupted) -> Safety:
    """The ``safety`` event ``crashed`` of a stroke cut short by the end of the sleeve's last
    process (the stroke's fields as its ``played`` event had them; row and column 0: it names
    no motor)."""
    return Safety(
        reason=CRASHED,
        row=0,
        column=0,
        message=(
            "cut short, after its played event: the sleeve's process ended while it played (it "
            "was killed, crashed or lost its power) and was started again; "
            f"{played_words(interrupted)}"
        ),
        stroke=interrupted.playing.ref(),
    )
