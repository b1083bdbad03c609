"""The senders with their own account, from ``feelmysign broker add-sender --name NAME``,
in ``senders.json``; the wearer blocks and unblocks them.

Shape of the file (mode 0600)::

    {"alice": {"username": "sender-alice", "password": "...", "blocked": false}, ...}

Each named sender has its own broker account with the sender's rights, so the wearer
can take one away without touching the others. A blocked sender's account stays in
this file (so unblocking gives back the same join token) but is left out of the
password file and the ACL the broker runs with: the broker refuses its login, and a
reload disconnects it. The page of ``feelmysign up`` keeps the shared sender account
of ``credentials.json``, listed as ``page`` and never blocked (the wearer pauses
instead): ``up`` itself needs it to log each drawing.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from feelmysign.broker.credentials import (
    Account,
    load_named_accounts,
    named_accounts_error,
    new_password,
    write_named_accounts,
)
from feelmysign.connection.settings import SENDER_USERNAME_PREFIX
from feelmysign.errors import BrokerError

PAGE_SENDER = "page"  # the name of up's page, on the shared sender account
_NAME_PATTERN = re.compile(r"[A-Za-z0-9_-]{1,64}")


@dataclass(frozen=True)
class Sender:
    name: str
    account: Account
    blocked: bool = False


def check_sender_name(name: str) -> str:
    """``name`` if it can name a sender, else a BrokerError saying why and what to use."""
    if not _NAME_PATTERN.fullmatch(name) or name == PAGE_SENDER:
        raise BrokerError(
            "bad-option",
            f"Sender name {name!r} cannot be used: use 1 to 64 letters, digits, '_' or '-', "
            f"other than {PAGE_SENDER!r} (the name of the drawing page of 'feelmysign up').",
        )
    return name


def load_senders(path: Path) -> dict[str, Sender]:
    """The named senders by name; none when the file does not exist yet."""
    senders: dict[str, Sender] = {}
    for name, (account, entry) in load_named_accounts(path, "sender", check_sender_name).items():
        blocked = entry.get("blocked", False)
        if not isinstance(blocked, bool):
            raise named_accounts_error(
                path, "sender", f"sender {name!r} has a 'blocked' that is not true or false"
            )
        senders[name] = Sender(name, account, blocked)
    return senders


def add_sender(path: Path, name: str) -> Sender:
    """The sender ``name``: the existing one (its token stays valid), or a new one."""
    senders = load_senders(path)
    if name in senders:
        return senders[name]
    sender = Sender(check_sender_name(name), Account(SENDER_USERNAME_PREFIX + name, new_password()))
    _write(path, {**senders, name: sender})
    return sender


def set_blocked(path: Path, name: str, blocked: bool) -> Sender:
    """Block or unblock the named sender; a BrokerError names the senders there are."""
    senders = load_senders(path)
    if name not in senders:
        known = ", ".join(sorted(senders)) or "none yet"
        raise BrokerError(
            "bad-option",
            f"There is no sender {name!r} to {'block' if blocked else 'unblock'} (senders: "
            f"{known}); senders get their account with 'feelmysign broker add-sender --name NAME'.",
        )
    sender = Sender(name, senders[name].account, blocked)
    _write(path, {**senders, name: sender})
    return sender


def _write(path: Path, senders: dict[str, Sender]) -> None:
    write_named_accounts(
        path,
        {
            name: {
                "username": s.account.username,
                "password": s.account.password,
                "blocked": s.blocked,
            }
            for name, s in senders.items()
        },
    )
