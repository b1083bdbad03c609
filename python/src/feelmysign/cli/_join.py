"""``feelmysign broker add-sleeve ID`` (a sleeve's account and its join token) and
``feelmysign broker nats-accounts`` (the same accounts for a NATS cluster)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from feelmysign.broker import Credentials, StateFiles, default_state_dir, load_credentials
from feelmysign.broker.accounts import reload_running_broker
from feelmysign.broker.credentials import check_sleeve_id
from feelmysign.broker.nats_accounts import render_nats_accounts
from feelmysign.broker.sleeves import add_sleeve, load_sleeves
from feelmysign.connection.join_token import JoinToken
from feelmysign.connection.settings import parse_broker_url
from feelmysign.errors import BrokerError
from feelmysign.topics import LEGACY_TOPIC


def _join_url(args: argparse.Namespace, credentials: Credentials, who: str) -> str:
    # No TLS listener: the plain loopback listener, as 'up' itself uses, for a second
    # sleeve (or a sender) on this machine (a password may go in clear text on loopback only).
    url: str = args.url or credentials.mqtts_url or credentials.mqtt_url
    settings = parse_broker_url(url)
    if not settings.tls and not settings.on_loopback:
        raise BrokerError(
            "bad-option",
            f"--url {url} is plain mqtt:// or ws:// to another machine: a {who} joins over "
            f"TLS (mqtts:// or wss://) unless it runs on this machine (127.0.0.1, ::1 or "
            "localhost). Start the broker with 'feelmysign up --lan' (or 'feelmysign broker "
            "--lan') and leave --url out, or give its TLS URL.",
        )
    return url


def run_add_sender(args: argparse.Namespace) -> int:
    files = StateFiles(Path(args.state_dir or default_state_dir()).absolute())
    credentials = load_credentials(files.credentials)
    sleeve_id = check_sleeve_id(args.to_sleeve_id or credentials.sleeve_id)
    url = _join_url(args, credentials, "sender")
    fingerprint = credentials.ca_fingerprint if args.url is None else None
    account = credentials.sender
    token = JoinToken(url, sleeve_id, account.username, account.password, fingerprint, "sender")
    print(token.encode(), flush=True)
    print(
        f"Sender {account.username}, to sleeve {sleeve_id}. On the sender's machine run\n"
        "  feelmysign send --join TOKEN --shape heart\n"
        "with the line above as TOKEN (it holds a password: keep it like one)."
        + (
            ""
            if parse_broker_url(url).tls
            else f"\nIts broker URL {url} is on this machine only: the sender must run here too."
        ),
        file=sys.stderr,
        flush=True,
    )
    return 0


def run_add_sleeve(args: argparse.Namespace) -> int:
    files = StateFiles(Path(args.state_dir or default_state_dir()).absolute())
    credentials = load_credentials(files.credentials)
    sleeve_id = check_sleeve_id(args.new_sleeve_id)
    url = _join_url(args, credentials, "sleeve")
    settings = parse_broker_url(url)
    if sleeve_id == credentials.sleeve_id:
        account = credentials.sleeve
    else:
        account = add_sleeve(files.sleeves, sleeve_id)
    # A user's own certificate (--tls-cert) is publicly trusted: nothing to pin then.
    fingerprint = credentials.ca_fingerprint if args.url is None else None
    pid = reload_running_broker(files, credentials)
    token = JoinToken(url, sleeve_id, account.username, account.password, fingerprint)
    print(token.encode(), flush=True)
    where = (
        f"the running broker (pid {pid}) has it now"
        if pid
        else "the broker has it at its next start"
    )
    print(
        f"Sleeve {sleeve_id}: account {account.username}, {where}. On the sleeve run\n"
        f"  feelmysign sleeve --join TOKEN\n"
        "with the line above as TOKEN (it holds a password: keep it like one)."
        + (
            ""
            if settings.tls
            else f"\nIts broker URL {url} is on this machine only: the sleeve must run here too."
        ),
        file=sys.stderr,
        flush=True,
    )
    return 0


def run_nats_accounts(args: argparse.Namespace) -> int:
    files = StateFiles(Path(args.state_dir or default_state_dir()).absolute())
    credentials = load_credentials(files.credentials)
    others = {i: a for i, a in load_sleeves(files.sleeves).items() if i != credentials.sleeve_id}
    print(render_nats_accounts(credentials, others, legacy_topic=LEGACY_TOPIC), end="")
    return 0
