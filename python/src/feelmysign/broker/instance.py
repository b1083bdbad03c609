"""One running feelmysign per state directory: ``up`` and ``broker`` hold a lock there.

``STATE_DIR/instance.lock`` is locked with ``flock(2)`` (exclusive, advisory) for as long
as the broker of that directory runs. The kernel releases the lock when the process ends,
however it ends (``kill -9`` included), so a crashed instance never blocks a restart; the
file itself stays. Beside it, ``instance.json`` (mode 0600) says who holds it: the pid,
the command and, once known, the page's and the broker's addresses. A second ``up`` or
``broker`` on the same directory reads it and refuses before writing anything there::

    with InstanceLock(state_dir, "feelmysign up") as lock:   # BrokerError "already-running"
        ...
        lock.describe(page="http://127.0.0.1:8000/")

``broker add-sleeve`` and ``add-sender`` take no lock: they are meant to run beside the
broker, and reload it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import json
import os
import time
from pathlib import Path
from typing import Any

from feelmysign.broker.credentials import write_private_file
from feelmysign.errors import BrokerError

LOCK_NAME = "instance.lock"
INFO_NAME = "instance.json"
MAX_INFO_BYTES = 16_384
# What instance.json says of a broker started from Python (benchmarks, tests).
LIBRARY_COMMAND = "a program using feelmysign.broker.Broker"


class InstanceLock:
    """The lock of one state directory, for ``command`` (as a person would type it)."""

    def __init__(self, state_dir: str | Path, command: str) -> None:
        self._state_dir = Path(state_dir).absolute()
        self._command = command
        self._fd: int | None = None
        self._info: dict[str, Any] = {}

    @property
    def state_dir(self) -> Path:
        return self._state_dir

    @property
    def lock_path(self) -> Path:
        return self._state_dir / LOCK_NAME

    @property
    def info_path(self) -> Path:
        return self._state_dir / INFO_NAME

    @property
    def held(self) -> bool:
        return self._fd is not None

    def acquire(self) -> None:
        """Take the lock, or raise BrokerError ``already-running`` saying who has it."""
        if self._fd is not None:
            return
        try:
            self._state_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
            fd = os.open(self.lock_path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
        except OSError as error:
            raise BrokerError(
                "bad-option",
                f"Cannot use the state directory {self._state_dir}: {error.strerror}. "
                "Choose another one with --state-dir.",
            ) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as error:
            os.close(fd)
            if error.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise already_running_error(
                    self._state_dir, read_info(self.info_path), self._command
                ) from None
            raise BrokerError(
                "bad-option",
                f"Cannot lock {self.lock_path} ({error.strerror}): the state directory must be "
                "on a file system with flock(2); choose another one with --state-dir.",
            ) from None
        self._fd = fd
        self._info = {
            "pid": os.getpid(),
            "command": self._command,
            "started": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        }
        self._write_info()

    def describe(self, **addresses: str | None) -> None:
        """Add what a second instance should be told (``page``, ``mqtt_url``, ...)."""
        if self._fd is None:
            return
        self._info.update({k: v for k, v in addresses.items() if v is not None})
        self._write_info()

    def release(self) -> None:
        fd, self._fd = self._fd, None
        if fd is None:
            return
        with contextlib.suppress(OSError):  # still ours: nobody else can hold the lock
            self.info_path.unlink(missing_ok=True)
        os.close(fd)  # closes the lock's open file description: the lock is released

    def __enter__(self) -> InstanceLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def _write_info(self) -> None:
        # Only a courtesy to a second instance (what to tell): the lock is what guards.
        with contextlib.suppress(OSError):
            write_private_file(self.info_path, json.dumps(self._info, indent=2) + "\n")


def read_info(path: Path) -> dict[str, Any]:
    """What ``instance.json`` says (nothing when it is missing or unreadable)."""
    try:
        with path.open("rb") as stream:
            data = json.loads(stream.read(MAX_INFO_BYTES))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def already_running_error(state_dir: Path, info: dict[str, Any], command: str) -> BrokerError:
    """Who runs on ``state_dir``, how to use it, stop it, or run ``command`` beside it."""
    pid = info.get("pid")
    pid = pid if isinstance(pid, int) else None
    who = str(info.get("command") or "feelmysign")
    since = f", since {info['started']}" if isinstance(info.get("started"), str) else ""
    lines = [
        f"feelmysign is already running with the state directory {state_dir} "
        f"({who}, pid {pid if pid is not None else 'unknown'}{since})."
    ]
    if isinstance(info.get("page"), str):
        lines.append(f"  Its page:    {info['page']}")
    if isinstance(info.get("mqtt_url"), str):
        ws = f" and {info['ws_url']}" if isinstance(info.get("ws_url"), str) else ""
        lines.append(f"  Its broker:  {info['mqtt_url']}{ws}")
    credentials = state_dir / "credentials.json"
    lines += [
        "Use it: open its page, or send to it with "
        f"'feelmysign send --credentials {credentials} --shape heart'.",
        "Stop it: Ctrl-C in its terminal"
        + (f", or 'kill {pid}'" if pid is not None else "")
        + " ('feelmysign stop' only stops what the sleeve plays).",
    ]
    if command == "feelmysign up":
        beside = "feelmysign up --state-dir OTHER_DIR --http-port 0 --port 0 --ws-port 0"
    else:
        beside = f"{command} --state-dir OTHER_DIR --port 0 --ws-port 0"
    lines.append(
        f"Or run another one beside it, with a state directory and ports of its own: {beside}"
    )
    return BrokerError("already-running", "\n".join(lines))
