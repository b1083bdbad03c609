"""``feelmysign replay``: re-run a recording through a simplifier, exactly; send it at its pace.

    feelmysign replay drawing.json                  # the strokes; do they match the recorded ones?
    feelmysign replay drawing.json --algorithm window --max-error 0.05
    feelmysign replay drawing.json --send           # to the local broker's sleeve, as drawn
    feelmysign replay drawing.json --send --speed 4 --broker mqtt://pi.local:1883 --id sleeve2

The simplifier options are those of 'feelmysign simplify' (the recording's own
settings, then the options, over the algorithm's defaults). A recording from
the browser carries the animation frames its simplifier was fed: they are
replayed as they are, so the replay gives exactly the strokes the browser sent
(when --fps is not changed), and when it carries those strokes the replay says
whether it matches them. Otherwise the pointer samples are resampled at --fps.
The same recording and options always give the same strokes.

With --send the strokes go to the sleeve as JSON v1 (one new drawing id, seq
0..n-1), each at the moment the simplifier let it go in the drawing (its
emitted_at_ms from the first frame, divided by --speed; durations unchanged),
and each is acknowledged by the broker before the next (QoS 1). Every stroke
is checked against the sleeve's rules before connecting. The sleeve's retained
status is read first (up to 2.5 s): its floor raises the simplifier's
min_duration_ms and min_length (never lowers them), and a recording with no grid
of its own (nor --rows/--columns) is cut for the sleeve's grid; each said on
stderr, as is a grid that differs from the sleeve's.
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
import uuid
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from feelmysign.cli import simplify
from feelmysign.cli.options.broker import (
    add_broker_options,
    add_broker_timeout_option,
    broker_settings_from_args,
)
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.cli.options.values import number
from feelmysign.connection import BrokerSettings, connect_client
from feelmysign.errors import StrokeError
from feelmysign.layout import PAPER_SLEEVE, grid_layout
from feelmysign.protocol import Rejected, validate_stroke
from feelmysign.sending import (
    STATUS_WAIT_S,
    OutgoingStroke,
    StrokeSender,
    printer,
    sleeve_status,
)
from feelmysign.simplify.recording import Recording
from feelmysign.simplify.registry import DEFAULT_ALGORITHM, Params
from feelmysign.stroke import Stroke

if TYPE_CHECKING:
    import paho.mqtt.client as mqtt

    from feelmysign.events import Status, StatusFloor
    from feelmysign.research.rerun import Rerun

MAX_SPEED = 1000.0  # a minute of drawing in 60 ms: faster is a burst, not a pace
BROKER_DESTS = ("broker", "sleeve_id", "username", "password", "credentials")


def _simplify_options() -> argparse.ArgumentParser:
    """The parser of 'feelmysign simplify', as a parent: its options, defined once, are ours."""
    holder = argparse.ArgumentParser(add_help=False)
    actions = holder.add_subparsers()
    simplify.register(actions)
    parser: argparse.ArgumentParser = actions.choices["simplify"]
    return parser


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "replay",
        help="re-run a recording through a simplifier, exactly, and optionally send it",
        description=__doc__,
        parents=[_simplify_options()],
        conflict_handler="resolve",  # both have -h
    )
    group = parser.add_argument_group("sending")
    group.add_argument(
        "--send",
        action="store_true",
        help="publish the strokes to a sleeve at the pace they were drawn (default: only show)",
    )
    group.add_argument(
        "--speed",
        type=number(0, MAX_SPEED, above_low=True),
        metavar="X",
        help="with --send, send X times faster than drawn (default: 1, as drawn)",
    )
    add_broker_timeout_option(group, help_start="with --send, longest wait for the broker, seconds")
    add_broker_options(parser, role="sender")
    parser.set_defaults(handler=functools.partial(run, parser=parser))


def run(args: argparse.Namespace, *, parser: argparse.ArgumentParser) -> int:
    from feelmysign.research.rerun import mismatch, rerun  # not by 'feelmysign --help'

    _check_usage(args, parser)
    recording = simplify.load(args.recording)
    algorithm = simplify.chosen_algorithm(args, recording)
    # An option of another algorithm, or of the core not run: exit 2.
    params = simplify.checked_params(args, recording, parser)
    client = _connect(args) if args.send else None
    try:
        wearer = None
        if client is not None:
            params, wearer = _respect_status(
                client, broker_settings_from_args(args, "sender"), params, args, recording
            )
        result = rerun(recording, params)
        compared = recording.strokes is not None and algorithm == _recorded_algorithm(recording)
        difference = mismatch(result.segments, recording.strokes or ()) if compared else None
        if client is not None:
            _send(args, client, result, params, wearer)
    finally:
        if client is not None:
            client.disconnect()
            client.loop_stop()
    if args.json:
        print(json.dumps(_document(result, params, compared, difference)))
    else:
        print(simplify.describe(result.segments, params, args.recording))
        verdict = _verdict(recording, algorithm, difference)
        print(f"\nframes: {result.frames_source}; {verdict}")
    return 0


def _check_usage(args: argparse.Namespace, parser: argparse.ArgumentParser) -> None:
    if not args.send:
        given = [d for d in BROKER_DESTS if getattr(args, d) is not None]
        if args.speed is not None:
            given.append("speed")
        if given:
            flags = ", ".join("--" + ("id" if d == "sleeve_id" else d) for d in given)
            verb = "applies" if len(given) == 1 else "apply"
            parser.error(f"{flags} only {verb} with --send")


def _recorded_algorithm(recording: Recording) -> str:
    return str(recording.simplifier.get("algorithm", DEFAULT_ALGORITHM))


def _verdict(recording: Recording, algorithm: str, difference: str | None) -> str:
    if recording.strokes is None:
        return "the recording has no strokes to compare with"
    if algorithm != _recorded_algorithm(recording):
        return (
            f"the recorded strokes came from {_recorded_algorithm(recording)}, "
            f"not {algorithm}: not compared"
        )
    if difference is None:
        return f"matches the {len(recording.strokes)} strokes the recording says were sent"
    return f"DIFFERS from the strokes the recording says were sent: {difference}"


def _document(
    result: Rerun, params: Params, compared: bool, difference: str | None
) -> dict[str, Any]:
    document = simplify.to_json(result.segments, params)
    document["frames"] = result.frames_source
    document["matches_recording"] = difference is None if compared else None
    document["difference"] = difference
    return document


def strokes_to_send(
    result: Rerun, params: Params, wearer: str | None = None
) -> tuple[list[Stroke], list[float]]:
    """The sent segments as strokes of one new drawing, and when to send each (ms from the press).

    Each is checked by the sleeve's own rules first: StrokeError, nothing sent. ``wearer``: whose
    limits (from the sleeve's status) the minimums were raised to, for the message when none is
    left.
    """
    layout = grid_layout(
        params.rows,
        params.columns,
        PAPER_SLEEVE.spacing_cm,
        max_stroke_duration_ms=PAPER_SLEEVE.max_stroke_duration_ms,
    )
    drawing = str(uuid.uuid4())
    origin_ms = next((path[0].t_ms for path in result.frames if path), 0.0)
    strokes, at_ms = [], []
    sent = [item.segment for item in result.segments if item.segment.dropped is None]
    for seq, segment in enumerate(sent):
        stroke = Stroke(segment.start, segment.end, segment.duration_ms, drawing=drawing, seq=seq)
        checked = validate_stroke(stroke, layout)
        if isinstance(checked, Rejected):
            raise checked.as_error(f"Stroke {seq + 1} of the replay", then=" Nothing was sent.")
        strokes.append(checked)
        at_ms.append(segment.emitted_at_ms - origin_ms)
    if not strokes:
        dropped = (
            f"The replay gave no stroke to send ({len(result.segments)} segment(s), all "
            "dropped as too short or too brief)"
        )
        if wearer is not None:  # lower options would be raised to the wearer's limits again
            raise StrokeError(
                "empty",
                f"{dropped}: wearer {wearer}'s limits (at least {params.min_duration_ms:g} ms "
                f"and {params.min_length:g} grid units a stroke) leave nothing of this drawing; "
                "draw it larger or slower.",
            )
        raise StrokeError("empty", f"{dropped}; try a lower --min-length or --min-duration-ms.")
    return strokes, at_ms


def _connect(args: argparse.Namespace) -> mqtt.Client:
    settings: BrokerSettings = broker_settings_from_args(args, "sender")
    return connect_client(
        settings, f"feelmysign-replay-{uuid.uuid4().hex[:12]}", timeout_s=args.timeout_s
    )


def _respect_status(
    client: mqtt.Client,
    settings: BrokerSettings,
    params: Params,
    args: argparse.Namespace,
    recording: Recording,
) -> tuple[Params, str | None]:
    """What the sleeve's retained status asks of the strokes: its grid (``_sleeves_grid``) and
    its floor (``_respect_floor``); whose limits are in that floor, if any."""
    status = sleeve_status(client, settings)
    params = _sleeves_grid(status, settings, params, args, recording)
    return _respect_floor(None if status is None else status.floor, params)


def _sleeves_grid(
    status: Status | None,
    settings: BrokerSettings,
    params: Params,
    args: argparse.Namespace,
    recording: Recording,
) -> Params:
    """The strokes cut for the grid the sleeve advertises, said on stderr, where neither the
    recording nor --rows/--columns gives one; where they do and it differs, said so (the
    sleeve refuses a stroke off its grid as ``outside_grid``)."""
    grid = None if status is None else status.layout
    sid = settings.sleeve_id
    if grid is None:
        print(
            f"No status from sleeve {sid!r} at {settings.url} within {STATUS_WAIT_S:g} s (it has "
            "never connected to this broker, or is an older sleeve): the strokes are cut for a "
            f"{params.rows} x {params.columns} grid; give --rows/--columns for another.",
            file=sys.stderr,
            flush=True,
        )
        return params
    if (grid.rows, grid.columns) == (params.rows, params.columns):
        return params
    chosen = getattr(args, "rows", None) is not None or getattr(args, "columns", None) is not None
    if not chosen and recording.rows is None and recording.columns is None:
        print(
            f"Cut for the {grid.rows} x {grid.columns} grid of sleeve {sid!r} (its status).",
            file=sys.stderr,
            flush=True,
        )
        return replace(params, rows=grid.rows, columns=grid.columns)
    source = "--rows/--columns" if chosen else "the recording"
    print(
        f"Cut for a {params.rows} x {params.columns} grid ({source}), but sleeve {sid!r} is "
        f"{grid.rows} x {grid.columns} (its status): the drawing is felt at another size, and "
        f"a stroke off its grid is refused; give --rows {grid.rows} --columns {grid.columns} to "
        "cut it for the sleeve.",
        file=sys.stderr,
        flush=True,
    )
    return params


def _respect_floor(floor: StatusFloor | None, params: Params) -> tuple[Params, str | None]:
    """The simplifier's minimums raised to the floor the sleeve advertises (never lowered), said
    on stderr (stdout may be JSON for a program); and whose limits are in that floor, if any."""
    from feelmysign.simplify.window import WindowParams
    from feelmysign.wearer import respect_floor  # the planner's constants: not by --help

    min_duration_ms, min_length, note = respect_floor(
        params.min_duration_ms, params.min_length, floor
    )
    if note is not None:
        print(note, file=sys.stderr, flush=True)
    params = replace(params, min_duration_ms=min_duration_ms, min_length=min_length)
    if floor is not None and isinstance(params, WindowParams):
        # The window simplifier merges what is briefer than the sleeve's floor into a neighbour,
        # so the motors' floor is kept to as well; a wearer's limits are never gone below.
        params = replace(
            params, floor_ms=floor.min_duration_ms, strict_minimums=floor.wearer is not None
        )
    return params, None if floor is None else floor.wearer


def _send(
    args: argparse.Namespace,
    client: mqtt.Client,
    result: Rerun,
    params: Params,
    wearer: str | None,
) -> None:
    strokes, at_ms = strokes_to_send(result, params, wearer)
    settings: BrokerSettings = broker_settings_from_args(args, "sender")
    speed = args.speed or 1.0
    messages = [
        OutgoingStroke(i, settings.strokes_topic, stroke, legacy=False)
        for i, stroke in enumerate(strokes)
    ]
    # The same publish, acknowledgement wait and report as 'send'.
    report = printer(json_lines=args.json, total=len(messages))
    sender = StrokeSender(client, settings, timeout_s=args.timeout_s, on_sent=report)
    sender.send_at(messages, [offset_ms / speed for offset_ms in at_ms])
