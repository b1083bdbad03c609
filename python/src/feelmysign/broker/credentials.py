"""The broker's accounts as written to ``credentials.json``, the one file clients read.

Shape of the file (mode 0600)::

    {"mqtt_url": "mqtt://127.0.0.1:1883", "ws_url": "ws://127.0.0.1:9001",
     "sleeve": {"id": "sleeve1", "username": "sleeve-sleeve1", "password": "..."},
     "sender": {"username": "sender", "password": "..."}}

Passwords are kept across restarts (a running sleeve keeps working); a new
sleeve id gets a new sleeve account, the sender's account is kept.

Beside it, ``sleeve-credentials.json`` holds only what a sleeve needs (the
same shape without ``ws_url`` and ``sender``): the file to copy to a sleeve on
another machine, which must not get the sender's password.
"""

from __future__ import annotations

import json
import os
import re
import secrets
import string
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

from feelmysign.connection.settings import BrokerSettings, parse_broker_url
from feelmysign.errors import BrokerError
from feelmysign.input_files import MAX_CREDENTIALS_BYTES, loads_json, read_text

Role = Literal["sleeve", "sender"]
SENDER_USERNAME = "sender"
SLEEVE_USERNAME_PREFIX = "sleeve-"
# A sleeve id becomes one level of a topic: no '/', and no MQTT wildcards '+' '#'.
SLEEVE_ID_PATTERN = re.compile(r"[A-Za-z0-9_-]{1,64}")
# 24 random bytes (192 bits), URL-safe so a password needs no quoting anywhere.
PASSWORD_ALPHABET = string.ascii_letters + string.digits
PASSWORD_LENGTH = 32  # 32 of 62 symbols: about 190 bits
# What a password file line and a URL can hold without escaping.
_PASSWORD_PATTERN = re.compile(r"[!-~]{8,256}")
CREDENTIALS_FILE_MODE = 0o600


@dataclass(frozen=True)
class Account:
    """One MQTT login. The password is left out of ``repr`` so it never lands in a log."""

    username: str
    password: str = field(repr=False)


@dataclass(frozen=True)
class Credentials:
    """Where the broker listens and the two accounts on it (a sleeve's and the sender's)."""

    mqtt_url: str
    ws_url: str
    sleeve_id: str
    sleeve: Account
    sender: Account
    # Off loopback (feelmysign up --lan): the TLS listener, and the SHA-256 of the local
    # CA's certificate that join tokens carry (None with a publicly trusted certificate).
    mqtts_url: str | None = None
    ca_fingerprint: str | None = None

    def settings(self, role: Role) -> BrokerSettings:
        """How ``role`` reaches the broker at ``mqtt_url``: its login, and this sleeve's id."""
        account = self.sender if role == "sender" else self.sleeve
        return parse_broker_url(
            self.mqtt_url,
            username=account.username,
            password=account.password,
            sleeve_id=self.sleeve_id,
        )

    @property
    def mqtt_host(self) -> str:
        return parse_broker_url(self.mqtt_url).host

    @property
    def mqtt_port(self) -> int:
        return parse_broker_url(self.mqtt_url).port

    @property
    def ws_port(self) -> int:
        return parse_broker_url(self.ws_url).port

    def to_json(self) -> dict[str, Any]:
        tls = {"mqtts_url": self.mqtts_url} if self.mqtts_url else {}
        if self.ca_fingerprint:
            tls["ca_fingerprint"] = self.ca_fingerprint
        return {
            **tls,
            "mqtt_url": self.mqtt_url,
            "ws_url": self.ws_url,
            "sleeve": {
                "id": self.sleeve_id,
                "username": self.sleeve.username,
                "password": self.sleeve.password,
            },
            "sender": {"username": self.sender.username, "password": self.sender.password},
        }


def check_sleeve_id(sleeve_id: str) -> str:
    """Return ``sleeve_id`` if it can be one topic level, else raise a BrokerError saying why."""
    if not SLEEVE_ID_PATTERN.fullmatch(sleeve_id):
        raise BrokerError(
            "bad-option",
            f"Sleeve id {sleeve_id!r} cannot be used: use 1 to 64 letters, digits, '_' or '-' "
            "(no '/', '+' or '#': they are MQTT topic separators and wildcards).",
        )
    return sleeve_id


def sleeve_username(sleeve_id: str) -> str:
    return SLEEVE_USERNAME_PREFIX + sleeve_id


def new_password() -> str:
    # Letters and digits only: a password that starts with '-' would be read as an option
    # by every command line that takes `--password`.
    return "".join(secrets.choice(PASSWORD_ALPHABET) for _ in range(PASSWORD_LENGTH))


def load_credentials(path: str | Path) -> Credentials:
    """Read a ``credentials.json`` the broker wrote; a BrokerError names the file and problem."""
    path = Path(path)
    return _credentials_from_json(_read_json(path), path)


def load_login(path: str | Path, role: Role) -> BrokerSettings:
    """How ``role`` reaches the broker, from a ``credentials.json`` or a
    ``sleeve-credentials.json``: its URL, the login of ``role`` and the sleeve id."""
    path = Path(path)
    data = _read_json(path)
    if isinstance(data, dict) and "sender" not in data and "sleeve" in data:
        if role == "sender":
            raise _bad_file(
                path,
                "it holds only a sleeve's login (a sleeve-credentials.json); to send, use the "
                "broker's credentials.json",
            )
        return _sleeve_login_from_json(data, path)
    return _credentials_from_json(data, path).settings(role)


def _read_json(path: Path) -> object:
    try:
        return loads_json(read_text(path, max_bytes=MAX_CREDENTIALS_BYTES))
    except FileNotFoundError:
        raise BrokerError(
            "credentials-file",
            f"No credentials file at {path}; start the broker first ('feelmysign broker') "
            "or pass the file it wrote (STATE_DIR/credentials.json, or "
            "STATE_DIR/sleeve-credentials.json for a sleeve).",
        ) from None
    except (OSError, ValueError) as error:
        raise _bad_file(path, f"it cannot be read as JSON ({error})") from None


def _sleeve_login_from_json(data: dict[str, Any], path: Path) -> BrokerSettings:
    try:
        sleeve = data["sleeve"]
        mqtt_url, sleeve_id = _text(data["mqtt_url"]), _text(sleeve["id"])
        account = Account(_text(sleeve["username"]), _text(sleeve["password"]))
    except (KeyError, TypeError):
        raise _bad_file(path, "it lacks mqtt_url or sleeve{id, username, password}") from None
    check_sleeve_id(sleeve_id)
    _check_account(account, path)
    return parse_broker_url(
        mqtt_url, username=account.username, password=account.password, sleeve_id=sleeve_id
    )


def _check_account(account: Account, path: Path) -> None:
    if ":" in account.username or not _PASSWORD_PATTERN.fullmatch(account.password):
        raise _bad_file(path, f"the account {account.username!r} has an unusable name or password")


def _credentials_from_json(data: object, path: Path) -> Credentials:
    try:
        if not isinstance(data, dict):
            raise TypeError(f"expected a JSON object, got {data!r}")
        sleeve, sender = data["sleeve"], data["sender"]
        credentials = Credentials(
            mqtt_url=_text(data["mqtt_url"]),
            ws_url=_text(data["ws_url"]),
            sleeve_id=_text(sleeve["id"]),
            sleeve=Account(_text(sleeve["username"]), _text(sleeve["password"])),
            sender=Account(_text(sender["username"]), _text(sender["password"])),
            mqtts_url=_optional_text(data.get("mqtts_url")),
            ca_fingerprint=_optional_text(data.get("ca_fingerprint")),
        )
    except (KeyError, TypeError):
        raise _bad_file(
            path, "it lacks mqtt_url, ws_url, sleeve{id, username, password} or sender{...}"
        ) from None
    check_sleeve_id(credentials.sleeve_id)
    for account in (credentials.sleeve, credentials.sender):
        _check_account(account, path)
    return credentials


def _text(value: object) -> str:
    if not isinstance(value, str):
        raise TypeError(f"expected a string, got {value!r}")
    return value


def _optional_text(value: object) -> str | None:
    return None if value is None else _text(value)


def _bad_file(path: Path, problem: str) -> BrokerError:
    return BrokerError(
        "credentials-file",
        f"The credentials file {path} is not usable: {problem}. Fix it, or delete it to have "
        "the broker generate new passwords (every sleeve and sender must then use the new file).",
    )


def reuse_or_create(
    path: Path,
    *,
    sleeve_id: str,
    mqtt_url: str,
    ws_url: str,
    mqtts_url: str | None = None,
    ca_fingerprint: str | None = None,
) -> Credentials:
    """The credentials to run with: the passwords in ``path`` when it exists, fresh ones otherwise.

    The URLs always follow the ports of this run. A different sleeve id gets a new sleeve
    account (the old sleeve must not read the new one's strokes); the sender keeps its own.
    """
    if path.exists():
        previous = load_credentials(path)
        sleeve = previous.sleeve
        if previous.sleeve_id != sleeve_id:
            sleeve = Account(sleeve_username(sleeve_id), new_password())
        return replace(
            previous,
            mqtt_url=mqtt_url,
            ws_url=ws_url,
            sleeve_id=sleeve_id,
            sleeve=sleeve,
            mqtts_url=mqtts_url,
            ca_fingerprint=ca_fingerprint,
        )
    return Credentials(
        mqtt_url=mqtt_url,
        ws_url=ws_url,
        sleeve_id=sleeve_id,
        sleeve=Account(sleeve_username(sleeve_id), new_password()),
        sender=Account(SENDER_USERNAME, new_password()),
        mqtts_url=mqtts_url,
        ca_fingerprint=ca_fingerprint,
    )


def write_private_file(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` with mode 0600, atomically (a reader never sees half a file)."""
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, CREDENTIALS_FILE_MODE)
    try:
        # The mode given to open() is filtered by the umask; set it explicitly.
        os.fchmod(descriptor, CREDENTIALS_FILE_MODE)
        with os.fdopen(descriptor, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def load_named_accounts(
    path: Path, kind: str, check_name: Callable[[str], str]
) -> dict[str, tuple[Account, dict[str, Any]]]:
    """A file of named accounts (``{name: {"username", "password", ...}}``, as
    ``sleeves.json`` and ``senders.json``): each name's account and its whole entry, or
    none when the file does not exist yet. ``kind`` names one entry in errors ("sleeve")."""
    try:
        data = loads_json(read_text(path, max_bytes=MAX_CREDENTIALS_BYTES))
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as error:
        raise named_accounts_error(path, kind, f"it cannot be read as JSON ({error})") from None
    if not isinstance(data, dict):
        raise named_accounts_error(path, kind, "it is not a JSON object")
    accounts: dict[str, tuple[Account, dict[str, Any]]] = {}
    for name, entry in data.items():
        check_name(name)
        if not isinstance(entry, dict) or not all(
            isinstance(entry.get(key), str) for key in ("username", "password")
        ):
            raise named_accounts_error(path, kind, f"{kind} {name!r} lacks a username or password")
        accounts[name] = (Account(entry["username"], entry["password"]), entry)
    return accounts


def write_named_accounts(path: Path, entries: dict[str, dict[str, Any]]) -> None:
    """Write a file of named accounts (mode 0600, atomically); the reverse of the above."""
    write_private_file(path, json.dumps(entries, indent=2) + "\n")


def named_accounts_error(path: Path, kind: str, problem: str) -> BrokerError:
    return BrokerError(
        "credentials-file",
        f"The {kind}s file {path} is not usable: {problem}. Fix it, or delete it and add "
        f"the {kind}s again (each then needs its new join token).",
    )


def write_credentials(path: Path, credentials: Credentials) -> None:
    write_private_file(path, json.dumps(credentials.to_json(), indent=2) + "\n")


def write_sleeve_credentials(path: Path, credentials: Credentials) -> None:
    """The sleeve's part of ``credentials``: what a sleeve on another machine gets."""
    sleeve_only = {"mqtt_url": credentials.mqtt_url, "sleeve": credentials.to_json()["sleeve"]}
    write_private_file(path, json.dumps(sleeve_only, indent=2) + "\n")
