"""The sleeves added to a broker with ``feelmysign broker add-sleeve ID``, in ``sleeves.json``.

Shape of the file (mode 0600)::

    {"arm2": {"username": "sleeve-arm2", "password": "..."}, ...}

The first sleeve (``--sleeve-id``) stays in ``credentials.json``; these are the others
that share the broker. Each has its own account, and the ACL gives it its own topics
only. An account is kept when it is added again, so its join token stays valid.
"""

from __future__ import annotations

import json
from pathlib import Path

from feelmysign.broker.credentials import (
    Account,
    check_sleeve_id,
    new_password,
    sleeve_username,
    write_private_file,
)
from feelmysign.errors import BrokerError
from feelmysign.input_files import MAX_CREDENTIALS_BYTES, loads_json, read_text


def load_sleeves(path: Path) -> dict[str, Account]:
    """The added sleeves by id; none when the file does not exist yet."""
    try:
        data = loads_json(read_text(path, max_bytes=MAX_CREDENTIALS_BYTES))
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as error:
        raise _bad_file(path, f"it cannot be read as JSON ({error})") from None
    if not isinstance(data, dict):
        raise _bad_file(path, "it is not a JSON object")
    sleeves: dict[str, Account] = {}
    for sleeve_id, account in data.items():
        check_sleeve_id(sleeve_id)
        if not isinstance(account, dict) or not all(
            isinstance(account.get(key), str) for key in ("username", "password")
        ):
            raise _bad_file(path, f"sleeve {sleeve_id!r} lacks a username or password")
        sleeves[sleeve_id] = Account(account["username"], account["password"])
    return sleeves


def add_sleeve(path: Path, sleeve_id: str) -> Account:
    """The account of ``sleeve_id``: the existing one, or a new one written to ``path``."""
    sleeves = load_sleeves(path)
    if sleeve_id in sleeves:
        return sleeves[check_sleeve_id(sleeve_id)]
    account = Account(sleeve_username(check_sleeve_id(sleeve_id)), new_password())
    sleeves[sleeve_id] = account
    data = {i: {"username": a.username, "password": a.password} for i, a in sleeves.items()}
    write_private_file(path, json.dumps(data, indent=2) + "\n")
    return account


def _bad_file(path: Path, problem: str) -> BrokerError:
    return BrokerError(
        "credentials-file",
        f"The sleeves file {path} is not usable: {problem}. Fix it, or delete it and add "
        "the sleeves again (each then needs its new join token).",
    )
