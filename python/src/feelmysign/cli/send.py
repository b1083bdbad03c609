"""``feelmysign send``: send strokes or a shape to a sleeve, and wait until the broker has them.

    feelmysign send 0,0,3,2,1500 3,2,0,2,800          # two strokes of one drawing
    feelmysign send --shape circle --segments 8        # the paper's study: a circle of 8 strokes
    feelmysign send --shape heart --legacy             # what the paper's Processing sender sends
    cat strokes.txt | feelmysign send -                # one stroke per line

Every stroke is checked with the sleeve's own validation before anything is
sent (a bad one: nothing is sent, exit 1). JSON v1 goes to
``feelmysign/<id>/strokes`` with one fresh drawing id, ``seq`` 0..n-1 and
``sent_at_ms``; ``--legacy`` sends the original text format to the legacy
topic. Each message is published with QoS 1, and the command returns once the
broker has acknowledged every one (exit 0), or says why not (exit 1).
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import sys
import threading
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any, Literal

import paho.mqtt.client as mqtt
from paho.mqtt.reasoncodes import ReasonCode

from feelmysign._mosquitto_config import LEGACY_TOPIC
from feelmysign.cli._broker_options import (
    DEFAULT_TIMEOUT_S,
    BrokerConnectionError,
    BrokerSettings,
    add_broker_options,
    broker_settings_from_args,
    connect_client,
)
from feelmysign.cli._options import add_layout_options, layout_from_args
from feelmysign.errors import ParameterError, StrokeError
from feelmysign.layout import Layout
from feelmysign.protocol import Accepted, format_json, format_legacy, parse
from feelmysign.shapes import DRAWING_SPEED_CM_S, SHAPE_NAMES, SHAPES, shape_strokes
from feelmysign.stroke import Stroke

Pace = Literal["realtime", "burst"]


def _epilog() -> str:
    shapes = "\n".join(
        f"  {s.name:<9} {s.description}; {s.allowed()}, default {s.default_segments}"
        for s in SHAPES.values()
    )
    return (
        "Shapes and their --segments (the number of strokes: the paper's resolution question):\n"
        f"{shapes}\n\n"
        "A stroke that starts with '-' (a negative coordinate) must follow '--':\n"
        "  feelmysign send -- -0.5,0,2,0,1000\n"
    )


@dataclass(frozen=True)
class _Message:
    index: int
    topic: str
    stroke: Stroke
    legacy: bool

    def payload(self) -> str:
        if self.legacy:
            return format_legacy(self.stroke)
        # The wall clock at the moment of sending: the sleeve measures latency from it.
        return format_json(replace(self.stroke, sent_at_ms=round(time.time() * 1000)))


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "send",
        help="send strokes or a shape to a sleeve over MQTT, acknowledged by the broker",
        description=__doc__,
        epilog=_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "strokes",
        nargs="*",
        metavar="STROKE",
        help="a stroke startX,startY,endX,endY,duration (grid units, ms); '-' reads one per "
        "line from standard input",
    )
    _add_shape_options(parser)
    _add_sending_options(parser)
    add_broker_options(parser, role="sender")
    add_layout_options(parser)
    parser.set_defaults(handler=functools.partial(run, parser=parser))


def _add_shape_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("shape (instead of STROKE)")
    group.add_argument(
        "--shape", choices=SHAPE_NAMES, help="send this shape, sized to fill the sleeve's grid"
    )
    group.add_argument(
        "--segments",
        type=int,
        metavar="N",
        help="number of strokes of the shape (default and range per shape: see below)",
    )
    group.add_argument(
        "--duration-ms",
        type=float,
        metavar="D",
        help=f"duration of the whole shape in ms, shared by the strokes by length "
        f"(default: drawn at {DRAWING_SPEED_CM_S:g} cm/s)",
    )
    group.add_argument(
        "--margin",
        type=float,
        metavar="M",
        help="grid units left free on every side of the shape (default: 0)",
    )


def _add_sending_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("sending")
    group.add_argument(
        "--intensity",
        type=float,
        metavar="A",
        help="intensity of every stroke in [0, 1] (default: the sleeve's default intensity)",
    )
    group.add_argument(
        "--legacy",
        action="store_true",
        help="send the legacy text startX,startY,endX,endY,duration to --legacy-topic "
        "(default: JSON v1 to feelmysign/<id>/strokes)",
    )
    group.add_argument(
        "--legacy-topic",
        default=LEGACY_TOPIC,
        metavar="TOPIC",
        help=f"topic of --legacy (default: {LEGACY_TOPIC}, the original sleeve's)",
    )
    group.add_argument(
        "--pace",
        choices=("realtime", "burst"),
        help="realtime: send each stroke when the previous one would have finished playing, "
        "like a person drawing; burst: all at once (default: realtime for --shape, burst for "
        "STROKEs)",
    )
    group.add_argument(
        "--timeout-s",
        type=float,
        default=DEFAULT_TIMEOUT_S,
        metavar="S",
        help=f"longest wait for the broker to answer, in seconds (default: {DEFAULT_TIMEOUT_S:g})",
    )
    group.add_argument(
        "--json", action="store_true", help="print one JSON object per message sent, for programs"
    )


def run(args: argparse.Namespace, *, parser: argparse.ArgumentParser) -> int:
    _check_usage(args, parser)
    layout = layout_from_args(args)
    strokes = _strokes(args, layout)  # all checked before connecting: a bad one sends nothing
    settings = broker_settings_from_args(args, "sender")
    topic = args.legacy_topic if args.legacy else settings.strokes_topic
    messages = [_Message(i, topic, stroke, args.legacy) for i, stroke in enumerate(strokes)]
    pace: Pace = args.pace or ("realtime" if args.shape else "burst")
    client_id = f"feelmysign-send-{uuid.uuid4().hex[:12]}"
    client = connect_client(settings, client_id, timeout_s=args.timeout_s)
    try:
        _Sender(client, settings, timeout_s=args.timeout_s, json_lines=args.json).send(
            messages, pace=pace
        )
    finally:
        client.disconnect()
        client.loop_stop()
    if not args.json:
        print(_summary(args, settings, strokes), flush=True)
    return 0


def _check_usage(args: argparse.Namespace, parser: argparse.ArgumentParser) -> None:
    """Usage errors (exit 2): what cannot be combined, and what is missing."""
    if args.shape and args.strokes:
        parser.error("give either STROKEs or --shape, not both")
    if not args.shape and not args.strokes:
        parser.error("give STROKEs (e.g. 0,0,3,2,1500), '-' to read them, or --shape NAME")
    if not args.shape:
        shape_only = (
            ("--segments", args.segments),
            ("--duration-ms", args.duration_ms),
            ("--margin", args.margin),
        )
        given = [option for option, value in shape_only if value is not None]
        if given:
            parser.error(f"{' and '.join(given)} only apply to --shape (a STROKE has its duration)")
    if args.legacy and args.intensity is not None:
        parser.error("--intensity cannot be sent with --legacy: the legacy format has no intensity")
    if not (math.isfinite(args.timeout_s) and args.timeout_s > 0):
        parser.error(f"--timeout-s must be a number of seconds above 0, not {args.timeout_s:g}")


def _strokes(args: argparse.Namespace, layout: Layout) -> list[Stroke]:
    if args.intensity is not None and not 0.0 <= args.intensity <= 1.0:
        raise ParameterError("--intensity", args.intensity, "a number in [0, 1]")
    if args.shape:
        return shape_strokes(
            args.shape,
            layout=layout,
            segments=args.segments,
            duration_ms=args.duration_ms,
            intensity=args.intensity,
            margin=args.margin or 0.0,
        )
    drawing = str(uuid.uuid4())
    strokes = []
    for seq, (where, text) in enumerate(_stroke_texts(args.strokes)):
        result = parse(text, layout, format="legacy")
        if not isinstance(result, Accepted):
            raise StrokeError(
                result.reason,
                f"{where} {text!r} would be rejected by the sleeve ({result.reason}): "
                f"{result.message} Nothing was sent.",
            )
        strokes.append(replace(result.stroke, intensity=args.intensity, drawing=drawing, seq=seq))
    if not strokes:
        raise StrokeError("empty", "Standard input held no stroke; nothing was sent.")
    return strokes


def _stroke_texts(arguments: list[str]) -> Iterator[tuple[str, str]]:
    """(where, text) of every stroke: 'stroke 2' for an argument, 'line 3 of stdin' for '-'."""
    for number, argument in enumerate(arguments, start=1):
        if argument != "-":
            yield f"Stroke {number}", argument
            continue
        for line_number, line in enumerate(sys.stdin, start=1):
            if line.strip():
                yield f"Line {line_number} of standard input", line.strip()


def _summary(args: argparse.Namespace, settings: BrokerSettings, strokes: list[Stroke]) -> str:
    what = (
        f"a {args.shape} of {len(strokes)} strokes" if args.shape else f"{len(strokes)} stroke(s)"
    )
    total_ms = sum(s.duration_ms for s in strokes)
    where = (
        f"the legacy topic {args.legacy_topic}"
        if args.legacy
        else f"sleeve {settings.sleeve_id!r} (drawing {strokes[0].drawing})"
    )
    return (
        f"Sent {what}, {total_ms / 1000:.2f} s of drawing, to {where} via {settings.url}; "
        f"the broker acknowledged every one."
    )


class _Acks:
    """PUBACKs by message id, from paho's thread; waiting ends early if the connection drops.

    An acknowledgement may arrive before ``publish`` has returned its id, hence a dict.
    """

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._codes: dict[int, ReasonCode] = {}
        self._lost: str | None = None

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

    def wait(self, mid: int, timeout_s: float) -> ReasonCode | str:
        """The PUBACK's reason code, or why none will come ('timeout' or the disconnect)."""
        with self._condition:
            arrived = self._condition.wait_for(
                lambda: mid in self._codes or self._lost is not None, max(timeout_s, 0.0)
            )
            if mid in self._codes:
                return self._codes.pop(mid)
            return self._lost if arrived and self._lost is not None else "timeout"


class _Sender:
    """Publishes messages at their pace and reports each once the broker acknowledged it."""

    def __init__(
        self, client: mqtt.Client, settings: BrokerSettings, *, timeout_s: float, json_lines: bool
    ) -> None:
        self._client = client
        self._settings = settings
        self._timeout_s = timeout_s
        self._json_lines = json_lines
        self._acks = _Acks()
        client.on_publish = self._acks.on_publish
        client.on_disconnect = self._acks.on_disconnect

    def send(self, messages: list[_Message], *, pace: Pace) -> None:
        if pace == "burst":
            sent = [(message, *self._publish(message)) for message in messages]
            deadline_s = time.monotonic() + self._timeout_s
            for message, payload, mid in sent:
                self._confirm(message, payload, mid, deadline_s, len(messages))
            return
        start_s = time.monotonic()
        offset_ms = 0.0
        for message in messages:
            # Drawing time, not a wait for an event: the pace is the point.
            time.sleep(max(0.0, start_s + offset_ms / 1000 - time.monotonic()))
            payload, mid = self._publish(message)
            self._confirm(message, payload, mid, time.monotonic() + self._timeout_s, len(messages))
            offset_ms += message.stroke.duration_ms

    def _publish(self, message: _Message) -> tuple[str, int]:
        payload = message.payload()
        info = self._client.publish(message.topic, payload, qos=1)
        if info.rc != mqtt.MQTT_ERR_SUCCESS:
            raise BrokerConnectionError(
                "closed",
                f"Lost the connection to {self._settings.url} before stroke {message.index + 1} "
                f"could be sent ({mqtt.error_string(info.rc)}); send the drawing again.",
                url=self._settings.url,
            )
        return payload, info.mid

    def _confirm(
        self, message: _Message, payload: str, mid: int, deadline_s: float, total: int
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
        if isinstance(answer, str):
            raise BrokerConnectionError(
                "closed",
                f"{url} closed the connection ({answer}) before acknowledging {number}; "
                "check the broker's log, then send the drawing again.",
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
        self._report(message, payload, total)

    def _report(self, message: _Message, payload: str, total: int) -> None:
        if self._json_lines:
            line = json.dumps({"index": message.index, "topic": message.topic, "payload": payload})
        else:
            width = len(str(total))
            line = f"[{message.index + 1:>{width}}/{total}] {message.topic} {payload}"
        print(line, flush=True)
