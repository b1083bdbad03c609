"""feelmysign broker: run a local Mosquitto for a sleeve and a sender until interrupted.

    feelmysign broker [--state-dir DIR] [--port P] [--ws-port W] [--sleeve-id ID]
                      [--lan | --host ADDRESS] [--tls-port P] [--tls-cert FILE --tls-key FILE]
    feelmysign broker [--state-dir DIR] add-sleeve ID    # prints the sleeve's join token
    feelmysign broker [--state-dir DIR] add-sender [--name NAME]  # a sender's join token

Prints the URLs, the credentials file and the log file, then "Ready." once the broker
accepts connections. Ctrl-C (SIGINT), SIGTERM or SIGHUP stop Mosquitto and exit 0.
While another 'feelmysign broker' or 'feelmysign up' runs on the same state directory it
refuses (exit 1), saying which and how to stop it, and changes nothing there.
"""

from __future__ import annotations

import argparse
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

from feelmysign.broker import (
    DEFAULT_MQTT_PORT,
    DEFAULT_SLEEVE_ID,
    DEFAULT_WS_PORT,
    Broker,
    default_state_dir,
)
from feelmysign.broker.instance import InstanceLock
from feelmysign.cli._join import run_add_sender, run_add_sleeve, run_nats_accounts
from feelmysign.cli.options.lan import add_lan_options, lan_from_args
from feelmysign.cli.options.parser import Subcommands, add_command

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
# How often the CLI notices a stop request or a Mosquitto that died.
WATCH_INTERVAL_S = 0.1


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "broker",
        help="run a local Mosquitto (MQTT and WebSockets on 127.0.0.1) until interrupted",
        description=__doc__,
    )
    parser.add_argument(
        "--state-dir",
        metavar="DIR",
        help="where the config, passwords, credentials.json, log and retained messages live "
        f"(default: {default_state_dir()})",
    )
    parser.add_argument(
        "--port",
        type=_port,
        default=DEFAULT_MQTT_PORT,
        metavar="P",
        help=f"MQTT TCP port on 127.0.0.1; 0 picks a free one (default: {DEFAULT_MQTT_PORT})",
    )
    parser.add_argument(
        "--ws-port",
        type=_port,
        default=DEFAULT_WS_PORT,
        metavar="W",
        help=f"MQTT-over-WebSockets port on 127.0.0.1, for browsers; 0 picks a free one "
        f"(default: {DEFAULT_WS_PORT})",
    )
    parser.add_argument(
        "--sleeve-id",
        default=DEFAULT_SLEEVE_ID,
        metavar="ID",
        help="the sleeve allowed on this broker: 1-64 letters, digits, '_' or '-' "
        f"(default: {DEFAULT_SLEEVE_ID})",
    )
    parser.add_argument(
        "--mosquitto",
        metavar="PATH",
        help="the mosquitto executable (default: found on PATH, then in /usr/sbin)",
    )
    add_lan_options(parser)
    parser.set_defaults(handler=run)
    commands = parser.add_subparsers(title="commands", metavar="COMMAND")
    add = commands.add_parser(
        "add-sleeve",
        help="give a sleeve on another machine its account; print its one-line join token",
        description=(
            "Create (or show again) the account of sleeve ID on this broker, allowed only its "
            "own topics, and print a one-line join token with the broker's TLS URL, its CA's "
            "fingerprint and the login. On the sleeve: feelmysign sleeve --join TOKEN. "
            "A running broker takes the new account at once."
        ),
    )
    add.add_argument("new_sleeve_id", metavar="ID", help="1-64 letters, digits, '_' or '-'")
    _add_url_option(add, "sleeve")
    add.set_defaults(handler=run_add_sleeve)
    sender = commands.add_parser(
        "add-sender",
        help="print the one-line join token of a sender on another machine (feelmysign send)",
        description=(
            "Print a one-line join token with the broker's TLS URL, its CA's fingerprint, the "
            "sleeve to send to and the sender's login. On the sender's machine: feelmysign "
            "send --join TOKEN --shape heart (the CA is fetched and checked against the "
            "fingerprint the first time)."
        ),
    )
    sender.add_argument(
        "--id",
        dest="to_sleeve_id",
        metavar="ID",
        help="the sleeve the token sends to (default: the broker's first sleeve; send --id "
        "may name another)",
    )
    sender.add_argument(
        "--name",
        metavar="NAME",
        help="give this sender an account of its own, which the wearer can block on the "
        "wearer's page (1-64 letters, digits, '_' or '-'; the same name again prints the same "
        "token); without it, the token holds the sender account every such token shares",
    )
    _add_url_option(sender, "sender")
    sender.set_defaults(handler=run_add_sender)
    nats = commands.add_parser(
        "nats-accounts",
        help="print the accounts.conf of a NATS cluster with this broker's accounts and ACL",
        description=(
            "Print, for deploy/nats/node.conf to include, the NATS accounts of this broker's "
            "sleeves and sender with permissions mirroring its ACL (it holds passwords)."
        ),
    )
    nats.set_defaults(handler=run_nats_accounts)


def _port(text: str) -> int:
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a port number") from None
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{port} is out of range: use 1 to 65535, or 0")
    return port


def run(args: argparse.Namespace) -> int:
    lock = InstanceLock(args.state_dir or default_state_dir(), "feelmysign broker")
    broker = Broker(
        state_dir=args.state_dir,
        port=args.port,
        ws_port=args.ws_port,
        sleeve_id=args.sleeve_id,
        mosquitto=args.mosquitto,
        lan=lan_from_args(args),
        lock=lock,
    )
    with lock, _stop_requests() as stop_requested, broker:
        _announce(broker)
        while not stop_requested:
            broker.check_running(wait_s=WATCH_INTERVAL_S)
    print("Mosquitto stopped.", flush=True)
    return 0


@contextmanager
def _stop_requests() -> Iterator[list[int]]:
    """Turn the stop signals into an entry in the yielded list while the broker runs.

    A flag, not an exception: a second Ctrl-C during shutdown must not cut the shutdown short.
    """
    received: list[int] = []

    def handler(signum: int, _frame: FrameType | None) -> None:
        received.append(signum)

    previous = {signum: signal.signal(signum, handler) for signum in STOP_SIGNALS}
    try:
        yield received
    finally:
        for signum, action in previous.items():
            signal.signal(signum, action)


def _announce(broker: Broker) -> None:
    credentials = broker.credentials
    version = ".".join(map(str, broker.version)) if broker.version else "(version unknown)"
    lines = [
        f"Mosquitto {version} running (pid {broker.pid}) with state in {broker.state_dir}",
        f"  MQTT:        {credentials.mqtt_url}",
        f"  WebSockets:  {credentials.ws_url}",
        *([f"  TLS:         {credentials.mqtts_url}"] if credentials.mqtts_url else []),
        f"  Credentials: {broker.credentials_path} "
        f"(sleeve user {credentials.sleeve.username}, sender user {credentials.sender.username})",
        f"  For a sleeve on another machine: {broker.sleeve_credentials_path} (its login only)",
        f"  Log:         {broker.log_path}",
        "Ready. Press Ctrl-C to stop.",
    ]
    print("\n".join(lines), flush=True)


def _add_url_option(parser: argparse.ArgumentParser, who: str) -> None:
    parser.add_argument(
        "--url",
        metavar="URL",
        help=f"the broker's URL as the {who} reaches it, mqtts:// or wss:// (default: the "
        "TLS listener of the last 'feelmysign broker --lan' or 'feelmysign up --lan')",
    )
