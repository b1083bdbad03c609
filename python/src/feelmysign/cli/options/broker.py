"""Broker options shared by the commands that talk to a broker (``send``, ``sleeve``).

    --broker URL          mqtt://HOST:PORT, mqtts:// (TLS), ws:// or wss:// (WebSockets)
    --id ID               the sleeve's id (default sleeve1)
    --username U --password P, or --credentials FILE (the credentials.json of 'feelmysign broker')

Each setting is taken from, in order: its option, its ``FEELMYSIGN_*`` environment
variable, the credentials file, the default. The credentials file gives the
account of the ``role`` (the sender's or the sleeve's), the MQTT URL and the
sleeve id. When neither a broker nor a credentials file is given, the local
broker's file (``feelmysign broker``'s default state directory) is used if it
exists, so that ``feelmysign send --shape circle`` just works next to it: its
URL and sleeve id always, its account unless --username gives another one. It
is never used with a broker named by --broker, so its passwords stay local.
Connecting is ``feelmysign.connection``'s part.
"""

from __future__ import annotations

import argparse
import os
from dataclasses import replace
from pathlib import Path

from feelmysign.broker import DEFAULT_SLEEVE_ID, default_state_dir
from feelmysign.broker.credentials import Role, check_sleeve_id, load_login
from feelmysign.cli.options.values import (
    MAX_CREDENTIALS_BYTES,
    MAX_TIMEOUT_S,
    check_input_file,
    not_empty,
    number,
    sleeve_id,
)
from feelmysign.connection import (
    DEFAULT_BROKER_URL,
    DEFAULT_TIMEOUT_S,
    BrokerSettings,
    parse_broker_url,
)
from feelmysign.connection.join_token import default_trust_dir, join_settings
from feelmysign.connection.settings import PASSWORD_ENV, USERNAME_ENV
from feelmysign.errors import BrokerConnectionError

BROKER_ENV = "FEELMYSIGN_BROKER"
SLEEVE_ID_ENV = "FEELMYSIGN_SLEEVE_ID"
CREDENTIALS_ENV = "FEELMYSIGN_CREDENTIALS"
JOIN_ENV = "FEELMYSIGN_JOIN"


def add_broker_timeout_option(
    parser: argparse.ArgumentParser | argparse._ArgumentGroup, *, help_start: str
) -> None:
    """Add --timeout-s, the longest wait for the broker; ``help_start`` says what is awaited."""
    parser.add_argument(
        "--timeout-s",
        type=number(0, MAX_TIMEOUT_S, unit="s", above_low=True),
        default=DEFAULT_TIMEOUT_S,
        metavar="S",
        help=f"{help_start} (default: {DEFAULT_TIMEOUT_S:g})",
    )


def add_broker_options(parser: argparse.ArgumentParser, *, role: Role) -> None:
    """Add --broker, --id, --username, --password and --credentials for ``role``."""
    group = parser.add_argument_group(
        "broker",
        "Where the MQTT broker is and how to log in. Each setting comes from its option, "
        "else its environment variable, else --credentials, else the default.",
    )
    group.add_argument(
        "--broker",
        metavar="URL",
        type=not_empty("broker URL"),
        help=f"broker URL: mqtt://HOST:PORT, mqtts:// (TLS), ws:// or wss:// (WebSockets) "
        f"(default: ${BROKER_ENV}, else the credentials file's mqtt_url, else "
        f"{DEFAULT_BROKER_URL})",
    )
    which = "the sleeve to send to" if role == "sender" else "this sleeve's id"
    group.add_argument(
        "--id",
        dest="sleeve_id",
        metavar="ID",
        type=sleeve_id,
        help=f"{which}: 1-64 letters, digits, '_' or '-' (default: ${SLEEVE_ID_ENV}, else "
        f"the credentials file's sleeve id, else {DEFAULT_SLEEVE_ID})",
    )
    group.add_argument(
        "--username",
        metavar="U",
        type=not_empty("user name"),
        help=f"MQTT user name (default: ${USERNAME_ENV})",
    )
    group.add_argument(
        "--password",
        metavar="P",
        type=not_empty("password"),
        help=f"MQTT password (default: ${PASSWORD_ENV}; prefer it or --credentials: "
        "other users can see command lines)",
    )
    if role == "sender":
        group.add_argument(
            "--join",
            metavar="TOKEN",
            type=not_empty("join token"),
            help="the one-line token of 'feelmysign broker add-sender': broker URL (TLS), its "
            "CA's fingerprint, the sleeve to send to and the sender's login; --id may name "
            "another sleeve; not to be given with --broker, --username, --password, "
            "--credentials or --ca",
        )
        group.add_argument(
            "--ca",
            metavar="FILE",
            type=not_empty("CA file"),
            help="the CA certificate (PEM) to check the broker's TLS certificate with, for "
            "mqtts:// or wss:// to a broker whose certificate is not publicly trusted (a "
            "'feelmysign broker --lan' one: its ca.pem; default: the system's trusted CAs)",
        )
    if role == "sleeve":
        group.add_argument(
            "--join",
            metavar="TOKEN",
            type=not_empty("join token"),
            help=f"the one-line token of 'feelmysign broker add-sleeve ID': broker URL (TLS), "
            f"its CA's fingerprint, this sleeve's id and login; not to be given with "
            f"--broker, --id, --username, --password or --credentials (default: ${JOIN_ENV}, "
            "which wins over their environment variables; prefer it: the token holds the "
            "sleeve's password, and other users can see command lines)",
        )
    group.add_argument(
        "--credentials",
        metavar="FILE",
        type=not_empty("credentials file"),
        help=f"the credentials.json written by 'feelmysign broker', for the {role} account, "
        "the URL and the sleeve id"
        + (" (or its sleeve-credentials.json, the sleeve's login only)" if role == "sleeve" else "")
        + f" (default: ${CREDENTIALS_ENV}, else "
        f"{local_credentials_path()} when it exists and no --broker is given)",
    )


def local_credentials_path() -> Path:
    """The credentials file of a ``feelmysign broker`` run with its default state directory."""
    return default_state_dir() / "credentials.json"


def broker_settings_from_args(args: argparse.Namespace, role: Role) -> BrokerSettings:
    """The settings the options and environment ask for; BrokerError saying what is wrong.

    A join token (sleeve only) fetches and checks the broker's CA the first time.
    """
    settings = _settings(args, role)
    ca = getattr(args, "ca", None)
    if ca is None:
        return settings
    if not settings.tls:
        raise BrokerConnectionError(
            "bad-option",
            f"--ca {ca} is for a TLS broker URL (mqtts:// or wss://); {settings.url} is not "
            "one. Give the broker's TLS URL with --broker, or leave --ca out.",
        )
    if not Path(ca).is_file():
        raise BrokerConnectionError(
            "bad-option",
            f"--ca {ca}: no such file. Copy the broker's ca.pem (in its state directory) to "
            "this machine and give its path.",
        )
    check_input_file(ca, what="CA file", max_bytes=MAX_CREDENTIALS_BYTES)
    return replace(settings, ca_file=str(Path(ca).absolute()))


def _settings(args: argparse.Namespace, role: Role) -> BrokerSettings:
    env = os.environ
    token = getattr(args, "join", None) or (env.get(JOIN_ENV) if role == "sleeve" else None)
    if token:
        _check_nothing_beside_the_token(
            "--join" if getattr(args, "join", None) else f"${JOIN_ENV}", args, role
        )
        joined = join_settings(token, default_trust_dir(), role=role)
        # A sender's account may send to every sleeve of its broker.
        if role == "sender" and args.sleeve_id:
            return replace(joined, sleeve_id=check_sleeve_id(args.sleeve_id))
        return joined
    url = args.broker or env.get(BROKER_ENV) or None
    username = args.username or env.get(USERNAME_ENV) or None
    password = args.password or env.get(PASSWORD_ENV) or None
    login = _login(args.credentials or env.get(CREDENTIALS_ENV), url, role)
    if username is None and password is not None:
        raise BrokerConnectionError(
            "bad-option",
            f"A password was given (--password or ${PASSWORD_ENV}) without a user name: "
            f"give --username too (or ${USERNAME_ENV}).",
        )
    if username is not None and password is None:
        raise BrokerConnectionError(
            "bad-option",
            f"User {username!r} was given without a password: give --password too "
            f"(or ${PASSWORD_ENV}), or use --credentials FILE.",
        )
    if username is None and login is not None:
        username, password = login.username, login.password
    sleeve_id = args.sleeve_id or env.get(SLEEVE_ID_ENV) or None
    if sleeve_id is None:
        sleeve_id = login.sleeve_id if login is not None else DEFAULT_SLEEVE_ID
    sleeve_id = check_sleeve_id(sleeve_id)
    if url is None and login is not None:
        return replace(login, username=username, password=password, sleeve_id=sleeve_id)
    return parse_broker_url(
        url or DEFAULT_BROKER_URL, username=username, password=password, sleeve_id=sleeve_id
    )


# What a join token holds, as options.
_IN_A_TOKEN = (
    ("broker", "--broker"),
    ("sleeve_id", "--id"),
    ("username", "--username"),
    ("password", "--password"),
    ("credentials", "--credentials"),
)


def _check_nothing_beside_the_token(token_from: str, args: argparse.Namespace, role: Role) -> None:
    """A join token is the broker URL, sleeve id and login: one of these options beside
    it is a conflict, refused rather than silently overruled.

    Their environment variables are not: the systemd unit sets $FEELMYSIGN_CREDENTIALS
    for every sleeve, and a token in sleeve.env wins over it, as the unit says.
    """
    held = [(k, o) for k, o in _IN_A_TOKEN if not (role == "sender" and k == "sleeve_id")]
    given = [option for key, option in [*held, ("ca", "--ca")] if getattr(args, key, None)]
    if given:
        also = " and ".join(given)
        raise BrokerConnectionError(
            "bad-option",
            f"{token_from} (a join token) holds the broker URL, its CA, the sleeve id and a login, "
            f"and would win over {also}: give one or the other. Leave {also} out to join "
            f"with the token, or leave {token_from} out to use {also}.",
        )


def _login(path: str | None, url: str | None, role: Role) -> BrokerSettings | None:
    local = local_credentials_path()
    if not path and (url is not None or not local.is_file()):
        return None
    chosen = path or local
    check_input_file(chosen, what="credentials file", max_bytes=MAX_CREDENTIALS_BYTES)
    return load_login(chosen, role)
