"""The wearer's page's HTTP API: pause, resume, stop, a ceiling, "do not disturb", and
blocking senders, from the wearer's phone.

Mounted by ``webserver.WebServer`` under ``/api/wearer/`` (``wearer_api=``), behind the
wearer's own key (never the sender's: a sender must not be able to pause or unblock)::

    GET  /api/wearer/state            -> the state below
    POST /api/wearer/pause | resume | stop                 (body: {} or none)
    POST /api/wearer/ceiling          {"ceiling": 0.6 | null}
    POST /api/wearer/do-not-disturb   {"until_ms": 1795330000000 | null}
    POST /api/wearer/block | unblock  {"sender": "alice"}

Each answers the new state, ``{"sleeve_id", "online", "controls", "max_intensity",
"senders": [{"name", "blocked", "blockable"}], "blocking"}``, or 400 with ``{"error":
sentence}``. The controls are called in this process (``WearerControls``): no broker in
between, so the wearer can pause even when the broker is down.

Blocking needs the broker feelmysign runs (its state directory: ``broker_files``): the
sender's account is left out of the password file and the ACL and the broker is reloaded,
which disconnects it (Mosquitto 2.0 checks every connected client again on SIGHUP) and
refuses its next login. Without that directory ``blocking`` is false. A block also stops
what plays and drops what waits, as ``stop`` does: the blocked sender's strokes already at
the sleeve must not go on, and the sleeve cannot tell one sender's strokes from another's.
"""

from __future__ import annotations

import json
import math
import secrets
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from feelmysign.broker._config import StateFiles
from feelmysign.broker.accounts import reload_running_broker
from feelmysign.broker.credentials import Credentials, write_private_file
from feelmysign.broker.senders import PAGE_SENDER, load_senders, set_blocked
from feelmysign.errors import FeelMySignError
from feelmysign.sleeve.controls import WearerControls

WEARER_KEY_BYTES = 16  # 128 bits, like the page's key
WEARER_KEY_FILE = "wearer-key"
PREFIX = "/api/wearer/"
JSON = "application/json"
BY = "page"  # who the controls say changed them
MAX_BODY_BYTES = 4096  # the API's bodies are a few dozen bytes


def wearer_key(state_dir: Path) -> str:
    """The wearer's key, kept in ``state_dir``: the wearer's bookmark works after a restart."""
    path = state_dir / WEARER_KEY_FILE
    try:
        key = path.read_text(encoding="utf-8").strip()
    except FileNotFoundError:
        key = ""
    if len(key) < WEARER_KEY_BYTES:  # missing, or cut short: a new one
        key = secrets.token_urlsafe(WEARER_KEY_BYTES)
        write_private_file(path, key + "\n")
    return key


@dataclass
class Blocking:
    """The broker feelmysign runs, whose accounts the wearer may block."""

    files: StateFiles
    credentials: Credentials


class WearerApi:
    """``api(method, path, host, body, content_type) -> (status, content type, body)``.

    ``controls``: the running sleeve's controls, None while it starts. ``online``: whether
    the sleeve is on the broker now.
    """

    def __init__(
        self,
        *,
        sleeve_id: str,
        max_intensity: float,
        controls: Callable[[], WearerControls | None],
        online: Callable[[], bool],
        blocking: Blocking | Callable[[], Blocking | None] | None = None,
    ) -> None:
        self._sleeve_id = sleeve_id
        self._max_intensity = max_intensity
        self._controls = controls
        self._online = online
        self._blocking = blocking

    def __call__(
        self, method: str, path: str, host: str, body: bytes, content_type: str
    ) -> tuple[int, str, bytes]:
        try:
            return 200, JSON, _json(self._answer(method, path, body, content_type))
        except _Refused as refused:
            return refused.status, JSON, _json({"error": refused.sentence})
        except FeelMySignError as error:
            return 400, JSON, _json({"error": str(error)})

    def _blocking_now(self) -> Blocking | None:
        """The broker whose senders may be blocked: given, or looked for at each call (a
        sleeve's own page finds the local broker once it runs)."""
        blocking = self._blocking
        return blocking() if callable(blocking) else blocking

    def state(self) -> dict[str, Any]:
        controls = self._controls()
        senders: list[dict[str, Any]] = []
        blocking = self._blocking_now()
        if blocking is not None:
            senders.append({"name": PAGE_SENDER, "blocked": False, "blockable": False})
            for name, sender in sorted(load_senders(blocking.files.senders).items()):
                senders.append({"name": name, "blocked": sender.blocked, "blockable": True})
        return {
            "sleeve_id": self._sleeve_id,
            "online": controls is not None and self._online(),
            "controls": None if controls is None else controls.state().to_json(),
            "max_intensity": self._max_intensity,
            "senders": senders,
            "blocking": blocking is not None,
        }

    def _answer(self, method: str, path: str, body: bytes, content_type: str) -> dict[str, Any]:
        action = path.removeprefix(PREFIX)
        if action == "state":
            if method not in ("GET", "HEAD"):
                raise _Refused(405, f"{path} is read with GET, not {method}.")
            return self.state()
        if action not in _ACTIONS:
            raise _Refused(
                404, f"There is no {path}: the wearer's API has state, {', '.join(_ACTIONS)}."
            )
        if method != "POST":
            raise _Refused(405, f"{path} changes the sleeve: send it with POST, not {method}.")
        fields = _body(body, content_type)
        controls = self._controls()
        if controls is None:
            raise _Refused(503, "The sleeve is still starting: try again in a moment.")
        if action == "pause":
            controls.pause(BY)
        elif action == "resume":
            controls.resume(BY)
        elif action == "stop":
            controls.stop(BY)
        elif action == "ceiling":
            controls.set_ceiling(_ceiling(fields), BY)
        elif action == "do-not-disturb":
            controls.set_do_not_disturb(_until_ms(fields), BY)
        else:
            blocked = action == "block"
            self._block(_sender(fields), blocked=blocked)
            if blocked:
                # What the sender already sent is at the sleeve (playing, waiting), and a
                # stroke does not say which account sent it: all of it is stopped, as by Stop.
                controls.stop(BY)
        return self.state()

    def _block(self, name: str, *, blocked: bool) -> None:
        blocking = self._blocking_now()
        if blocking is None:
            raise _Refused(
                400,
                "Blocking a sender needs the broker feelmysign runs, on the machine of this "
                "page (in its usual state directory, as 'feelmysign up' and 'feelmysign broker' "
                "keep it); this sleeve's broker is not found there: block the sender on the "
                "wearer's page of 'feelmysign up' where the broker runs, or its owner removes "
                "the sender's account.",
            )
        if name == PAGE_SENDER:
            raise _Refused(
                400,
                f"The drawing page of 'feelmysign up' ({PAGE_SENDER!r}) cannot be blocked here: "
                "pause the sleeve instead, or stop 'feelmysign up'.",
            )
        set_blocked(blocking.files.senders, name, blocked)
        reload_running_broker(blocking.files, blocking.credentials)


_ACTIONS = ("pause", "resume", "stop", "ceiling", "do-not-disturb", "block", "unblock")


class _Refused(Exception):
    def __init__(self, status: int, sentence: str) -> None:
        super().__init__(sentence)
        self.status = status
        self.sentence = sentence


def _json(data: dict[str, Any]) -> bytes:
    return json.dumps(data).encode()


def _body(body: bytes, content_type: str) -> dict[str, Any]:
    if len(body) > MAX_BODY_BYTES:
        raise _Refused(400, f"The body is over {MAX_BODY_BYTES} bytes: send a small JSON object.")
    if not body.strip():
        return {}
    if content_type.split(";")[0].strip().lower() != JSON:
        raise _Refused(400, "Send the body as JSON, with Content-Type: application/json.")
    try:
        fields = json.loads(body)
    except (UnicodeDecodeError, ValueError):
        raise _Refused(
            400, 'The body is not JSON: send an object such as {"ceiling": 0.5}.'
        ) from None
    if not isinstance(fields, dict):
        raise _Refused(400, 'The body must be a JSON object, such as {"ceiling": 0.5}.')
    return fields


def _ceiling(fields: dict[str, Any]) -> float | None:
    if "ceiling" not in fields:
        raise _Refused(400, 'Give the ceiling: {"ceiling": 0.5}, or {"ceiling": null} for none.')
    value = fields["ceiling"]
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise _Refused(
            400, f"The ceiling {value!r} is not a number: give one such as 0.5, or null for none."
        )
    return float(value)


def _until_ms(fields: dict[str, Any]) -> int | None:
    if "until_ms" not in fields:
        raise _Refused(
            400,
            'Give the end of "do not disturb": {"until_ms": wall clock in ms since 1970}, '
            'or {"until_ms": null} to end it now.',
        )
    value = fields["until_ms"]
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise _Refused(
            400,
            f'"do not disturb" until {value!r} is not a time: give milliseconds since 1970, '
            "or null to end it.",
        )
    return int(value)


def _sender(fields: dict[str, Any]) -> str:
    name = fields.get("sender")
    if not isinstance(name, str) or not name:
        raise _Refused(400, 'Name the sender: {"sender": "alice"} (see "senders" in the state).')
    return name
