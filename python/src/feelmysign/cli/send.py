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

The wearer's choice wins over the sender's. When the sleeve's status says the
wearer paused it, or asked not to be disturbed, one line on stderr says so and
until when, nothing is sent, and the exit code is 3: wait for the wearer to
resume, then send again. With --wait, strokes the sleeve refused because the
wearer paused during the drawing (or cut by the wearer's pause) are named, and
the exit code is 3 too. A ceiling the wearer set is said in one line: it caps
every stroke's intensity.

Exit codes: 0 sent (and with --wait, every stroke played); 1 an error, or with
--wait a stroke refused, cut or unanswered; 2 a usage error; 3 the wearer
paused the sleeve or asked not to be disturbed (nothing sent, or with --wait
strokes refused or cut for it).
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
from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from feelmysign.cli.options.broker import (
    add_broker_options,
    add_broker_timeout_option,
    broker_settings_from_args,
)
from feelmysign.cli.options.layout import add_layout_options, layout_from_args, layout_given
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.cli.options.values import number, stdin_lines, topic
from feelmysign.connection import BrokerSettings, connect_client
from feelmysign.errors import BrokerConnectionError, LayoutError, ParameterError, StrokeError
from feelmysign.events import (
    Event,
    EventError,
    Status,
    StatusControls,
    StatusFloor,
    delivery_delay_ms,
    is_delayed,
)
from feelmysign.fates import caught_up_ms, waited_ms
from feelmysign.input_files import loads_json
from feelmysign.layout import MAX_DURATION_MS, MAX_GRID_SIDE, PAPER_SLEEVE, Layout, check_layout
from feelmysign.outcome import DrawingOutcome, StrokeOutcome
from feelmysign.plural import plural
from feelmysign.protocol import DURATION_NOT_POSITIVE, LATE, Accepted, parse
from feelmysign.sending import (
    STATUS_WAIT_S,
    OutgoingStroke,
    Pace,
    StrokeSender,
    printer,
    sleeve_status_and_payload,
)
from feelmysign.shapes import DRAWING_SPEED_CM_S, SHAPE_NAMES, SHAPES, shape_strokes
from feelmysign.stroke import Stroke
from feelmysign.topics import LEGACY_TOPIC, strokes_topic, telemetry_topic
from feelmysign.wearer_status import (
    WEARER_REASONS,
    ceiling_sentence,
    hold_sentence,
    wearer_hold,
)

if TYPE_CHECKING:
    import paho.mqtt.client as mqtt

# The faintest intensity sent (the page's MIN_INTENSITY): at 0 the sleeve would play, and report
# as played, a stroke no one feels; so 0 is refused here, with the range to give.
MIN_INTENSITY = 0.01
# The exit code when the wearer's choice (paused, do not disturb) kept the drawing from the skin:
# apart from 1 (an error to fix), since what to do is wait, not change the command.
WEARER_HOLD_EXIT = 3


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
        help="realtime (the default): send each stroke when the previous one would have "
        "finished playing, like a person drawing; burst: all at once, so the sleeve, catching "
        "up with a drawing that arrived ahead of it, plays every stroke after the first faster, "
        "down to its floor (docs/protocol.md, Catching up)",
    )
    group.add_argument(
        "--wait",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="wait for the sleeve's events for the strokes sent, print what it played or "
        "refused, and exit 1 when any stroke was refused, cut or not answered within "
        "--timeout-s after the drawing (3 when the wearer paused the sleeve or asked not to "
        "be disturbed); returns once the last stroke has been felt (default: "
        "--wait for --shape, --no-wait for STROKEs; not with --legacy)",
    )
    add_broker_timeout_option(
        group,
        help_start="longest wait for the broker to answer, and with --wait for the sleeve's "
        "answers after the drawing's own time, in seconds",
    )
    group.add_argument(
        "--json", action="store_true", help="print one JSON object per message sent, for programs"
    )


def run(args: argparse.Namespace, *, parser: argparse.ArgumentParser) -> int:
    _check_usage(args, parser)
    wait = _wait_asked(args, parser)
    # A layout asked for is checked, and the strokes with it, before connecting: a bad one
    # sends nothing. Without one, the sleeve's retained status gives it, once connected.
    layout = layout_from_args(args) if layout_given(args) else None
    texts = [] if args.shape else list(_stroke_texts(args.strokes))
    # Without a layout, their form is checked now against any grid, their place once the
    # sleeve's grid is known.
    strokes = _strokes(args, layout or ANY_GRID, texts)
    settings = broker_settings_from_args(args, "sender")
    client_id = f"feelmysign-send-{uuid.uuid4().hex[:12]}"
    client = connect_client(settings, client_id, timeout_s=args.timeout_s)
    try:
        status, payload = sleeve_status_and_payload(client, settings, wait_s=STATUS_WAIT_S)
        if layout is None:
            layout = _layout_of_sleeve(status, settings)
            strokes = _strokes(args, layout, texts)
        else:
            _say_other_grid(status, settings, layout)
        _say_offline(status, settings, wait=wait)
        controls = _wearer_controls(status, payload)
        hold = wearer_hold(controls)
        if hold is not None:
            print(f"Error: {hold_sentence(hold, settings.sleeve_id)}", file=sys.stderr, flush=True)
            return WEARER_HOLD_EXIT
        _say_ceiling(controls, strokes, layout)
        _say_floor(None if status is None else status.floor, strokes)
        topic = args.legacy_topic if args.legacy else settings.strokes_topic
        messages = [OutgoingStroke(i, topic, s, args.legacy) for i, s in enumerate(strokes)]
        lines = _InOrder()
        outcome = _watch_events(client, settings, strokes, args, lines) if wait else None
        sent, cut_off = _send(client, settings, messages, args, outcome, lines)
        lines.flush()
        if outcome is not None and sent < len(messages):
            outcome.hold(range(sent, len(messages)))
        if not args.json:
            stopped = outcome is not None and outcome.stopped() and not outcome.held_by_wearer()
            print(_summary(args, settings, strokes, sent, stopped=stopped), flush=True)
        if outcome is None:
            return 0
        online = status is not None and status.online
        return _await_sleeve(outcome, settings, args, strokes, online=online, cut_off=cut_off)
    finally:
        client.disconnect()
        client.loop_stop()


def _send(
    client: mqtt.Client,
    settings: BrokerSettings,
    messages: list[OutgoingStroke],
    args: argparse.Namespace,
    outcome: DrawingOutcome | None,
    lines: _InOrder,
) -> tuple[int, Callable[[], str | None]]:
    """Publishes the strokes; how many went out, and a call saying why the broker cut this
    sender off since (its login refused on reconnecting: blocked), or None. Waiting for the
    sleeve's answers, it stops once the sleeve refuses one as its wearer paused it (the rest
    would be refused too), or once the drawing is cancelled (``feelmysign stop``, or the
    wearer's stop): it is over."""
    pace: Pace = args.pace or "realtime"
    say = printer(json_lines=args.json, total=len(messages))

    def report(message: OutgoingStroke, payload: str) -> None:
        lines.sent(message.index, lambda: say(message, payload))

    sender = StrokeSender(client, settings, timeout_s=args.timeout_s, on_sent=report)
    if outcome is None:
        return sender.send(messages, pace=pace), sender.login_refused
    sent = sender.send(
        messages, pace=pace, until=lambda: outcome.held_by_wearer() or outcome.stopped()
    )
    return sent, sender.login_refused


def _wait_asked(args: argparse.Namespace, parser: argparse.ArgumentParser) -> bool:
    if args.wait and args.legacy:
        parser.error(
            "--wait cannot be used with --legacy: a legacy stroke has no drawing id, so the "
            "sleeve's events cannot be matched to it"
        )
    if args.wait is None:
        return bool(args.shape) and not args.legacy
    return bool(args.wait)


def _layout_of_sleeve(status: Status | None, settings: BrokerSettings) -> Layout:
    """The grid and limits the sleeve's status advertises; the paper's sleeve, said on stderr,
    when the broker holds no status of it."""
    if status is None or status.layout is None:
        print(
            f"No status from sleeve {settings.sleeve_id!r} at {settings.url} within "
            f"{STATUS_WAIT_S:g} s (it has never connected to this broker, or is an older "
            f"sleeve): strokes are checked against the paper's sleeve "
            f"({PAPER_SLEEVE.rows} rows x {PAPER_SLEEVE.columns} columns). Give --layout FILE "
            "or --rows/--columns for another grid.",
            file=sys.stderr,
            flush=True,
        )
        return PAPER_SLEEVE
    advertised = status.layout
    # Checked below by the layout rules (an actuator type from the wire is a plain string).
    known: dict[str, Any] = {
        name: value
        for name, value in (
            ("spacing_cm", advertised.spacing_cm),
            ("default_intensity", advertised.default_intensity),
            ("max_intensity", advertised.max_intensity),
            ("max_stroke_duration_ms", advertised.max_stroke_duration_ms),
            ("actuator_type", advertised.actuator_type),
        )
        if value is not None
    }
    name = advertised.name or settings.sleeve_id
    try:
        grid = replace(
            PAPER_SLEEVE, name=name, rows=advertised.rows, columns=advertised.columns, **known
        )
        return check_layout(grid, f"the status of sleeve {settings.sleeve_id!r}")
    except LayoutError as error:
        raise LayoutError(
            error.source, [*error.problems, "give --layout FILE with the sleeve's layout"]
        ) from None


def _say_other_grid(status: Status | None, settings: BrokerSettings, layout: Layout) -> None:
    """A grid given (--layout, --rows/--columns) that is not the one the sleeve advertises:
    said, since the sleeve refuses a stroke off its own grid (``outside_grid``)."""
    grid = None if status is None else status.layout
    if grid is None or (grid.rows, grid.columns) == (layout.rows, layout.columns):
        return
    print(
        f"The strokes are checked against a {layout.rows} x {layout.columns} grid (--layout, "
        f"--rows/--columns), but sleeve {settings.sleeve_id!r} is {grid.rows} x {grid.columns} "
        "(its status): it refuses a stroke off its own grid. Leave the grid options out to use "
        "the sleeve's.",
        file=sys.stderr,
        flush=True,
    )


def _say_offline(status: Status | None, settings: BrokerSettings, *, wait: bool) -> None:
    if status is None or status.online:
        return
    then = (
        f"the strokes wait at the broker until it returns; this command waits for its answer "
        f"at most --timeout-s {'after the drawing' if wait else ''}".rstrip()
        if wait
        else "the strokes wait at the broker until it returns (and may be stale by then)"
    )
    print(
        f"Sleeve {settings.sleeve_id!r} is offline (its last status): {then}.",
        file=sys.stderr,
        flush=True,
    )


def _wearer_controls(status: Status | None, payload: bytes | None) -> StatusControls | None:
    """The wearer's choice in the sleeve's status; none for no status or an offline one (the
    last will carries none). Controls not understood are said, and the sleeve still enforces
    them: its refusals then say what holds it."""
    if status is None or payload is None or not status.online:
        return None
    if status.controls is not None:
        return status.controls
    try:
        controls = loads_json(payload).get("controls")
        if controls is not None:
            StatusControls.from_json(controls)
    except (ValueError, AttributeError) as error:
        field = getattr(error, "field", None)
        print(
            "The sleeve's status has wearer controls this command does not understand "
            f"({f'controls.{field}: ' if field else ''}{error}); "
            "sending anyway: the sleeve refuses strokes if its wearer paused it.",
            file=sys.stderr,
            flush=True,
        )
    return None


def _say_ceiling(controls: StatusControls | None, strokes: list[Stroke], layout: Layout) -> None:
    """One line on stderr: the wearer's ceiling caps every stroke's intensity."""
    if controls is None or controls.ceiling is None:
        return
    asked = [layout.default_intensity if s.intensity is None else s.intensity for s in strokes]
    print(ceiling_sentence(controls.ceiling, asked), file=sys.stderr, flush=True)


def _watch_events(
    client: mqtt.Client,
    settings: BrokerSettings,
    strokes: list[Stroke],
    args: argparse.Namespace,
    lines: _InOrder,
) -> DrawingOutcome:
    """Subscribed to the sleeve's events before the first stroke goes out, so no answer is
    missed; each answer printed as it comes."""
    total = len(strokes)

    def tell(seq: int, stroke: StrokeOutcome, event: Event) -> None:
        line = _answer_line(seq, total, stroke, event, json_lines=args.json)
        lines.answer(seq, lambda: print(line, flush=True))

    outcome = DrawingOutcome(strokes[0].drawing or "", total, tell)
    topic = telemetry_topic(settings.sleeve_id, "events")
    client.message_callback_add(topic, outcome.on_message)
    # The sleeve's status too: offline (its will, when its process dies) while a stroke plays.
    status_topic = telemetry_topic(settings.sleeve_id, "status")
    client.message_callback_add(status_topic, lambda *m: _on_status(outcome, m[2]))
    subscribed = threading.Event()
    client.on_subscribe = lambda *_: subscribed.set()
    # Subscribed again on a reconnection: a clean session forgets subscriptions.
    client.on_connect = lambda c, *_: c.subscribe([(topic, 1), (status_topic, 1)])
    client.subscribe([(topic, 1), (status_topic, 1)])
    if not subscribed.wait(args.timeout_s):
        raise BrokerConnectionError(
            "timeout",
            f"{settings.url} did not confirm the subscription to {topic} within "
            f"{args.timeout_s:g} s; nothing was sent. Try again, or use --no-wait.",
            url=settings.url,
        )
    return outcome


def _on_status(outcome: DrawingOutcome, message: mqtt.MQTTMessage) -> None:
    """A status that says offline: the sleeve's process ended (or it left the broker)."""
    try:
        status = Status.from_json(bytes(message.payload))
    except EventError:
        return  # one this sender cannot read: not a word on whether it is online
    if not status.online:
        outcome.went_offline()


class _InOrder:
    """Each stroke's answer printed after the line that says it was sent: the broker's
    acknowledgement and the sleeve's answer reach this process on different threads, and a
    sleeve quick to answer would otherwise be heard before its stroke is said sent."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._sent: set[int] = set()
        self._waiting: dict[int, list[Callable[[], None]]] = {}

    def sent(self, index: int, say: Callable[[], None]) -> None:
        with self._lock:
            say()
            self._sent.add(index)
            for answer in self._waiting.pop(index, []):
                answer()

    def answer(self, index: int, say: Callable[[], None]) -> None:
        with self._lock:
            if index in self._sent:
                say()
            else:
                self._waiting.setdefault(index, []).append(say)

    def flush(self) -> None:
        """The answers of strokes never said sent (the sending stopped), in order."""
        with self._lock:
            for index in sorted(self._waiting):
                for answer in self._waiting[index]:
                    answer()
            self._waiting.clear()


# How the sleeve begins the message of a stroke a lost chip cut after it began (player.py).
CUT_PART_WAY = "cut part-way, after its played event: "


def _answer_line(
    seq: int, total: int, stroke: StrokeOutcome, event: Event, *, json_lines: bool
) -> str:
    if json_lines:
        return json.dumps({"index": seq, "event": event.to_json()})
    width = len(str(total))
    where = f"[{seq + 1:>{width}}/{total}]"
    if stroke.cut_reason is not None:
        # The sleeve's own sentence may begin with what the line says ("cut part-way, after
        # its played event: The DRV2605L ..."): said once.
        message = str(getattr(event, "message", "") or "").removeprefix(CUT_PART_WAY)
        return f"{where} cut part-way ({stroke.cut_reason}): {message}".rstrip(": ")
    if stroke.refused_reason == LATE:  # said as the summary, up's line and the page say it
        return f"{where} skipped as late: {stroke.refused_message or ''}".rstrip()
    if stroke.refused_reason is not None:
        return f"{where} refused ({stroke.refused_reason}): {stroke.refused_message or ''}".rstrip()
    played = stroke.played
    assert played is not None
    how = f"{event.kind}" + (
        f" ({getattr(event, 'reason', '')})" if event.kind == "adjusted" else ""
    )
    duration = f"{round(played.duration_ms, 1):g}"
    line = f"{where} {how}: {duration} ms, latency {played.latency_ms:.0f} ms"
    waited = waited_ms(played)
    if waited:  # the wait behind the strokes before it, not the network
        line += f" (of which {waited:.0f} ms waiting for the strokes before it)"
    shorter_ms = caught_up_ms(played)
    if shorter_ms:  # played faster to catch up with the strokes before it
        line += f", {shorter_ms:.0f} ms shorter to catch up"
    if is_delayed(played):  # held on the way: the broker kept it, or the network was slow
        delay_s = (delivery_delay_ms(played) or 0.0) / 1000
        line += f", delayed on the way by {delay_s:.1f} s"
    return line


# Beyond the drawing's own time after the last stroke went out, the longest the sleeve's
# answer may take is --timeout-s; a stroke played is then awaited until it has been felt,
# at most this long (the sleeve's own cap on queued strokes).
MAX_FELT_WAIT_S = 30.0
# While waiting for the answers: how often to look whether the broker cut this sender off.
CUT_OFF_CHECK_S = 0.25


def _await_sleeve(
    outcome: DrawingOutcome,
    settings: BrokerSettings,
    args: argparse.Namespace,
    strokes: list[Stroke],
    *,
    online: bool,
    cut_off: Callable[[], str | None] = lambda: None,
) -> int:
    """``online``: the sleeve's retained status said it was online when the drawing began.
    ``cut_off``: why the broker cut this sender off meanwhile (blocked), or None: then no
    answer can come, and that is said instead of waiting for them."""
    burst = (args.pace or "realtime") == "burst"
    drawing_s = (
        sum(s.duration_ms for s in strokes) / 1000 if burst else strokes[-1].duration_ms / 1000
    )
    answered_by_s = time.monotonic() + drawing_s + args.timeout_s
    while time.monotonic() < answered_by_s and cut_off() is None:
        outcome.wait_answered(min(answered_by_s, time.monotonic() + CUT_OFF_CHECK_S))
        if outcome.summary().unheard == []:
            break
    # Return once the last stroke has been felt, not when it started: a second send right
    # after this one then starts on a sleeve with nothing left of this drawing. A cut-off
    # meanwhile (a block during the last stroke) ends the wait: a cut of it could not reach us.
    felt_by_s = outcome.felt_by_s()
    if felt_by_s is not None:
        until_s = time.monotonic() + min(MAX_FELT_WAIT_S, max(0.0, felt_by_s - time.monotonic()))
        while cut_off() is None and time.monotonic() < until_s:
            time.sleep(min(CUT_OFF_CHECK_S, max(0.0, until_s - time.monotonic())))
    why = cut_off()
    if why is not None:
        print(
            f"Error: {outcome.summary().text()}; no more answers can come. {why}",
            file=sys.stderr,
            flush=True,
        )
        return 1
    summary = outcome.summary()
    line = summary.text()
    if summary.unheard:
        unheard = ", ".join(str(seq + 1) for seq in summary.unheard)
        line += f"; no answer for stroke(s) {unheard} within {args.timeout_s:g} s after the drawing"
        if online and len(summary.unheard) == len(strokes):
            # Online, yet not one answer: most often the broker's access rules, which drop
            # what they refuse without a word (MQTT 3.1.1 has no way to say it).
            sleeve = settings.sleeve_id
            line += (
                f": sleeve {sleeve!r} is online (its status), yet none of its answers reached "
                f"this sender. The broker's access rules (ACL) may keep the sleeve from reading "
                f"{strokes_topic(sleeve)} or writing {telemetry_topic(sleeve, 'events')}, or "
                "this account from reading the events (docs/deploy.md, Topics and ACL); a "
                "sleeve stopped a moment ago may also still show online (--timeout-s waits "
                "longer; --no-wait does not wait)"
            )
        else:
            line += (
                f": is sleeve {settings.sleeve_id!r} running and connected to "
                f"{settings.url}? (--timeout-s waits longer; --no-wait does not wait)"
            )
    if summary.all_played and not summary.unheard:
        if not args.json:
            print(f"{line}.", flush=True)
        return 0
    wearer = _wearer_line(outcome)
    stopped = ""
    if wearer is None and summary.held and outcome.stopped():
        stopped = (
            " The drawing was stopped (feelmysign stop, or a sender's stop): the rest was not sent."
        )
    print(f"Error: {line}.{wearer or stopped}", file=sys.stderr, flush=True)
    return 1 if wearer is None else WEARER_HOLD_EXIT


def _wearer_line(outcome: DrawingOutcome) -> str | None:
    """The strokes the wearer's choice kept from the skin, named, and what to do; None when the
    wearer had no part in it."""
    refused = {
        reason: [i + 1 for i, s in enumerate(outcome.strokes) if s.refused_reason == reason]
        for reason in sorted(WEARER_REASONS)
    }
    cut = [i + 1 for i, s in enumerate(outcome.strokes) if s.by_wearer]
    if not any(refused.values()) and not cut:
        return None
    parts = []
    if refused["paused"]:
        parts.append(
            f"the wearer paused the sleeve: stroke(s) {_numbers(refused['paused'])} refused"
        )
    if refused["do_not_disturb"]:
        parts.append(
            "the wearer asked not to be disturbed: stroke(s) "
            f"{_numbers(refused['do_not_disturb'])} refused"
        )
    if cut:
        parts.append(
            f"the wearer (a pause, stop or block) cut or dropped stroke(s) {_numbers(cut)}"
        )
    held = [i + 1 for i, s in enumerate(outcome.strokes) if s.held]
    if held:
        parts.append(f"stroke(s) {_numbers(held)} not sent, since the sleeve would refuse them")
    text = "; ".join(parts)
    # What to do depends on what the wearer chose: a pause ends with a resume, do not disturb
    # at its time, and a stop (no refusal for a hold) means the wearer did not want it now.
    if refused["paused"] or (held and not refused["do_not_disturb"]):
        advice = "Send again once the wearer has resumed."
    elif refused["do_not_disturb"]:
        advice = "Send again once do not disturb has ended."
    else:
        advice = "The wearer stopped it (or paused the sleeve): send again only when they want it."
    return f" {text[0].upper()}{text[1:]}. {advice}"


def _numbers(numbers: list[int]) -> str:
    """Stroke numbers, a run of three or more as one range: "1, 3, 5 to 24"."""
    runs: list[list[int]] = []
    for n in numbers:
        if runs and n == runs[-1][-1] + 1:
            runs[-1].append(n)
        else:
            runs.append([n])
    return ", ".join(
        f"{run[0]} to {run[-1]}" if len(run) >= 3 else ", ".join(map(str, run)) for run in runs
    )


def _say_floor(floor: StatusFloor | None, strokes: list[Stroke]) -> None:
    """One line on stderr (stdout may be JSON for a program): the floor the sleeve advertises and
    how many of the strokes, sent as given (no simplifier here), are below it; said when some
    are, or when the floor is a wearer's measured limits, not before every send."""
    if floor is None:
        return
    below = sum(
        1
        for s in strokes
        if s.duration_ms < floor.min_duration_ms or math.dist(s.start, s.end) < floor.min_length
    )
    if not below and not floor.wearer:
        return
    whose = f" with wearer {floor.wearer}'s limits" if floor.wearer else ""
    # The sleeve slows only what its motors cannot play; a wearer's limits are kept by senders,
    # so below them a stroke is played as sent, and may not be felt.
    why = (
        "sent as given: the wearer may not feel a briefer or shorter one"
        if floor.wearer
        else "the sleeve slows a briefer one; a shorter one may not be felt"
    )
    verdict = (
        f"{'the stroke is' if len(strokes) == 1 else f'{below} of the {len(strokes)} strokes are'}"
        f" below it ({why})"
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
    if args.shape and args.segments is not None and not SHAPES[args.shape].accepts(args.segments):
        parser.error(
            f"--segments: {args.segments} does not fit a {args.shape}; give "
            f"{SHAPES[args.shape].allowed()}"
        )


# What a stroke or shape is checked against before the sleeve's own grid is known.
ANY_GRID = replace(
    PAPER_SLEEVE,
    name="any sleeve",
    rows=MAX_GRID_SIDE,
    columns=MAX_GRID_SIDE,
    max_stroke_duration_ms=MAX_DURATION_MS,
)


def _strokes(
    args: argparse.Namespace, layout: Layout, texts: list[tuple[str, str]]
) -> list[Stroke]:
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
    # Before the sleeve's grid is known its form only: its grid and its longest stroke are the
    # sleeve's, checked once its status is read (ANY_GRID's would be quoted as the sleeve's).
    known = layout is not ANY_GRID
    for seq, (where, text) in enumerate(texts):
        result = parse(text, layout if known else None, format="legacy")
        if not isinstance(result, Accepted):
            if not known and result.reason == DURATION_NOT_POSITIVE:
                result = replace(
                    result,
                    message=f"{result.message.removesuffix('.')} and at most the sleeve's "
                    "longest stroke (its layout's max_stroke_duration_ms, "
                    f"{PAPER_SLEEVE.max_stroke_duration_ms:g} ms on the paper's sleeve): give "
                    "the duration in milliseconds as the stroke's fifth number, e.g. "
                    "0,0,2,0,500.",
                )
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


def _summary(
    args: argparse.Namespace,
    settings: BrokerSettings,
    strokes: list[Stroke],
    sent: int,
    *,
    stopped: bool = False,
) -> str:
    what = (
        f"a {args.shape} of {plural(len(strokes), 'stroke')}"
        if args.shape
        else plural(len(strokes), "stroke")
    )
    if sent < len(strokes):
        why = "the drawing was stopped" if stopped else "the sleeve refused strokes for its wearer"
        what = f"{sent} of {what} (the rest not sent: {why})"
    total_ms = sum(s.duration_ms for s in strokes[:sent])
    where = (
        f"the legacy topic {args.legacy_topic}"
        if args.legacy
        else f"sleeve {settings.sleeve_id!r} (drawing {strokes[0].drawing})"
    )
    return (
        f"Sent {what}, {total_ms / 1000:.2f} s of drawing, to {where} via {settings.url}; "
        f"the broker acknowledged every one."
    )
