"""Mosquitto as a child process: find it, check ports, start it, wait for it, stop it.

The child never outlives us: it is killed by the kernel when the thread that
started it dies (Linux ``PR_SET_PDEATHSIG``), and stopped by ``Broker.stop``,
``atexit`` and the CLI's signal handlers otherwise. That thread is the main one, or,
for a broker started again from another thread (``up``'s watchdog), one kept for
that which never ends before the process does: so a ``kill -9`` of the process
takes a restarted broker with it too.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from pathlib import Path
from typing import IO

from feelmysign.errors import BrokerError

INSTALL_HINT = (
    "Install it with 'sudo apt-get install mosquitto' (or 'make system' in the repository)."
)
# Debian installs the broker in sbin, which is not on a normal user's PATH.
SBIN_DIRS = ("/usr/sbin", "/usr/local/sbin")
VERSION_TIMEOUT_S = 5.0
PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>
LOG_TAIL_BYTES = 16_384


def search_dirs() -> list[str]:
    """Where ``mosquitto`` is looked for: PATH, then the sbin directories."""
    path_dirs = [d for d in os.environ.get("PATH", "").split(os.pathsep) if d]
    return path_dirs + [d for d in SBIN_DIRS if d not in path_dirs]


def find_executable(name: str, dirs: Sequence[str]) -> str | None:
    return shutil.which(name, path=os.pathsep.join(dirs))


def find_mosquitto(explicit: str | Path | None, dirs: Sequence[str]) -> str:
    """The mosquitto executable to run, else BrokerError ``mosquitto-missing`` (how to install)."""
    if explicit is not None:
        found = shutil.which(str(explicit))
        if found is None:
            raise BrokerError(
                "mosquitto-missing",
                f"Mosquitto was not found at {explicit} (no executable file there). "
                f"{INSTALL_HINT} Or give the path of an installed mosquitto.",
            )
        return found
    found = find_executable("mosquitto", dirs)
    if found is None:
        raise BrokerError(
            "mosquitto-missing",
            f"Mosquitto was not found (looked for 'mosquitto' in {os.pathsep.join(dirs)}). "
            + INSTALL_HINT,
        )
    return found


def mosquitto_version(executable: str) -> tuple[int, int, int] | None:
    """The version ``mosquitto -h`` reports (it prints usage and exits non-zero), or None."""
    try:
        result = subprocess.run(
            [executable, "-h"], capture_output=True, text=True, timeout=VERSION_TIMEOUT_S
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    match = re.search(r"mosquitto version (\d+)\.(\d+)\.(\d+)", result.stdout + result.stderr)
    if match is None:
        return None
    major, minor, patch = (int(part) for part in match.groups())
    return major, minor, patch


def free_port(host: str) -> int:
    """A TCP port nobody listens on right now (the kernel's choice for port 0)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind((host, 0))
        port: int = probe.getsockname()[1]
        return port


def check_port_free(host: str, port: int, *, what: str, option: str) -> None:
    """BrokerError ``port-in-use`` naming the port and what to do, if something listens there."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        # Like Mosquitto itself: a port left in TIME_WAIT by a previous run is free.
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError as error:
            if error.errno not in (errno.EADDRINUSE, errno.EACCES):
                raise
            raise port_in_use_error(port, what=what, option=option) from None


def port_in_use_error(
    port: int, *, what: str, option: str, log_path: Path | None = None
) -> BrokerError:
    return BrokerError(
        "port-in-use",
        f"The {what} port {port} is already in use on 127.0.0.1. Another broker may be "
        f"running (Debian starts one: 'sudo systemctl stop mosquitto'); see who holds it "
        f"with \"ss -ltnp 'sport = :{port}'\", or choose another port with {option} "
        "(0 picks a free one).",
        port=port,
        log_path=log_path,
    )


class _Spawner:
    """A thread that forks the children other threads ask for, and lives as long as the
    process (it never returns): the kernel's parent-death signal watches the *thread* that
    forks, so a child forked by a passing thread would die with it, and one forked without
    the signal would outlive a ``kill -9`` of the process."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._requests: list[
            tuple[Callable[[], subprocess.Popen[bytes]], Future[subprocess.Popen[bytes]]]
        ] = []
        self._wake = threading.Condition(self._lock)
        self.thread: threading.Thread | None = None

    def run(self, start: Callable[[], subprocess.Popen[bytes]]) -> subprocess.Popen[bytes]:
        future: Future[subprocess.Popen[bytes]] = Future()
        with self._lock:
            if self.thread is None:
                self.thread = threading.Thread(
                    target=self._serve, name="feelmysign-spawner", daemon=True
                )
                self.thread.start()
            self._requests.append((start, future))
            self._wake.notify()
        return future.result()

    def _serve(self) -> None:
        while True:
            with self._lock:
                self._wake.wait_for(lambda: bool(self._requests))
                start, future = self._requests.pop(0)
            try:
                future.set_result(start())
            except BaseException as error:  # handed to the thread that asked
                future.set_exception(error)


_SPAWNER = _Spawner()


def _parent_death_signal(parent_pid: int) -> Callable[[], None] | None:
    """A pre-exec hook asking the kernel to SIGTERM the child when its parent dies (Linux only).

    The kernel watches the *thread* that forks, not the process: only the main thread and
    the spawner's (``_Spawner``), which end with the process, may set it.
    """
    current = threading.current_thread()
    if not sys.platform.startswith("linux") or (
        current is not threading.main_thread() and current is not _SPAWNER.thread
    ):
        return None
    prctl = ctypes.CDLL(None, use_errno=True).prctl  # resolved before fork: nothing to load after

    def hook() -> None:
        prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
        if os.getppid() != parent_pid:  # the parent died before prctl took effect
            os._exit(1)

    return hook


def spawn(executable: str, config: Path, log: IO[bytes]) -> subprocess.Popen[bytes]:
    """Start ``mosquitto -c config`` in its own session, its stdout and stderr into ``log``.

    Its own session: a Ctrl-C in the terminal reaches only us, and we stop the broker in
    order (SIGTERM, so it saves its database) instead of racing it. From a thread other
    than the main one (a restart), forked by the spawner's thread (``_Spawner``), so that
    it still dies with this process.
    """

    def start() -> subprocess.Popen[bytes]:
        return subprocess.Popen(
            [executable, "-c", str(config)],
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=log,
            start_new_session=True,
            preexec_fn=_parent_death_signal(os.getpid()),  # only prctl runs there: fork-safe
        )

    if (
        sys.platform.startswith("linux")
        and threading.current_thread() is not threading.main_thread()
    ):
        return _SPAWNER.run(start)
    return start()


def stop(process: subprocess.Popen[bytes], *, timeout_s: float) -> None:
    """SIGTERM (Mosquitto saves its database and exits), then SIGKILL after ``timeout_s``.

    SIGCONT after the SIGTERM: a stopped process (SIGSTOP, a debugger's pause) takes no
    signal but SIGKILL until continued, and continued it saves its database as it exits.
    """
    if process.poll() is None:
        process.terminate()
        with contextlib.suppress(ProcessLookupError):
            os.kill(process.pid, signal.SIGCONT)
        try:
            process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            process.kill()
    process.wait()


def log_tail(path: Path, *, start_offset_bytes: int = 0, lines: int = 15) -> str:
    """The last ``lines`` lines written to ``path`` after ``start_offset_bytes``."""
    try:
        with path.open("rb") as stream:
            size = stream.seek(0, os.SEEK_END)
            stream.seek(max(start_offset_bytes, size - LOG_TAIL_BYTES))
            text = stream.read().decode(errors="replace")
    except OSError:
        return ""
    return "\n".join(text.splitlines()[-lines:])


def accepts_tcp(host: str, port: int, *, timeout_s: float) -> bool:
    try:
        with socket.create_connection((host, port), timeout=timeout_s):
            return True
    except OSError:
        return False
