"""Vectors for what the sleeve publishes: its events and its status (feelmysign.events).

- ``event/<name>.json``: ``wire`` (a message as received), ``typed`` (every field of the
  event it reads as, ``null`` when absent) and ``json`` (what ``to_json`` writes back:
  optional fields left out, unknown keys dropped, keys in publishing order);
- ``status/<name>.json``: the same for the retained status (``typed`` holds ``floor`` only
  when the status has one);
- ``invalid/<name>.json``: ``kind`` (``event`` or ``status``) and a ``wire`` value that
  is not one, with the ``field`` at fault (``null`` when it is the whole message).
- ``delay/<name>.json``: a played or adjusted event's ``wire``, its ``delay_ms`` (sent ->
  first motor command, less its wait behind the strokes before it; ``null`` without a
  ``sent_at_ms``) and whether it was ``delayed`` (``events.DELAYED_MS``, kept as
  ``delayed_ms``): the page marks the same strokes as the terminal of ``feelmysign up``.

- ``fates/<name>.json``: the events (``wire``, in the order the sleeve published them) of
  one drawing's strokes, and what became of each stroke by the rule of
  feelmysign.fates: ``fates`` by seq, ``counts`` by fate and the refused strokes'
  reasons (``refusals``). The page, ``up`` and the study report from this rule. And how the
  sleeve kept the drawing in time (``catch_up``: strokes played faster to catch up and by
  how much in all, slowed to its floor, skipped as late) with the words the page's card,
  ``up`` and ``send --wait`` say of the played (``catch_up_words``).

Every expected value is computed here by feelmysign.events (and feelmysign.fates); a case that the
reference reads differently from what it is meant to show stops generation.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from feelmysign.events import (
    DELAYED_MS,
    Event,
    EventError,
    Played,
    Status,
    delivery_delay_ms,
    event_from_json,
    is_delayed,
)
from feelmysign.fates import NOTABLE_CHANGE, DrawingFates

TIMING = {
    "received_at_ms": 1795326267664.25,
    "start_at_ms": 1795326267664.25,
    "first_command_at_ms": 1795326267664.5,
    "latency_ms": 0.25,
    "start_error_ms": 0.031,
    "queued_ms": 0,
    "duration_ms": 417.5,
    "commands": 5,
}
STROKE = {"topic": "feelmysign/sleeve1/strokes", "drawing": "d-1", "seq": 3}
LAYOUT = {
    "name": "paper-sleeve",
    "rows": 3,
    "columns": 4,
    "spacing_cm": 3.0,
    "actuator_type": "ERM",
    "default_intensity": 0.8,
    "max_intensity": 1.0,
    "max_stroke_duration_ms": 10000.0,
}

EVENTS: dict[str, tuple[str, dict[str, Any]]] = {
    "played": ("a stroke of a drawing played", {"type": "played", **STROKE, **TIMING}),
    "played-legacy": (
        "a legacy stroke: no drawing, seq or sent_at_ms",
        {"type": "played", "topic": "deviceOne/line", **TIMING},
    ),
    "played-with-sent-at": (
        "the sender stamped sent_at_ms",
        {"type": "played", **STROKE, "sent_at_ms": 1795326267600, **TIMING},
    ),
    "played-with-pace": (
        "how old the stroke was and how late it started (the pace rules)",
        {
            "type": "played",
            **STROKE,
            "sent_at_ms": 1795326267600,
            "age_ms": 64.3,
            "lag_ms": 0,
            **TIMING,
        },
    ),
    "played-compressed": (
        "a stroke played faster to catch up with its drawing, by compressed_ms",
        {"type": "played", **STROKE, **TIMING, "queued_ms": 180.5, "compressed_ms": 126.299},
    ),
    "rejected-late": (
        "a stroke skipped to catch up after a stall",
        {
            "type": "rejected",
            "reason": "late",
            "message": "the stroke would start 4.20 s after it was due",
            **STROKE,
            "sent_at_ms": 1795326263400,
            "age_ms": 4264.3,
            "lag_ms": 4200.5,
            "received_at_ms": 1795326267664.25,
        },
    ),
    "played-unknown-keys": (
        "keys a newer sleeve may add are ignored",
        {"type": "played", **STROKE, **TIMING, "colour": "red", "extra": {"a": [1]}},
    ),
    "played-seq-as-float": (
        "3.0 is the whole number 3 (JavaScript cannot tell them apart)",
        {"type": "played", **STROKE, **TIMING, "seq": 3.0},
    ),
    "played-null-optional": (
        "null for an optional field means absent",
        {"type": "played", "topic": None, "drawing": None, "seq": None, **TIMING},
    ),
    "adjusted": (
        "a stroke slowed to be felt",
        {
            "type": "adjusted",
            **STROKE,
            **TIMING,
            "reason": "too_fast",
            "requested_duration_ms": 120,
        },
    ),
    "rejected": (
        "a stroke refused, with the reason code and sentence",
        {
            "type": "rejected",
            "reason": "outside_grid",
            "message": "start (4, 0) is outside the grid",
            **STROKE,
            "received_at_ms": 1795326267664.25,
        },
    ),
    "rejected-unparsed": (
        "a payload that could not be read: only the topic is known",
        {
            "type": "rejected",
            "reason": "invalid_json",
            "message": "not JSON",
            "topic": "feelmysign/sleeve1/strokes",
            "received_at_ms": 1795326267664.25,
        },
    ),
    "cancelled-queued": (
        "a stroke dropped from the queue by a cancel",
        {
            "type": "cancelled",
            "reason": "cancelled",
            "message": "cancelled by a control message",
            **STROKE,
            "received_at_ms": 1795326267664.25,
            "cancelled_at_ms": 1795326268000.5,
            "started": False,
        },
    ),
    "cancelled-playing": (
        "the stroke playing when the cancel came, cut short",
        {
            "type": "cancelled",
            "reason": "cancelled",
            "message": "cancelled by a control message",
            **STROKE,
            "received_at_ms": 1795326267664.25,
            "cancelled_at_ms": 1795326268000.5,
            "started": True,
        },
    ),
    "cancelled-by-wearer": (
        "the stroke playing when the wearer paused or stopped the sleeve, cut short",
        {
            "type": "cancelled",
            "reason": "cancelled",
            "message": "cut short by the wearer",
            **STROKE,
            "received_at_ms": 1795326267664.25,
            "cancelled_at_ms": 1795326268000.5,
            "started": True,
            "by": "wearer",
        },
    ),
    "rejected-paused": (
        "a stroke that came while the wearer had paused the sleeve",
        {
            "type": "rejected",
            "reason": "paused",
            "message": "the wearer paused the sleeve; it plays again when the wearer presses "
            "the pause button again, or resumes on the wearer's page",
            **STROKE,
            "received_at_ms": 1795326267664.25,
        },
    ),
    "rejected-do-not-disturb": (
        'a stroke that came while the wearer\'s "do not disturb" ran',
        {
            "type": "rejected",
            "reason": "do_not_disturb",
            "message": "the wearer asked not to be disturbed until 2026-11-23 08:00:00 UTC; "
            "strokes play again after that",
            **STROKE,
            "received_at_ms": 1795326267664.25,
        },
    ),
    "safety-duty-cycle": (
        "a stroke the duty-cycle cap kept from playing, with the motor and by how much",
        {
            "type": "safety",
            "reason": "duty_cycle",
            "row": 1,
            "column": 2,
            "message": "not played: the motor would have been driven 52% of the last 60 s",
            **STROKE,
            "received_at_ms": 1795326267664.25,
            "duty_cycle": 0.52,
            "max_duty_cycle": 0.5,
            "window_ms": 60000.0,
        },
    ),
    "safety-off-failed": (
        "an off that failed twice: every motor off",
        {"type": "safety", "reason": "off_failed", "row": 0, "column": 3},
    ),
    "error-backend": (
        "a motor write failed",
        {"type": "error", "reason": "backend", "message": "I2C error", "row": 2, "column": 0},
    ),
    "error-player-crashed": (
        "the player stopped on a bug",
        {"type": "error", "reason": "player_crashed"},
    ),
}

STATUSES: dict[str, tuple[str, dict[str, Any]]] = {
    "online": (
        "what the sleeve publishes on connecting",
        {
            "online": True,
            "sleeve_id": "sleeve1",
            "version": "0.1.0",
            "backend": "sim",
            "legacy_topic": "deviceOne/line",
            "layout": LAYOUT,
            "at_ms": 1795326267664,
        },
    ),
    "last-will": ("the least a status carries", {"online": False}),
    "no-legacy-topic": (
        "a sleeve without the legacy topic publishes null for it",
        {"online": True, "sleeve_id": "s2", "legacy_topic": None, "layout": LAYOUT},
    ),
    "small-layout": (
        "a layout with only its grid",
        {"online": True, "layout": {"rows": 4, "columns": 6}},
    ),
    "floor": (
        "the sleeve's floor: the shortest stroke it plays unslowed (ERM), the shortest felt",
        {
            "online": True,
            "layout": LAYOUT,
            "floor": {"min_duration_ms": 73.701, "min_length": 0.05},
        },
    ),
    "controls-paused": (
        "the wearer paused the sleeve with its button and set an intensity ceiling",
        {
            "online": True,
            "sleeve_id": "sleeve1",
            "layout": LAYOUT,
            "at_ms": 1795326267664,
            "controls": {
                "paused": True,
                "paused_by": "button",
                "ceiling": 0.6,
                "do_not_disturb_until_ms": None,
            },
        },
    ),
    "controls-do-not-disturb": (
        '"do not disturb" until a time, not paused, no ceiling',
        {
            "online": True,
            "sleeve_id": "sleeve1",
            "layout": LAYOUT,
            "controls": {
                "paused": False,
                "paused_by": None,
                "ceiling": None,
                "do_not_disturb_until_ms": 1795330000000,
            },
        },
    ),
    "floor-wearer": (
        "the floor raised to a wearer's measured limits",
        {
            "online": True,
            "sleeve_id": "sleeve1",
            "layout": LAYOUT,
            "at_ms": 1795326267664,
            "floor": {"min_duration_ms": 118.4, "min_length": 0.62, "wearer": "P01"},
        },
    ),
}

INVALID: dict[str, tuple[str, str, Any]] = {
    "event-not-object": ("event", "a JSON array is not an event", [1, 2]),
    "event-no-type": ("event", "no type", {"reason": "backend"}),
    "event-unknown-type": ("event", "a type no sleeve publishes", {"type": "exploded"}),
    "event-type-not-string": ("event", "type must be a string", {"type": 1}),
    "played-missing-timing": (
        "event",
        "played without its timing",
        {"type": "played", **STROKE},
    ),
    "played-negative-seq": (
        "event",
        "seq below 0",
        {"type": "played", **STROKE, **TIMING, "seq": -1},
    ),
    "played-fractional-seq": (
        "event",
        "seq 1.5",
        {"type": "played", **STROKE, **TIMING, "seq": 1.5},
    ),
    "played-latency-string": (
        "event",
        "a number sent as text",
        {"type": "played", **STROKE, **TIMING, "latency_ms": "0.25"},
    ),
    "played-duration-bool": (
        "event",
        "true is not a number",
        {"type": "played", **STROKE, **TIMING, "duration_ms": True},
    ),
    "adjusted-no-requested": (
        "event",
        "adjusted without the duration asked",
        {"type": "adjusted", **STROKE, **TIMING, "reason": "too_fast"},
    ),
    "rejected-no-message": (
        "event",
        "rejected without its sentence",
        {"type": "rejected", "reason": "x", "received_at_ms": 1},
    ),
    "cancelled-started-not-bool": (
        "event",
        "started must be true or false",
        {
            "type": "cancelled",
            "reason": "cancelled",
            "message": "m",
            "received_at_ms": 1,
            "cancelled_at_ms": 2,
            "started": 1,
        },
    ),
    "safety-no-row": ("event", "safety without its actuator", {"type": "safety", "reason": "x"}),
    "status-not-object": ("status", "a string is not a status", "online"),
    "status-online-string": ("status", "online must be true or false", {"online": "yes"}),
    "status-no-online": ("status", "online is required", {"sleeve_id": "s"}),
    "status-layout-zero-rows": (
        "status",
        "a grid side outside 1..64",
        {"online": True, "layout": {"rows": 0, "columns": 4}},
    ),
    "status-floor-negative": (
        "status",
        "a floor below 0",
        {"online": True, "floor": {"min_duration_ms": -1, "min_length": 0.05}},
    ),
    "status-floor-no-length": (
        "status",
        "a floor without its length",
        {"online": True, "floor": {"min_duration_ms": 73.701}},
    ),
    "status-controls-no-paused": (
        "status",
        "the wearer's controls without paused",
        {"online": True, "controls": {"ceiling": 0.5}},
    ),
    "status-controls-ceiling-above-one": (
        "status",
        "a ceiling above full drive",
        {"online": True, "controls": {"paused": False, "ceiling": 1.5}},
    ),
    "status-controls-until-fractional": (
        "status",
        "do_not_disturb_until_ms is a whole number of ms",
        {"online": True, "controls": {"paused": False, "do_not_disturb_until_ms": 1.5}},
    ),
    "cancelled-by-not-string": (
        "event",
        "by must be a string",
        {
            "type": "cancelled",
            "reason": "cancelled",
            "message": "m",
            "received_at_ms": 1,
            "cancelled_at_ms": 2,
            "started": True,
            "by": True,
        },
    ),
    "status-layout-not-object": (
        "status",
        "layout must be an object",
        {"online": True, "layout": [3, 4]},
    ),
}


SENT_MS = 1795326267000.0


def _delay_case(first_after_sent_ms: float, queued_ms: float, **extra: Any) -> dict[str, Any]:
    """A played event felt ``first_after_sent_ms`` after it was sent, ``queued_ms`` of it in
    the queue behind the strokes before it."""
    first_ms = SENT_MS + first_after_sent_ms
    timing = {**TIMING, "queued_ms": queued_ms, "first_command_at_ms": first_ms}
    return {"type": "played", **STROKE, "sent_at_ms": SENT_MS, **timing, **extra}


# Delivery delays, around DELAYED_MS (500 ms): what the page and 'up' mark as delayed.
DELAYS: dict[str, tuple[str, dict[str, Any]]] = {
    "on-time": ("felt 64.5 ms after it was sent: not delayed", _delay_case(64.5, 0)),
    "delayed": ("felt 1.6 s after it was sent, none of it queued", _delay_case(1600.25, 0)),
    "queued-not-delayed": (
        "felt 2 s after it was sent, 1.9 s of it behind the strokes before it: not delayed",
        _delay_case(2000.0, 1900.0),
    ),
    "queued-and-delayed": (
        "felt 2.7 s after it was sent, 1.9 s of it queued: delayed by 0.8 s",
        _delay_case(2700.5, 1900.25),
    ),
    "at-the-threshold": ("a delay of exactly 500 ms is not delayed", _delay_case(500.0, 0)),
    "just-above": ("a delay of 500.25 ms is delayed", _delay_case(500.25, 0)),
    "sender-clock-ahead": (
        "the sender's clock runs ahead of the sleeve's: a negative delay, not delayed",
        _delay_case(-250.0, 0),
    ),
    "no-sent-at": (
        "a stroke without sent_at_ms has no delivery delay",
        {"type": "played", "topic": "deviceOne/line", **TIMING},
    ),
    "adjusted-delayed": (
        "an adjusted stroke is delayed by the same rule",
        _delay_case(900.0, 100.0, type="adjusted", reason="too_fast", requested_duration_ms=50),
    ),
}


def _stroke(seq: int) -> dict[str, Any]:
    return {**STROKE, "seq": seq}


def _played(seq: int) -> dict[str, Any]:
    return {"type": "played", **_stroke(seq), **TIMING}


def _compressed(seq: int, compressed_ms: float) -> dict[str, Any]:
    return {**_played(seq), "queued_ms": 180.5, "compressed_ms": compressed_ms}


def _slowed(seq: int) -> dict[str, Any]:
    wire = {"type": "adjusted", **_stroke(seq), **TIMING, "duration_ms": 73.7}
    return {**wire, "reason": "too_fast", "requested_duration_ms": 41.5}


def _rejected(seq: int, reason: str, **extra: Any) -> dict[str, Any]:
    message = f"refused as {reason}"
    wire = {"type": "rejected", "reason": reason, "message": message, **_stroke(seq)}
    return {**wire, "received_at_ms": 1795326267664.25, **extra}


def _cancelled(seq: int, started: bool) -> dict[str, Any]:
    return {**EVENTS["cancelled-queued"][1], "seq": seq, "started": started}


def _capped(seq: int) -> dict[str, Any]:
    return {**EVENTS["safety-duty-cycle"][1], "seq": seq}


# What became of a drawing's strokes (feelmysign.fates), after a broker restart and a Stop.
FATES: dict[str, tuple[str, list[dict[str, Any]]]] = {
    "played": ("each stroke played once", [_played(0), _played(1)]),
    "duplicate-of-played": (
        "a broker restart delivers a played stroke again: the copy is refused as a duplicate "
        "of a played stroke, and the stroke stays played, once",
        [_played(0), _played(1), _rejected(1, "duplicate", original_played=True)],
    ),
    "duplicate-played-event-lost": (
        "the played event was lost: the duplicate's original_played says it was felt",
        [_played(0), _rejected(1, "duplicate", original_played=True)],
    ),
    "duplicate-of-refused": (
        "a copy of a refused stroke: refused, once, for the reason the stroke had",
        [_rejected(0, "late"), _rejected(0, "duplicate", original_played=False), _played(1)],
    ),
    "duplicate-from-an-older-sleeve": (
        "a duplicate without original_played, nothing else known: refused (nothing says felt)",
        [_played(0), _rejected(1, "duplicate")],
    ),
    "stop": (
        "Stop: two played whole, one cut short while playing, one dropped before it started, "
        "one refused as cancelled on arrival (sent just after the cancel), one capped",
        [
            _played(0),
            _played(1),
            _played(2),
            _cancelled(2, started=True),
            _cancelled(3, started=False),
            _rejected(4, "cancelled"),
            _capped(5),
        ],
    ),
    "copy-after-stop": (
        "a copy of a played stroke delivered after its drawing was stopped is refused as "
        "cancelled: the stroke stays played",
        [_played(0), _played(1), _cancelled(1, started=True), _rejected(0, "cancelled")],
    ),
    "wearer-paused": (
        "the wearer paused mid-drawing: the stroke playing cut short by the wearer, the one "
        "waiting and the ones sent after refused as paused, then do-not-disturb refuses one",
        [
            _played(0),
            _played(1),
            {**EVENTS["cancelled-by-wearer"][1], "seq": 1},
            _rejected(2, "paused"),
            _rejected(3, "paused"),
            _rejected(4, "do_not_disturb"),
        ],
    ),
    "wearer-stop": (
        "the wearer's stop: cut while playing, dropped before it started, both by the wearer",
        [
            _played(0),
            {**EVENTS["cancelled-by-wearer"][1], "seq": 0},
            {**EVENTS["cancelled-by-wearer"][1], "seq": 1, "started": False},
        ],
    ),
    "catching-up": (
        "strokes queued: two played faster to catch up, one slowed to the floor, two skipped as "
        "late; one caught up then cut by Stop counts under cut, not caught up",
        [
            _played(0),
            _compressed(1, 143.25),
            _slowed(2),
            _compressed(3, 66.75),
            _rejected(4, "late", lag_ms=1320.5),
            _rejected(5, "late", lag_ms=1102.25),
            _compressed(6, 88.5),
            _cancelled(6, started=True),
            _rejected(7, "queue_full"),
        ],
    ),
    "caught-up-over-a-second": (
        "caught up by more than a second in all, said in seconds; a copy of a caught-up stroke "
        "counts it once, a compressed_ms of 0 is no catching up",
        [
            _compressed(0, 612.25),
            _compressed(1, 622.5),
            _rejected(1, "duplicate", original_played=True),
            _compressed(2, 0.0),
        ],
    ),
    "caught-up-unfelt": (
        "changes below 5 % of the duration a stroke came with are not said: 20 ms shorter of "
        "437.5 ms (jitter), slowed from 72.5 to 73.7 ms; 22 ms shorter of 439.5 ms is said",
        [
            _compressed(0, 20.0),
            {**_slowed(1), "requested_duration_ms": 72.5},
            _compressed(2, 22.0),
        ],
    ),
    "chip-lost": (
        "a chip lost while a stroke played cuts it; one cut before its first command is refused",
        [
            _played(0),
            {**EVENTS["safety-duty-cycle"][1], "reason": "chip_lost", "seq": 0},
            {**EVENTS["safety-duty-cycle"][1], "reason": "chip_lost", "seq": 1},
        ],
    ),
}


def _typed(value: Any) -> dict[str, Any]:
    return dataclasses.asdict(value)


def typed_status(status: Status) -> dict[str, Any]:
    """A status's fields; ``floor``, added after the others, only when the status has one (the
    vectors of statuses without it were written before it)."""
    typed = _typed(status)
    if typed["floor"] is None:
        del typed["floor"]
    if typed["hardware"] is None:  # a later field still: only where a status has it
        del typed["hardware"]
    if typed["controls"] is None:  # the wearer's, later again
        del typed["controls"]
    return typed


def typed_event(event: Event) -> dict[str, Any]:
    """An event's fields; a cancel's ``by``, added after the others, only when it is set."""
    typed = {"type": event.kind, **event.typed()}
    if event.kind == "cancelled" and typed["by"] is None:
        del typed["by"]
    return typed


def cases() -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name, (description, wire) in EVENTS.items():
        event = event_from_json(wire)
        assert event.kind == wire["type"], name
        typed = typed_event(event)
        out[f"event/{name}.json"] = {
            "description": description,
            "wire": wire,
            "typed": typed,
            "json": event.to_json(),
        }
    for name, (description, wire) in STATUSES.items():
        status = Status.from_json(wire)
        out[f"status/{name}.json"] = {
            "description": description,
            "wire": wire,
            "typed": typed_status(status),
            "json": status.to_json(),
        }
    for name, (description, wire) in DELAYS.items():
        played = event_from_json(wire)
        assert isinstance(played, Played), name
        out[f"delay/{name}.json"] = {
            "description": description,
            "wire": wire,
            "delayed_ms": DELAYED_MS,
            "delay_ms": delivery_delay_ms(played),
            "delayed": is_delayed(played),
        }
    for name, (description, wires) in FATES.items():
        fates = DrawingFates()
        for wire in wires:
            fates.add(event_from_json(wire))
        out[f"fates/{name}.json"] = {
            "description": description,
            "wire": wires,
            "fates": {str(seq): fate for seq, fate in fates.fates().items()},
            "counts": fates.counts(),
            "refusals": dict(fates.refusals()),
            "notable_change": NOTABLE_CHANGE,
            "catch_up": dataclasses.asdict(fates.catch_up()),
            "catch_up_words": fates.catch_up().played_words(),
        }
    for name, (kind, description, wire) in INVALID.items():
        try:
            if kind == "event":
                event_from_json(wire)
            else:
                Status.from_json(wire)
        except EventError as error:
            out[f"invalid/{name}.json"] = {
                "description": description,
                "kind": kind,
                "wire": wire,
                "field": error.field,
                "message": str(error),
            }
        else:
            raise AssertionError(f"{name}: the reference accepts it")
    return out
