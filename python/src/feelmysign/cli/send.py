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
broker has acknowledged every one (exit 0), or says why not (exit 1). When the
sleeve's retained status advertises a floor, one line on stderr says how many
strokes are below it (they are sent as given).
"""

from __future__ import annotations

import argparse
import functools
import math
import sys
import uuid
from collections.abc import Iterator
from dataclasses import replace

from feelmysign.cli.options.broker import (
    add_broker_options,
    add_broker_timeout_option,
    broker_settings_from_args,
)
from feelmysign.cli.options.layout import add_layout_options, layout_from_args
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.cli.options.values import number, stdin_lines, topic
from feelmysign.connection import BrokerSettings, connect_client
from feelmysign.errors import ParameterError, StrokeError
from feelmysign.events import StatusFloor
from feelmysign.layout import MAX_DURATION_MS, MAX_GRID_SIDE, Layout
from feelmysign.protocol import Accepted, parse
from feelmysign.sending import (
    OutgoingStroke,
    Pace,
    StrokeSender,
    printer,
    sleeve_floor_from_status,
)
from feelmysign.shapes import DRAWING_SPEED_CM_S, SHAPE_NAMES, SHAPES, shape_strokes
from feelmysign.stroke import Stroke
from feelmysign.topics import LEGACY_TOPIC

# The faintest intensity sent (the page's MIN_INTENSITY): at 0 the sleeve would play, and report
# as played, a stroke no one feels; so 0 is refused here, with the range to give.
MIN_INTENSITY = 0.01


def _epilog() -> str:
    shapes = "\n".join(
        f"  {s.name:<9} {s.description}; {s.allowed()}, default {s.default_segments}"
        for s in SHAPES.values()
    )
    return (
        "Shapes and their --segments (the number of strokes: the paper's resolution question):\n"
        f"{shapes}\n\n"
        "A stroke may start with '-' (a negative coordinate): feelmysign send -0.5,0,2,0,1000\n"
    )


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "send",
        help="send strokes or a shape to a sleeve over MQTT, acknowledged by the broker",
        description=__doc__,
        epilog=_epilog(),
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
        type=number(0, MAX_DURATION_MS, unit="ms", above_low=True),
        metavar="D",
        help=f"duration of the whole shape in ms, shared by the strokes by length "
        f"(default: drawn at {DRAWING_SPEED_CM_S:g} cm/s)",
    )
    group.add_argument(
        "--margin",
        type=number(0, MAX_GRID_SIDE, unit="grid units"),
        metavar="M",
        help="grid units left free on every side of the shape (default: 0)",
    )


def _add_sending_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("sending")
    group.add_argument(
        "--intensity",
        type=number(MIN_INTENSITY, 1, unit="(at 0 the sleeve would play strokes no one feels)"),
        metavar="A",
        help=f"intensity of every stroke, from {MIN_INTENSITY:g} to 1 (default: the sleeve's "
        "default intensity); 0 is refused: the sleeve would report as played what no one feels",
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
        type=topic,
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
    add_broker_timeout_option(group, help_start="longest wait for the broker to answer, in seconds")
    group.add_argument(
        "--json", action="store_true", help="print one JSON object per message sent, for programs"
    )


def run(args: argparse.Namespace, *, parser: argparse.ArgumentParser) -> int:
    _check_usage(args, parser)
    layout = layout_from_args(args)
    strokes = _strokes(args, layout)  # all checked before connecting: a bad one sends nothing
    settings = broker_settings_from_args(args, "sender")
    topic = args.legacy_topic if args.legacy else settings.strokes_topic
    messages = [OutgoingStroke(i, topic, stroke, args.legacy) for i, stroke in enumerate(strokes)]
    pace: Pace = args.pace or ("realtime" if args.shape else "burst")
    client_id = f"feelmysign-send-{uuid.uuid4().hex[:12]}"
    client = connect_client(settings, client_id, timeout_s=args.timeout_s)
    try:
        _say_floor(sleeve_floor_from_status(client, settings, wait_s=FLOOR_WAIT_S), strokes)
        report = printer(json_lines=args.json, total=len(messages))
        StrokeSender(client, settings, timeout_s=args.timeout_s, on_sent=report).send(
            messages, pace=pace
        )
    finally:
        client.disconnect()
        client.loop_stop()
    if not args.json:
        print(_summary(args, settings, strokes), flush=True)
    return 0


# The retained status comes right after the subscription; on a LAN far within this.
FLOOR_WAIT_S = 1.0


def _say_floor(floor: StatusFloor | None, strokes: list[Stroke]) -> None:
    """One line on stderr (stdout may be JSON for a program): the floor the sleeve advertises and
    how many of the strokes, sent as given (no simplifier here), are below it."""
    if floor is None:
        return
    below = sum(
        1
        for s in strokes
        if s.duration_ms < floor.min_duration_ms or math.dist(s.start, s.end) < floor.min_length
    )
    whose = f" with wearer {floor.wearer}'s limits" if floor.wearer else ""
    verdict = (
        f"{below} of the {len(strokes)} strokes are below it (the sleeve slows a briefer one; "
        "a shorter one may not be felt)"
        if below
        else "every stroke is at or above it"
    )
    print(
        f"The sleeve's floor{whose}: strokes of at least {floor.min_duration_ms:g} ms and "
        f"{floor.min_length:g} grid units; {verdict}.",
        file=sys.stderr,
        flush=True,
    )


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


def _strokes(args: argparse.Namespace, layout: Layout) -> list[Stroke]:
    if args.intensity is not None and not MIN_INTENSITY <= args.intensity <= 1.0:
        raise ParameterError(
            "--intensity",
            args.intensity,
            f"a number from {MIN_INTENSITY:g} to 1 "
            "(at 0 the sleeve would play strokes no one feels)",
        )
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
            raise result.as_error(f"{where} {text!r}", then=" Nothing was sent.")
        strokes.append(replace(result.stroke, intensity=args.intensity, drawing=drawing, seq=seq))
    if not strokes:
        raise StrokeError("empty", "Standard input held no stroke; nothing was sent.")
    return strokes


def _stroke_texts(arguments: list[str]) -> Iterator[tuple[str, str]]:
    """(where, text) of every stroke: 'stroke 2' for an argument, 'line 3 of stdin' for '-'."""
    for position, argument in enumerate(arguments, start=1):
        if argument != "-":
            yield f"Stroke {position}", argument
            continue
        for line_number, line in enumerate(stdin_lines(what="strokes"), start=1):
            if line:
                yield f"Line {line_number} of standard input", line


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
