"""The sleeves added to a broker with ``feelmysign broker add-sleeve ID``, in ``sleeves.json``.

Shape of the file (mode 0600)::

    {"arm2": {"username": "sleeve-arm2", "password": "..."}, ...}

The first sleeve (``--sleeve-id``) stays in ``credentials.json``; these are the others
that share the broker. Each has its own account, and the ACL gives it its own topics
only. An account is kept when it is added again, so its join token stays valid.
"""

from __future__ import annotations

from pathlib import Path

from feelmysign.broker.credentials import (
    Account,
    check_sleeve_id,
    load_named_accounts,
    new_password,
    sleeve_username,
    write_named_accounts,
)


def load_sleeves(path: Path) -> dict[str, Account]:
    """The added sleeves by id; none when the file does not exist yet."""
    return {
        i: account
        for i, (account, _) in load_named_accounts(path, "sleeve", check_sleeve_id).items()
    }


def add_sleeve(path: Path, sleeve_id: str) -> Account:
    """The account of ``sleeve_id``: the existing one, or a new one written to ``path``."""
    sleeves = load_sleeves(path)
    if sleeve_id in sleeves:
        return sleeves[check_sleeve_id(sleeve_id)]
    account = Account(sleeve_username(check_sleeve_id(sleeve_id)), new_password())
    sleeves[sleeve_id] = account
    write_named_accounts(
        path, {i: {"username": a.username, "password": a.password} for i, a in sleeves.items()}
    )
    return account
