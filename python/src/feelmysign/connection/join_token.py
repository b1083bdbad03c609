"""Join tokens: one line holding what a sleeve on another machine needs to reach its broker.

``feelmysign broker add-sleeve arm2`` prints one; ``feelmysign sleeve --join TOKEN``
reads it. The token is ``fms1.`` followed by URL-safe base64 of compact JSON::

    {"url": "mqtts://192.168.1.5:8883", "ca": "<sha-256 of the CA certificate, hex>",
     "id": "arm2", "user": "sleeve-arm2", "pass": "..."}

``ca`` is absent for a broker whose certificate is publicly trusted. A sender's token
(``feelmysign broker add-sender``, read by ``feelmysign send --join TOKEN``) also has
``"role": "sender"``, its login is the sender's and ``id`` the sleeve it sends to; a
token without ``role`` is a sleeve's. The token holds a
password: treat it as one (the systemd unit reads it from a file only root can read).
"""

from __future__ import annotations

import base64
import binascii
import json
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

from feelmysign.connection.pinned_ca import pinned_ca_file
from feelmysign.connection.settings import BrokerSettings, parse_broker_url
from feelmysign.errors import BrokerConnectionError
from feelmysign.input_files import loads_json
from feelmysign.state_home import state_path

TOKEN_PREFIX = "fms1."
Role = Literal["sleeve", "sender"]
_FINGERPRINT = re.compile(r"[0-9a-f]{64}")


@dataclass(frozen=True)
class JoinToken:
    url: str
    sleeve_id: str
    username: str
    password: str
    ca_fingerprint: str | None = None
    role: Role = "sleeve"

    def encode(self) -> str:
        data = {"url": self.url, "id": self.sleeve_id, "user": self.username}
        data["pass"] = self.password
        if self.ca_fingerprint:
            data["ca"] = self.ca_fingerprint
        if self.role != "sleeve":
            data["role"] = self.role
        raw = json.dumps(data, separators=(",", ":")).encode()
        return TOKEN_PREFIX + base64.urlsafe_b64encode(raw).decode().rstrip("=")

    def settings(self, *, ca_file: str | None = None) -> BrokerSettings:
        """Where and how to connect; ``ca_file`` is the pinned CA once fetched and checked."""
        base = parse_broker_url(
            self.url, username=self.username, password=self.password, sleeve_id=self.sleeve_id
        )
        return replace(base, ca_file=ca_file)


def join_settings(text: str, trust_dir: Path, *, role: Role = "sleeve") -> BrokerSettings:
    """Settings from a join token for ``role``, its CA (if any) fetched, checked and kept in
    ``trust_dir``."""
    token = decode_join_token(text)
    if token.role != role:
        made_by = {"sleeve": "add-sleeve ID", "sender": "add-sender"}
        raise BrokerConnectionError(
            "bad-token",
            f"This join token is a {token.role}'s (from 'feelmysign broker "
            f"{made_by[token.role]}'), not a {role}'s: its account may not do what a {role} "
            f"does. Use the token of 'feelmysign broker {made_by[role]}'.",
        )
    settings = token.settings()
    if token.ca_fingerprint is None:
        return settings
    ca_file = pinned_ca_file(settings, token.ca_fingerprint, trust_dir)
    return token.settings(ca_file=str(ca_file))


def default_trust_dir() -> Path:
    """``$XDG_STATE_HOME/feelmysign/trusted``: the CAs of joined brokers."""
    return Path(state_path("trusted"))


def decode_join_token(text: str) -> JoinToken:
    """The token in ``text``; BrokerConnectionError ``bad-token`` saying what is wrong."""
    token = text.strip()
    if not token.startswith(TOKEN_PREFIX):
        raise _bad(f"it does not start with {TOKEN_PREFIX!r}")
    body = token[len(TOKEN_PREFIX) :]
    try:
        data = loads_json(base64.urlsafe_b64decode(body + "=" * (-len(body) % 4)))
    except (binascii.Error, ValueError):
        raise _bad("it is cut or mistyped (not base64 JSON)") from None
    if not isinstance(data, dict) or not all(
        isinstance(data.get(key), str) for key in ("url", "id", "user", "pass")
    ):
        raise _bad("it lacks the URL, sleeve id, user name or password")
    fingerprint = data.get("ca")
    if fingerprint is not None and (
        not isinstance(fingerprint, str) or not _FINGERPRINT.fullmatch(fingerprint)
    ):
        raise _bad("its CA fingerprint is not 64 hex digits")
    role = data.get("role", "sleeve")
    if role not in ("sleeve", "sender"):
        raise _bad(f"its role {role!r} is neither 'sleeve' nor 'sender'")
    joined = JoinToken(data["url"], data["id"], data["user"], data["pass"], fingerprint, role)
    settings = joined.settings()  # checks the URL
    if not settings.tls and not settings.on_loopback:
        raise _bad(
            f"its URL {joined.url} is not mqtts:// or wss://; a {role} joins over TLS "
            "unless it runs on the broker's machine (a loopback URL)"
        )
    return joined


def _bad(problem: str) -> BrokerConnectionError:
    return BrokerConnectionError(
        "bad-token",
        f"The join token is not usable: {problem}. Copy the whole line that "
        "'feelmysign broker add-sleeve ID' printed (it starts with fms1.).",
    )
