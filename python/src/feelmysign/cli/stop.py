"""``feelmysign stop``: cancel a drawing on the sleeve, or everything it is playing."""

from __future__ import annotations

import argparse
import threading
import uuid
from typing import TYPE_CHECKING, Any

from feelmysign.cli.options.broker import (
    add_broker_options,
    add_broker_timeout_option,
    broker_settings_from_args,
)
from feelmysign.cli.options.parser import Subcommands
from feelmysign.connection import connect_client
from feelmysign.control import CANCEL_ALL, Cancel, format_control
from feelmysign.errors import BrokerConnectionError, ParameterError
from feelmysign.protocol import MAX_DRAWING_ID_CHARS, is_drawing_id
from feelmysign.topics import control_topic

if TYPE_CHECKING:  # paho is imported where a client is made, not by 'feelmysign --help'
    import paho.mqtt.client as mqtt
    from paho.mqtt.reasoncodes import ReasonCode


def register(subparsers: Subcommands) -> None:
    parser = subparsers.add_parser(
        "stop",
        help="stop a drawing on the sleeve, or everything it plays",
        description=(
            "Publish a control message: the sleeve switches off the motors of the drawing "
            "(all of them without DRAWING) within one frame, drops its strokes still waiting, "
            "and reports each one as 'cancelled' on its events topic. Later strokes of a "
            "cancelled drawing are not played."
        ),
    )
    parser.add_argument(
        "drawing",
        nargs="?",
        default=CANCEL_ALL,
        metavar="DRAWING",
        help='the drawing id to cancel (as in the strokes\' "drawing"; default: everything)',
    )
    add_broker_timeout_option(parser, help_start="how long to wait for the broker, seconds")
    add_broker_options(parser, role="sender")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    drawing: str = args.drawing
    if drawing != CANCEL_ALL and not is_drawing_id(drawing):
        raise ParameterError(
            "DRAWING",
            drawing,
            f"a drawing id of 1 to {MAX_DRAWING_ID_CHARS} printable ASCII characters without "
            "spaces (leave it out to stop everything)",
        )
    settings = broker_settings_from_args(args, "sender")
    topic = control_topic(settings.sleeve_id)
    client = connect_client(settings, f"feelmysign-stop-{uuid.uuid4().hex[:12]}")
    acked = threading.Event()
    codes: list[ReasonCode] = []

    def on_publish(_c: mqtt.Client, _u: Any, _mid: int, code: ReasonCode, _p: Any) -> None:
        codes.append(code)
        acked.set()

    client.on_publish = on_publish
    try:
        client.publish(topic, format_control(Cancel(drawing)), qos=1)
        if not acked.wait(args.timeout_s):
            raise BrokerConnectionError(
                "timeout",
                f"{settings.url} did not acknowledge the stop within {args.timeout_s:g} s; "
                "try again, or raise --timeout-s",
                url=settings.url,
            )
        if codes[0].is_failure:
            raise BrokerConnectionError(
                "publish-refused",
                f"{settings.url} refused the stop on {topic} ({codes[0]}): user "
                f"{settings.username!r} may not publish there; use the sender account "
                "(credentials.json's 'sender') and check --id",
                url=settings.url,
            )
    finally:
        client.disconnect()
        client.loop_stop()
    what = "everything" if drawing == CANCEL_ALL else f"drawing {drawing}"
    print(f"Stop sent to sleeve {settings.sleeve_id}: {what}.", flush=True)
    return 0
