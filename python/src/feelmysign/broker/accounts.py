"""The password file and the ACL for every account of a broker, and reloading a running one.

``feelmysign broker add-sleeve`` runs beside the broker: it writes the new account,
renders both files again from the state directory, and sends Mosquitto SIGHUP, on
which Mosquitto 2.0 reads its password file and ACL again without dropping anyone.
"""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path

from feelmysign.broker import _process as process_
from feelmysign.broker._config import StateFiles, render_acl, write_password_file
from feelmysign.broker.credentials import Credentials, write_private_file
from feelmysign.broker.senders import load_senders
from feelmysign.broker.sleeves import load_sleeves
from feelmysign.errors import BrokerError


def write_auth_files(
    files: StateFiles, credentials: Credentials, *, legacy_topic: str, mosquitto_dir: str | None
) -> None:
    """passwd and acl for the first sleeve, the sender, every added sleeve and every named
    sender the wearer has not blocked (a blocked one is in neither: no login, no rights)."""
    others = {
        sleeve_id: account
        for sleeve_id, account in load_sleeves(files.sleeves).items()
        if sleeve_id != credentials.sleeve_id
    }
    senders = [s.account for s in load_senders(files.senders).values() if not s.blocked]
    dirs = ([mosquitto_dir] if mosquitto_dir else []) + process_.search_dirs()
    passwd_tool = process_.find_executable("mosquitto_passwd", dirs)
    write_password_file(
        files.passwords,
        [credentials.sleeve, credentials.sender, *others.values(), *senders],
        mosquitto_passwd=passwd_tool,
    )
    acl = render_acl(
        sleeve_id=credentials.sleeve_id,
        sleeve_username=credentials.sleeve.username,
        sender_username=credentials.sender.username,
        legacy_topic=legacy_topic,
        other_sleeves=[(sleeve_id, account.username) for sleeve_id, account in others.items()],
        other_senders=[account.username for account in senders],
    )
    write_private_file(files.acl, acl)


def write_runtime(files: StateFiles, *, pid: int, legacy_topic: str, executable: str) -> None:
    data = {"pid": pid, "legacy_topic": legacy_topic, "mosquitto": executable}
    write_private_file(files.runtime, json.dumps(data) + "\n")


def reload_running_broker(files: StateFiles, credentials: Credentials) -> int | None:
    """Render the auth files again and SIGHUP the running Mosquitto; its pid, or None if none runs.

    With no broker running, nothing is written: the next start renders every file anyway.
    """
    try:
        runtime = json.loads(files.runtime.read_text(encoding="utf-8"))
        pid, legacy_topic = int(runtime["pid"]), str(runtime["legacy_topic"])
        executable = str(runtime["mosquitto"])
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise BrokerError(
            "credentials-file", f"{files.runtime} is not usable ({error}); restart the broker."
        ) from None
    if not _alive(pid):
        return None
    write_auth_files(
        files, credentials, legacy_topic=legacy_topic, mosquitto_dir=str(Path(executable).parent)
    )
    os.kill(pid, signal.SIGHUP)
    return pid


def _alive(pid: int) -> bool:
    """A Mosquitto with this pid runs (a pid left by a crash may now be someone else's)."""
    try:
        command = Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return False
    return b"mosquitto" in command
