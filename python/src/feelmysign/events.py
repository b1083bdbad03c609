"""What the sleeve publishes, as typed values: one class per event, and its status.

The sleeve publishes one JSON object per event on ``feelmysign/<id>/events``
(``played``, ``adjusted``, ``rejected``, ``cancelled``, ``safety``, ``error``)
and a retained ``status`` (docs/protocol.md, "What the sleeve publishes").
``to_json`` gives the object as published (optional fields left out when
absent, keys in the order below); ``event_from_json`` and
``Status.from_json`` read one back: unknown keys are ignored (a newer sleeve
may add some), a missing or mistyped field raises ``EventError``. The page
reads the same messages with ``web/src/events.ts``; ``testdata/events`` keeps
the two equal.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, fields
from typing import TYPE_CHECKING, Any, ClassVar, Literal, TypeVar

from feelmysign.input_files import loads_json

if TYPE_CHECKING:
    from feelmysign.layout import Layout

EventType = Literal["played", "adjusted", "rejected", "cancelled", "safety", "error"]


class EventError(ValueError):
    """A message that is not a sleeve event (or status): ``field`` names what was wrong."""

    def __init__(self, message: str, field: str | None = None) -> None:
        super().__init__(message)
        self.field = field


class _Reader:
    """Typed access to a JSON object's fields; every wrong value raises EventError."""

    def __init__(self, data: object, what: str) -> None:
        if not isinstance(data, dict):
            raise EventError(f"{what} must be a JSON object, not {type(data).__name__}")
        self._data: dict[str, Any] = data

    def _get(self, name: str, required: bool) -> Any:
        value = self._data.get(name)
        if value is None and required:
            raise EventError(f"{name} is missing", name)
        return value

    def text(self, name: str, *, required: bool = True) -> Any:
        value = self._get(name, required)
        if value is not None and not isinstance(value, str):
            raise EventError(f"{name} must be a string", name)
        return value

    def number(self, name: str, *, required: bool = True) -> Any:
        value = self._get(name, required)
        if value is None:
            return None
        number = isinstance(value, int | float) and not isinstance(value, bool)
        if not number or not math.isfinite(value):
            raise EventError(f"{name} must be a finite number", name)
        return value

    def index(self, name: str, *, required: bool = True) -> Any:
        """A whole number 0 or more (seq, row, column, counts); 3.0 counts as 3."""
        value = self.number(name, required=required)
        if value is None:
            return None
        if value < 0 or value != int(value):
            raise EventError(f"{name} must be a whole number 0 or more", name)
        return int(value)

    def flag(self, name: str, *, required: bool = True) -> Any:
        value = self._get(name, required)
        if value is not None and not isinstance(value, bool):
            raise EventError(f"{name} must be true or false", name)
        return value

    def obj(self, name: str) -> dict[str, Any] | None:
        value = self._data.get(name)
        if value is not None and not isinstance(value, dict):
            raise EventError(f"{name} must be a JSON object", name)
        return value


def _wire(type_name: str | None, values: dict[str, Any]) -> dict[str, Any]:
    head = {} if type_name is None else {"type": type_name}
    return head | {k: v for k, v in values.items() if v is not None}


_E = TypeVar("_E", bound="_Event")


@dataclass(frozen=True)
class StrokeRef:
    """What names the stroke an event is about: the topic it came in on, its drawing and
    seq, when it was sent (the sender's wall clock) and received (the sleeve's), and the
    pace's figures. Every stroke event embeds one; on the wire its fields stand among the
    event's own, in this order (docs/protocol.md)."""

    topic: str | None = None
    drawing: str | None = None
    seq: int | None = None
    sent_at_ms: float | None = None
    age_ms: float | None = None  # received minus sent_at_ms (docs/protocol.md, pace)
    lag_ms: float | None = None  # how much later than due it starts
    received_at_ms: float | None = None

    def __init__(
        self,
        topic: str | None = None,
        drawing: str | None = None,
        seq: int | None = None,
        sent_at_ms: float | None = None,
        age_ms: float | None = None,
        lag_ms: float | None = None,
        received_at_ms: float | None = None,
    ) -> None:
        # As Stroke's: a frozen dataclass's own __init__ sets each field through
        # object.__setattr__, and the sleeve makes one per stroke before its first command.
        self.__dict__.update(
            topic=topic,
            drawing=drawing,
            seq=seq,
            sent_at_ms=sent_at_ms,
            age_ms=age_ms,
            lag_ms=lag_ms,
            received_at_ms=received_at_ms,
        )


NO_STROKE = StrokeRef()  # an event about no stroke (a motor's safety off)


@dataclass(frozen=True, kw_only=True)
class _Event:
    kind: ClassVar[EventType]

    def typed(self) -> dict[str, Any]:
        """Every field by its name on the wire, in publishing order, None where absent: the
        embedded stroke's fields stand in its place."""
        values: dict[str, Any] = {}
        for field in fields(self):
            value = getattr(self, field.name)
            if isinstance(value, StrokeRef):
                values.update(value.__dict__)  # set in field order (see its __init__)
            else:
                values[field.name] = value
        return values

    def to_json(self) -> dict[str, Any]:
        return _wire(self.kind, self.typed())

    def dumps(self) -> str:
        return json.dumps(self.to_json())

    @classmethod
    def from_json(cls: type[_E], data: object) -> _E:
        """This event from its JSON object or text; EventError if it is another type
        (``Played.from_json`` reads an ``adjusted`` event too: it was played)."""
        event = event_from_json(data)
        if not isinstance(event, cls):
            raise EventError(f"expected a {cls.kind!r} event, got {event.kind!r}", "type")
        return event


def _read_stroke(r: _Reader, *, received_required: bool = True) -> dict[str, Any]:
    """The stroke an event is about, as the ``stroke`` argument of its class."""
    stroke = StrokeRef(
        topic=r.text("topic", required=False),
        drawing=r.text("drawing", required=False),
        seq=r.index("seq", required=False),
        sent_at_ms=r.number("sent_at_ms", required=False),
        age_ms=r.number("age_ms", required=False),
        lag_ms=r.number("lag_ms", required=False),
        received_at_ms=r.number("received_at_ms", required=received_required),
    )
    return {"stroke": stroke}


class _AboutAStroke:
    """An event's stroke fields read as its own (``event.drawing``), as on the wire."""

    stroke: StrokeRef

    @property
    def topic(self) -> str | None:
        return self.stroke.topic

    @property
    def drawing(self) -> str | None:
        return self.stroke.drawing

    @property
    def seq(self) -> int | None:
        return self.stroke.seq

    @property
    def sent_at_ms(self) -> float | None:
        return self.stroke.sent_at_ms

    @property
    def age_ms(self) -> float | None:
        return self.stroke.age_ms

    @property
    def lag_ms(self) -> float | None:
        return self.stroke.lag_ms

    @property
    def received_at_ms(self) -> float | None:
        return self.stroke.received_at_ms


@dataclass(frozen=True, kw_only=True)
class Played(_AboutAStroke, _Event):
    """The stroke's first command went out (times ``*_at_ms``: the sleeve's wall clock)."""

    kind: ClassVar[EventType] = "played"
    stroke: StrokeRef  # with received_at_ms
    start_at_ms: float  # planned start
    first_command_at_ms: float
    latency_ms: float  # receive -> first command
    start_error_ms: float  # first command -> planned start
    queued_ms: float  # waiting for the strokes before it
    duration_ms: float
    commands: int
    # Played faster to catch up with its drawing (docs/protocol.md, "Playback"): by this much.
    compressed_ms: float | None = None

    @classmethod
    def _read(cls, r: _Reader) -> dict[str, Any]:
        return {
            **_read_stroke(r),
            "start_at_ms": r.number("start_at_ms"),
            "first_command_at_ms": r.number("first_command_at_ms"),
            "latency_ms": r.number("latency_ms"),
            "start_error_ms": r.number("start_error_ms"),
            "queued_ms": r.number("queued_ms"),
            "duration_ms": r.number("duration_ms"),
            "commands": r.index("commands"),
            "compressed_ms": r.number("compressed_ms", required=False),
        }


@dataclass(frozen=True, kw_only=True)
class Adjusted(Played):
    """Played, but changed to be felt: slowed (``reason: too_fast``) from the duration asked."""

    kind: ClassVar[EventType] = "adjusted"
    reason: str
    requested_duration_ms: float

    @classmethod
    def _read(cls, r: _Reader) -> dict[str, Any]:
        return Played._read(r) | {
            "reason": r.text("reason"),
            "requested_duration_ms": r.number("requested_duration_ms"),
        }


@dataclass(frozen=True, kw_only=True)
class Rejected(_AboutAStroke, _Event):
    """The stroke will not be played: ``reason`` is a code of docs/protocol.md."""

    kind: ClassVar[EventType] = "rejected"
    reason: str
    message: str
    stroke: StrokeRef  # with received_at_ms
    # A ``duplicate`` only: whether the stroke it is a copy of started playing (it was felt,
    # and stays played) or not (refused, capped or cancelled before). Absent from other
    # reasons, and from a sleeve older than the field.
    original_played: bool | None = None

    @classmethod
    def _read(cls, r: _Reader) -> dict[str, Any]:
        return {
            "reason": r.text("reason"),
            "message": r.text("message"),
            **_read_stroke(r),
            "original_played": r.flag("original_played", required=False),
        }


@dataclass(frozen=True, kw_only=True)
class Cancelled(_AboutAStroke, _Event):
    """A control message cancelled the stroke: ``started`` when it was cut short while playing
    (it had its ``played`` event), not when it was dropped before it started. ``by`` is
    ``"wearer"`` when the wearer stopped or paused the sleeve (its button, its page); absent
    for a sender's control message, and from sleeves older than the field."""

    kind: ClassVar[EventType] = "cancelled"
    reason: str = "cancelled"
    message: str
    stroke: StrokeRef  # with received_at_ms
    cancelled_at_ms: float
    started: bool
    by: str | None = None

    @classmethod
    def _read(cls, r: _Reader) -> dict[str, Any]:
        return {
            "reason": r.text("reason"),
            "message": r.text("message"),
            **_read_stroke(r),
            "cancelled_at_ms": r.number("cancelled_at_ms"),
            "started": r.flag("started"),
            "by": r.text("by", required=False),
        }


@dataclass(frozen=True, kw_only=True)
class Safety(_AboutAStroke, _Event):
    """A motor was protected: a stroke the duty-cycle cap kept from playing (``duty_cycle``:
    the stroke's fields, the motor's would-be duty cycle and the limit); a chip that stopped
    answering (``chip_lost``, one per stroke cut, or one without a stroke) or answers again
    (``chip_back``); a stroke cut while the sleeve is silent (``silenced``); a stroke cut short
    after its ``played`` because the sleeve stopped (``stopped``) or its process ended
    (``crashed``, said by the sleeve started next) while it played. Sleeves before these sent
    ``off_failed`` for an off that failed twice."""

    kind: ClassVar[EventType] = "safety"
    reason: str
    row: int
    column: int
    message: str | None = None
    stroke: StrokeRef = NO_STROKE
    duty_cycle: float | None = None  # what the window would have held, 0..1 of full drive
    max_duty_cycle: float | None = None
    window_ms: float | None = None

    @classmethod
    def _read(cls, r: _Reader) -> dict[str, Any]:
        return {
            "reason": r.text("reason"),
            "row": r.index("row"),
            "column": r.index("column"),
            "message": r.text("message", required=False),
            **_read_stroke(r, received_required=False),
            "duty_cycle": r.number("duty_cycle", required=False),
            "max_duty_cycle": r.number("max_duty_cycle", required=False),
            "window_ms": r.number("window_ms", required=False),
        }


@dataclass(frozen=True, kw_only=True)
class ErrorEvent(_Event):
    """A motor write failed (``backend``, with the actuator), or the player stopped on a bug."""

    kind: ClassVar[EventType] = "error"
    reason: str
    message: str | None = None
    row: int | None = None
    column: int | None = None

    @classmethod
    def _read(cls, r: _Reader) -> dict[str, Any]:
        return {
            "reason": r.text("reason"),
            "message": r.text("message", required=False),
            "row": r.index("row", required=False),
            "column": r.index("column", required=False),
        }


Event = Played | Adjusted | Rejected | Cancelled | Safety | ErrorEvent
EVENT_CLASSES: dict[str, type[Played | Rejected | Cancelled | Safety | ErrorEvent]] = {
    cls.kind: cls for cls in (Played, Adjusted, Rejected, Cancelled, Safety, ErrorEvent)
}


def event_from_json(data: object) -> Event:
    """An event from its JSON object (or text); EventError if it is not one."""
    if isinstance(data, str | bytes):
        try:
            data = loads_json(data)
        except ValueError as error:
            raise EventError(f"not JSON: {error}") from None
    r = _Reader(data, "an event")
    kind = r.text("type")
    cls = EVENT_CLASSES.get(kind)
    if cls is None:
        known = ", ".join(EVENT_CLASSES)
        raise EventError(f"unknown event type {kind!r}; known: {known}", "type")
    event: Event = cls(**cls._read(r))
    return event


# --- what a played event means for its sender --------------------------------------------

# A stroke whose delivery delay is above this was "delayed": the page and the terminal of
# 'feelmysign up' mark it. Not the sleeve's `late` refusal (docs/protocol.md, pace), which
# skips a stroke; a delayed stroke was played.
DELAYED_MS = 500.0


# Stroke events remembered to tell a copy from a new event: far more than one drawing sends.
REMEMBERED_EVENTS = 4096


class EventCopies:
    """Tells a copy of a stroke's event from a new one.

    The sleeve publishes events at QoS 1, so after a broker restart a reader may get
    the same event twice; counting it twice would report a stroke played twice that was
    felt once. A stroke's event carries its times, so a copy is equal in every field and
    two real events never are. Events that name no stroke (errors, a message the sleeve
    could not read) are never held back. The page does the same (``EventCopies`` in
    web/src/events.ts).
    """

    def __init__(self, capacity: int = REMEMBERED_EVENTS) -> None:
        from collections import OrderedDict

        self._capacity = capacity
        self._seen: OrderedDict[Event, None] = OrderedDict()

    def is_copy(self, event: Event) -> bool:
        """True when ``event`` is a copy of a stroke's event already seen (else remembered)."""
        if getattr(event, "drawing", None) is None or getattr(event, "seq", None) is None:
            return False
        if event in self._seen:
            return True
        self._seen[event] = None
        if len(self._seen) > self._capacity:
            self._seen.popitem(last=False)
        return False


def delivery_delay_ms(event: Played) -> float | None:
    """How long a played stroke was held on its way: sent -> its first motor command, less
    its wait behind the strokes before it (playing a drawing back to back is the design, not
    a delay). What remains is the network, the broker holding it, the sleeve offline. None
    when the stroke carried no ``sent_at_ms`` (the two clocks are the sender's and the
    sleeve's: their offset is part of the figure). web/src/events.ts computes the same, and
    ``testdata/events/delay`` keeps the two equal."""
    if event.sent_at_ms is None:
        return None
    return event.first_command_at_ms - event.sent_at_ms - event.queued_ms


def is_delayed(event: Played, *, threshold_ms: float = DELAYED_MS) -> bool:
    """Whether ``event``'s stroke was delayed on its way (see ``delivery_delay_ms``)."""
    delay_ms = delivery_delay_ms(event)
    return delay_ms is not None and delay_ms > threshold_ms


# The order the sleeve publishes the layout's keys in.
_LAYOUT_ORDER = (
    "name",
    "rows",
    "columns",
    "spacing_cm",
    "actuator_type",
    "default_intensity",
    "max_intensity",
    "max_stroke_duration_ms",
)


@dataclass(frozen=True, kw_only=True)
class StatusLayout:
    """The sleeve's layout as its status tells it (the page sizes its grid from this)."""

    rows: int
    columns: int
    name: str | None = None
    spacing_cm: float | None = None
    actuator_type: str | None = None
    default_intensity: float | None = None
    max_intensity: float | None = None
    max_stroke_duration_ms: float | None = None

    @classmethod
    def of(cls, layout: Layout) -> StatusLayout:
        """What the status tells of ``layout``."""
        return cls(**{name: getattr(layout, name) for name in _LAYOUT_ORDER})

    @classmethod
    def from_json(cls, data: object) -> StatusLayout:
        r = _Reader(data, "layout")
        rows, columns = r.index("rows"), r.index("columns")
        if not 1 <= rows <= 64 or not 1 <= columns <= 64:
            raise EventError("layout rows and columns must be 1 to 64", "layout")
        return cls(
            rows=rows,
            columns=columns,
            name=r.text("name", required=False),
            spacing_cm=r.number("spacing_cm", required=False),
            actuator_type=r.text("actuator_type", required=False),
            default_intensity=r.number("default_intensity", required=False),
            max_intensity=r.number("max_intensity", required=False),
            max_stroke_duration_ms=r.number("max_stroke_duration_ms", required=False),
        )

    def to_json(self) -> dict[str, Any]:
        values = asdict(self)
        return _wire(None, {name: values[name] for name in _LAYOUT_ORDER})


@dataclass(frozen=True)
class LostChip:
    """A DRV2605L that stopped answering and has not taken an "off" since."""

    row: int
    column: int
    multiplexer: str | None = None  # "0x70"
    channel: int | None = None

    def to_json(self) -> dict[str, Any]:
        return _wire(None, asdict(self))


@dataclass(frozen=True)
class StatusHardware:
    """The motors' hardware as the status tells it: ``state`` is ``ok``, ``degraded`` (a chip
    lost, its motor perhaps still on, the others playing) or ``silenced`` (the enable line held
    low for a lost chip: nothing plays); ``enable`` is the line's level, None without one."""

    state: str
    lost: tuple[LostChip, ...] = ()
    enable: str | None = None  # "high" or "low"

    @classmethod
    def from_json(cls, data: object) -> StatusHardware:
        r = _Reader(data, "hardware")
        raw = data.get("lost", []) if isinstance(data, dict) else []
        if not isinstance(raw, list):
            raise EventError("lost must be an array", "lost")
        lost = []
        for item in raw:
            chip = _Reader(item, "hardware.lost")
            lost.append(
                LostChip(
                    row=chip.index("row"),
                    column=chip.index("column"),
                    multiplexer=chip.text("multiplexer", required=False),
                    channel=chip.index("channel", required=False),
                )
            )
        return cls(state=r.text("state"), lost=tuple(lost), enable=r.text("enable", required=False))

    def to_json(self) -> dict[str, Any]:
        return _wire(
            None,
            {
                "state": self.state,
                "lost": [chip.to_json() for chip in self.lost],
                "enable": self.enable,
            },
        )


@dataclass(frozen=True, kw_only=True)
class StatusFloor:
    """The least a stroke should be for this sleeve to play it as sent and its wearer to feel it.

    ``min_duration_ms``: the shortest stroke the sleeve plays without slowing it (its
    layout's two end bursts, ``apparent_motion.shortest_planned_ms``), or the wearer's
    measured limit when that is longer; ``min_length``: the shortest stroke felt as moving
    (grid units), likewise. ``wearer``: whose measured limits are in it, when any. A sender
    raises its simplifier's ``min_duration_ms`` and ``min_length`` to at least these.
    """

    min_duration_ms: float
    min_length: float
    wearer: str | None = None

    @classmethod
    def from_json(cls, data: object) -> StatusFloor:
        r = _Reader(data, "floor")
        min_duration_ms, min_length = r.number("min_duration_ms"), r.number("min_length")
        if min_duration_ms < 0 or min_length < 0:
            raise EventError("floor min_duration_ms and min_length must be 0 or more", "floor")
        return cls(
            min_duration_ms=min_duration_ms,
            min_length=min_length,
            wearer=r.text("wearer", required=False),
        )

    def to_json(self) -> dict[str, Any]:
        return _wire(None, asdict(self))


@dataclass(frozen=True)
class StatusControls:
    """The wearer's controls as the status tells them (``feelmysign.sleeve.controls``, where
    it is also ``ControlsState``): ``paused`` (and by what: ``"button"``, ``"page"`` or
    ``"cli"``), the wearer's intensity ceiling, and "do not disturb" until a wall-clock time
    (ms since 1970). The sleeve refuses every stroke while paused (``paused``) or while "do
    not disturb" runs (``do_not_disturb``); no motor drives above the ceiling."""

    paused: bool = False
    paused_by: str | None = None
    ceiling: float | None = None
    do_not_disturb_until_ms: int | None = None

    @classmethod
    def from_json(cls, data: object) -> StatusControls:
        r = _Reader(data, "controls")
        ceiling = r.number("ceiling", required=False)
        if ceiling is not None and not 0 <= ceiling <= 1:
            raise EventError("controls ceiling must be from 0 to 1", "controls")
        until_ms = r.index("do_not_disturb_until_ms", required=False)
        return cls(
            paused=r.flag("paused"),
            paused_by=r.text("paused_by", required=False),
            ceiling=ceiling,
            do_not_disturb_until_ms=until_ms,
        )

    def to_json(self) -> dict[str, Any]:
        """All four keys, null where not set: a reader tells "not set" from an older sleeve."""
        return asdict(self)


@dataclass(frozen=True, kw_only=True)
class Status:
    """The retained ``status``: ``online`` is all a last will must carry.

    ``floor`` came later than the other fields: absent from an older sleeve's status, and
    an older reader ignores it. So did ``controls`` (the wearer's): absent from the last
    will and from older sleeves, which a reader takes as not paused, no ceiling, no "do
    not disturb"."""

    online: bool
    sleeve_id: str | None = None
    version: str | None = None
    backend: str | None = None
    legacy_topic: str | None = None
    layout: StatusLayout | None = None
    at_ms: float | None = None
    floor: StatusFloor | None = None
    hardware: StatusHardware | None = None  # the drv2605 backend's only
    controls: StatusControls | None = None

    @classmethod
    def from_json(cls, data: object) -> Status:
        if isinstance(data, str | bytes):
            try:
                data = loads_json(data)
            except ValueError as error:
                raise EventError(f"not JSON: {error}") from None
        r = _Reader(data, "a status")
        layout = r.obj("layout")
        floor = r.obj("floor")
        hardware = r.obj("hardware")
        controls = r.obj("controls")
        return cls(
            online=r.flag("online"),
            sleeve_id=r.text("sleeve_id", required=False),
            version=r.text("version", required=False),
            backend=r.text("backend", required=False),
            legacy_topic=r.text("legacy_topic", required=False),
            layout=None if layout is None else StatusLayout.from_json(layout),
            at_ms=r.number("at_ms", required=False),
            floor=None if floor is None else StatusFloor.from_json(floor),
            hardware=None if hardware is None else StatusHardware.from_json(hardware),
            controls=None if controls is None else StatusControls.from_json(controls),
        )

    def to_json(self) -> dict[str, Any]:
        # legacy_topic is published as null when the sleeve listens to none: kept as it is sent.
        wire = _wire(
            None,
            {
                "online": self.online,
                "sleeve_id": self.sleeve_id,
                "version": self.version,
                "backend": self.backend,
                "legacy_topic": self.legacy_topic,
                "layout": None if self.layout is None else self.layout.to_json(),
                "at_ms": self.at_ms,
                "floor": None if self.floor is None else self.floor.to_json(),
                "hardware": None if self.hardware is None else self.hardware.to_json(),
                "controls": None if self.controls is None else self.controls.to_json(),
            },
        )
        return wire

    def dumps(self) -> str:
        return json.dumps(self.to_json())
