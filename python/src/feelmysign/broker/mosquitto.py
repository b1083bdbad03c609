"""A local Mosquitto for feelmysign: generated config, accounts and ACL, run as a child process.

::

    with Broker(state_dir=Path("state"), port=0, ws_port=0) as broker:   # 0: a free port
        broker.credentials.mqtt_url          # "mqtt://127.0.0.1:40123"
        broker.credentials.sleeve.username   # "sleeve-sleeve1"

Everything lives in the state directory (default ``$XDG_STATE_HOME/feelmysign/broker``):
``mosquitto.conf``, ``acl``, ``passwd``, ``credentials.json`` (what clients read),
``mosquitto.log`` and ``data/`` (retained messages and sessions). Passwords are kept
across restarts, so a running sleeve keeps working. Listeners are on 127.0.0.1 only.

One broker at a time per state directory: ``start()`` takes its ``InstanceLock``
(``instance.lock``) before writing anything, and refuses (BrokerError
``already-running``) while another process holds it. A start that fails puts back the
files it had rewritten; ``credentials.json`` is written only once Mosquitto accepts logins.
"""

from __future__ import annotations

import atexit
import os
import pwd
import re
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

from feelmysign.broker import _process as process_
from feelmysign.broker._config import LOOPBACK_ADDRESS, StateFiles, TlsListener, render_config
from feelmysign.broker.accounts import write_auth_files, write_runtime
from feelmysign.broker.credentials import (
    Credentials,
    check_sleeve_id,
    reuse_or_create,
    write_credentials,
    write_private_file,
    write_sleeve_credentials,
)
from feelmysign.broker.instance import LIBRARY_COMMAND, InstanceLock
from feelmysign.broker.tls import LanOptions, TlsFiles
from feelmysign.connection.client import probe_login
from feelmysign.connection.settings import DEFAULT_MQTT_PORT, DEFAULT_SLEEVE_ID
from feelmysign.errors import BrokerError
from feelmysign.lifecycle import Started
from feelmysign.state_home import state_path
from feelmysign.topics import LEGACY_TOPIC

DEFAULT_WS_PORT = 9001  # the WebSocket port of Mosquitto's documentation and examples
DEFAULT_READY_TIMEOUT_S = 10.0
DEFAULT_STOP_TIMEOUT_S = 5.0
# Ports chosen by us (port=0) can be taken by someone else before Mosquitto binds them.
AUTO_PORT_ATTEMPTS = 3
READY_POLL_S = 0.02
READY_PROBE_TIMEOUT_S = 1.0
# Mosquitto 2.0.11 and older bind a WebSocket listener to every address whatever the
# config says (eclipse-mosquitto/mosquitto#2085); naming the loopback interface works.
FIRST_VERSION_BINDING_WS_ADDRESS = (2, 0, 12)
LOOPBACK_INTERFACE = "lo"
LOG_ROTATE_BYTES = 10_000_000  # checked at each start
_TOPIC_PATTERN = re.compile(r"[^\s+#\x00]{1,256}")


def default_state_dir() -> Path:
    """``$XDG_STATE_HOME/feelmysign/broker``, ``~/.local/state/feelmysign/broker`` by default."""
    return Path(state_path("broker"))


class Broker(Started):
    """Mosquitto on 127.0.0.1 with one sleeve account, one sender account and their ACL.

    Options are checked when the object is made; ``start()`` (or ``with``) writes the
    files, starts Mosquitto and returns once it accepts the sender's login. ``port`` or
    ``ws_port`` 0 picks a free port. ``mosquitto`` is the executable (default: found on
    PATH, then in /usr/sbin). Mosquitto is stopped by ``stop()``, at exit, and, on Linux,
    by the kernel if this process dies (from whichever thread it was started).
    ``save_every_change`` (default) has Mosquitto save its state after every change, so
    that a SIGKILL loses no stroke it acknowledged; False saves every 60 s (for benchmarks).
    ``lock``: the state directory's lock when the caller holds it already (``feelmysign up``
    holds it for its whole run); else ``start()`` takes it and ``stop()`` lets it go.
    """

    def __init__(
        self,
        *,
        state_dir: str | Path | None = None,
        port: int = DEFAULT_MQTT_PORT,
        ws_port: int = DEFAULT_WS_PORT,
        sleeve_id: str = DEFAULT_SLEEVE_ID,
        legacy_topic: str = LEGACY_TOPIC,
        mosquitto: str | Path | None = None,
        ready_timeout_s: float = DEFAULT_READY_TIMEOUT_S,
        stop_timeout_s: float = DEFAULT_STOP_TIMEOUT_S,
        lan: LanOptions | None = None,
        save_every_change: bool = True,
        lock: InstanceLock | None = None,
    ) -> None:
        _check_port(port, "--port")
        if lan is not None:
            _check_port(lan.port, "--tls-port")
        _check_port(ws_port, "--ws-port")
        if port == ws_port != 0:
            raise BrokerError(
                "bad-option",
                f"The MQTT and WebSocket ports are both {port}; give them different ports.",
            )
        _check_topic(legacy_topic)
        state_dir = Path(state_dir) if state_dir is not None else default_state_dir()
        if "\n" in str(state_dir) or "\r" in str(state_dir):
            # Mosquitto's config is line based: such a path cannot be written into it.
            raise BrokerError("bad-option", f"State directory {state_dir!r} contains a line break.")
        self._files = StateFiles(state_dir.absolute())
        if lock is not None and lock.state_dir != self._files.state_dir:
            raise ValueError(f"the lock of {lock.state_dir} for a broker in {state_dir}")
        self._lock = lock or InstanceLock(self._files.state_dir, LIBRARY_COMMAND)
        self._release_lock_at_stop = False
        self._requested_port = port
        self._requested_ws_port = ws_port
        self._sleeve_id = check_sleeve_id(sleeve_id)
        self._legacy_topic = legacy_topic
        self._lan = lan
        self._tls: TlsFiles | None = None
        self._mosquitto = mosquitto
        self._ready_timeout_s = ready_timeout_s
        self._stop_timeout_s = stop_timeout_s
        self._save_every_change = save_every_change
        self._process: subprocess.Popen[bytes] | None = None
        self._credentials: Credentials | None = None
        self.version: tuple[int, int, int] | None = None
        """Mosquitto's version, known once started (None if it did not say)."""

    @property
    def state_dir(self) -> Path:
        return self._files.state_dir

    @property
    def credentials_path(self) -> Path:
        return self._files.credentials

    @property
    def sleeve_credentials_path(self) -> Path:
        """The sleeve's login only: what to copy to a sleeve on another machine."""
        return self._files.sleeve_credentials

    @property
    def log_path(self) -> Path:
        return self._files.log

    @property
    def config_path(self) -> Path:
        return self._files.config

    @property
    def files(self) -> StateFiles:
        return self._files

    @property
    def lan(self) -> LanOptions | None:
        """Where the broker listens off loopback (its port chosen once started), or None."""
        return self._lan

    @property
    def tls(self) -> TlsFiles | None:
        """The certificate off loopback (None on loopback only), known once started."""
        return self._tls

    @property
    def lock(self) -> InstanceLock:
        """The state directory's lock (held while this broker runs)."""
        return self._lock

    @property
    def pid(self) -> int | None:
        return self._process.pid if self._process is not None else None

    @property
    def running(self) -> bool:
        return self._process is not None and self._process.poll() is None

    @property
    def credentials(self) -> Credentials:
        """URLs and accounts of the running broker (also in ``credentials_path``)."""
        if self._credentials is None or self._process is None:
            raise BrokerError(
                "not-running", "The broker is not running: call start() or use 'with Broker(...)'."
            )
        return self._credentials

    def start(self) -> Credentials:
        """Take the state directory's lock (BrokerError ``already-running`` if another process
        holds it), write the files, start Mosquitto, wait until it accepts a login, then write
        credentials.json; return the credentials. A failure puts back the files it rewrote."""
        if self._process is not None:
            raise BrokerError("start-failed", f"This broker already runs (pid {self.pid}).")
        taken_here = not self._lock.held
        self._lock.acquire()  # first: another instance on this state directory refuses us
        try:
            credentials = self._start()
        except BaseException:
            if taken_here:
                self._lock.release()
            raise
        self._release_lock_at_stop = taken_here
        self._lock.describe(
            mqtt_url=credentials.mqtt_url,
            ws_url=credentials.ws_url,
            mqtts_url=credentials.mqtts_url,
        )
        return credentials

    def _start(self) -> Credentials:
        executable = process_.find_mosquitto(self._mosquitto, process_.search_dirs())
        self.version = process_.mosquitto_version(executable)
        self._make_state_dir()
        if self._lan is not None:
            self._lan = self._bindable(self._lan)
        # Ports checked before anything is written: a port taken leaves the state as it was.
        port, ws_port = self._choose_ports()
        if self._lan is not None:
            self._tls = self._lan.tls_files(self._files.tls_dir)
        attempts_left = AUTO_PORT_ATTEMPTS
        while True:
            try:
                return self._start_on(executable, port, ws_port)
            except BrokerError as error:
                attempts_left -= 1
                if attempts_left == 0 or not self._took_a_port_we_chose(error):
                    raise
            port, ws_port = self._choose_ports()

    def _took_a_port_we_chose(self, error: BrokerError) -> bool:
        """Someone else bound a port we picked before Mosquitto could: worth another pick."""
        requested = (self._requested_port, self._requested_ws_port)
        return error.reason == "port-in-use" and error.port not in (None, *requested)

    def stop(self) -> None:
        """Stop Mosquitto (SIGTERM, so it saves retained messages; SIGKILL after the timeout),
        and let the state directory's lock go if ``start()`` took it."""
        try:
            self._stop_process()
        finally:
            if self._release_lock_at_stop:
                self._release_lock_at_stop = False
                self._lock.release()

    def _stop_process(self) -> None:
        process, self._process = self._process, None
        self._credentials = None
        atexit.unregister(self.stop)
        if process is not None:
            process_.stop(process, timeout_s=self._stop_timeout_s)
            self._files.runtime.unlink(missing_ok=True)

    def check_running(self, *, wait_s: float = 0.0) -> None:
        """Wait up to ``wait_s`` for Mosquitto to exit; BrokerError ``exited`` if it did."""
        process = self._process
        if process is None:
            raise BrokerError("not-running", "The broker is not running.")
        try:
            code = process.wait(timeout=wait_s) if wait_s > 0 else process.poll()
        except subprocess.TimeoutExpired:
            return
        if code is not None:
            self.stop()
            tail = process_.log_tail(self.log_path)
            raise BrokerError(
                "exited",
                f"Mosquitto stopped unexpectedly (exit code {code}). "
                f"Last lines of {self.log_path}:\n{_indent(tail)}",
                log_path=self.log_path,
                exit_code=code,
            )

    def _make_state_dir(self) -> None:
        try:
            self._files.state_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
            self._files.persistence_dir.mkdir(mode=0o700, exist_ok=True)
        except OSError as error:
            raise BrokerError(
                "bad-option",
                f"Cannot create the state directory {self._files.state_dir}: {error.strerror}. "
                "Choose another one with --state-dir.",
            ) from None

    def _choose_ports(self) -> tuple[int, int]:
        port = self._requested_port or process_.free_port(LOOPBACK_ADDRESS)
        ws_port = self._requested_ws_port
        while ws_port in (0, port):
            ws_port = process_.free_port(LOOPBACK_ADDRESS)
        process_.check_port_free(LOOPBACK_ADDRESS, port, what="MQTT", option="--port")
        process_.check_port_free(LOOPBACK_ADDRESS, ws_port, what="WebSocket", option="--ws-port")
        return port, ws_port

    def _start_on(self, executable: str, port: int, ws_port: int) -> Credentials:
        credentials = reuse_or_create(
            self._files.credentials,
            sleeve_id=self._sleeve_id,
            mqtt_url=f"mqtt://{LOOPBACK_ADDRESS}:{port}",
            ws_url=f"ws://{LOOPBACK_ADDRESS}:{ws_port}",
            mqtts_url=self._mqtts_url(),
            ca_fingerprint=self._tls.ca_fingerprint if self._tls else None,
        )
        files = self._files
        previous = _contents(files.config, files.acl, files.passwords)
        try:
            self._write_files(credentials, executable, port, ws_port)
            _rotate(files.log)
            log_offset_bytes = files.log.stat().st_size if files.log.exists() else 0
            # The log names clients and accounts: private like the rest of the state directory.
            log_fd = os.open(files.log, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
            with os.fdopen(log_fd, "ab") as log:
                self._process = process_.spawn(executable, files.config, log)
            atexit.register(self.stop)
            write_runtime(
                files,
                pid=self._process.pid,
                legacy_topic=self._legacy_topic,
                executable=executable,
            )
            self._wait_until_ready(credentials, port, ws_port, log_offset_bytes)
        except BaseException:
            self._stop_process()
            _restore(previous)  # a failed start leaves the state directory as it found it
            raise
        # What clients read, written once the broker it names accepts them.
        write_credentials(files.credentials, credentials)
        write_sleeve_credentials(files.sleeve_credentials, credentials)
        self._credentials = credentials
        _publish_clock(credentials)
        return credentials

    def _write_files(
        self, credentials: Credentials, executable: str, port: int, ws_port: int
    ) -> None:
        files = self._files
        write_auth_files(
            files,
            credentials,
            legacy_topic=self._legacy_topic,
            mosquitto_dir=str(Path(executable).parent),
        )
        config = render_config(
            files,
            port=port,
            ws_port=ws_port,
            ws_bind=_ws_bind(self.version),
            run_as_user=_user_name(),
            tls=self._tls_listener(),
            save_every_change=self._save_every_change,
        )
        write_private_file(files.config, config)

    @staticmethod
    def _bindable(lan: LanOptions) -> LanOptions:
        """``lan`` with its port chosen when 0; BrokerError when the address is not ours."""
        try:
            port = lan.port or process_.free_port(lan.host)
            process_.check_port_free(lan.host, port, what="MQTT TLS", option="--tls-port")
        except OSError as error:
            raise BrokerError(
                "bad-option",
                f"Cannot listen on {lan.host} ({error.strerror}): give --host one of this "
                "machine's own addresses (see 'ip -brief address'), or leave it out for --lan "
                "to pick the address of the default route.",
            ) from None
        return replace(lan, port=port)

    def _mqtts_url(self) -> str | None:
        if self._lan is None:
            return None
        host = f"[{self._lan.host}]" if ":" in self._lan.host else self._lan.host
        return f"mqtts://{host}:{self._lan.port}"

    def _tls_listener(self) -> TlsListener | None:
        if self._lan is None or self._tls is None:
            return None
        return TlsListener(self._lan.host, self._lan.port, self._tls.cert, self._tls.key)

    def _wait_until_ready(
        self, credentials: Credentials, port: int, ws_port: int, log_offset_bytes: int
    ) -> None:
        """Return once Mosquitto accepts the sender's login on ``port`` (the port of
        ``credentials.mqtt_url``) and TCP on ``ws_port``."""
        assert self._process is not None
        sender = credentials.settings("sender")
        probe_id = f"feelmysign-ready-probe-{os.getpid()}"
        deadline = time.monotonic() + self._ready_timeout_s
        while True:
            code = self._process.poll()
            if code is not None:
                raise self._start_error(code, port, ws_port, log_offset_bytes)
            remaining_s = deadline - time.monotonic()
            if remaining_s <= 0:
                raise self._not_ready_error(port, log_offset_bytes)
            probe_s = min(remaining_s, READY_PROBE_TIMEOUT_S)
            accepted = probe_login(sender, client_id=probe_id, timeout_s=probe_s)
            if accepted is False:
                raise self._login_refused_error(port, log_offset_bytes)
            if (
                accepted
                and process_.accepts_tcp(LOOPBACK_ADDRESS, ws_port, timeout_s=probe_s)
                and (
                    self._lan is None
                    or process_.accepts_tcp(self._lan.host, self._lan.port, timeout_s=probe_s)
                )
            ):
                return
            # No event to wait on: the listener does not exist yet, so poll.
            time.sleep(READY_POLL_S)

    def _start_error(
        self, code: int, port: int, ws_port: int, log_offset_bytes: int
    ) -> BrokerError:
        tail = process_.log_tail(self.log_path, start_offset_bytes=log_offset_bytes)
        if "Unable to create websockets listener" in tail:
            return process_.port_in_use_error(
                ws_port, what="WebSocket", option="--ws-port", log_path=self.log_path
            )
        if "Address already in use" in tail:
            return process_.port_in_use_error(
                port, what="MQTT", option="--port", log_path=self.log_path
            )
        return BrokerError(
            "start-failed",
            f"Mosquitto exited at start-up (exit code {code}). "
            f"Last lines of {self.log_path}:\n{_indent(tail)}",
            log_path=self.log_path,
        )

    def _not_ready_error(self, port: int, log_offset_bytes: int) -> BrokerError:
        tail = process_.log_tail(self.log_path, start_offset_bytes=log_offset_bytes)
        return BrokerError(
            "start-failed",
            f"Mosquitto (pid {self.pid}) did not accept connections on {LOOPBACK_ADDRESS}:{port} "
            f"within {self._ready_timeout_s:g} s. Last lines of {self.log_path}:\n{_indent(tail)}",
            port=port,
            log_path=self.log_path,
        )

    def _login_refused_error(self, port: int, log_offset_bytes: int) -> BrokerError:
        tail = process_.log_tail(self.log_path, start_offset_bytes=log_offset_bytes)
        return BrokerError(
            "start-failed",
            f"The broker on {LOOPBACK_ADDRESS}:{port} refused the generated sender login: "
            f"either another broker answered there, or {self._files.passwords} is wrong "
            f"(delete it to have it rewritten). Last lines of {self.log_path}:\n{_indent(tail)}",
            port=port,
            log_path=self.log_path,
        )


def _contents(*paths: Path) -> dict[Path, bytes | None]:
    """Each file's bytes (None: it does not exist), to put back with ``_restore``."""
    contents: dict[Path, bytes | None] = {}
    for path in paths:
        try:
            contents[path] = path.read_bytes()
        except FileNotFoundError:
            contents[path] = None
    return contents


def _restore(contents: dict[Path, bytes | None]) -> None:
    for path, data in contents.items():
        try:
            if data is None:
                path.unlink(missing_ok=True)
            else:
                write_private_file(path, data.decode())
        except (OSError, UnicodeDecodeError):
            pass  # best effort: the error being raised says more than this one would


def _rotate(log: Path) -> None:
    """Keep one previous log, so a broker that runs for months cannot fill a Pi's SD card."""
    if log.exists() and log.stat().st_size > LOG_ROTATE_BYTES:
        log.replace(log.with_name(log.name + ".1"))


def _check_port(port: int, option: str) -> None:
    if not 0 <= port <= 65535:
        raise BrokerError(
            "bad-option",
            f"Port {port} ({option}) is out of range: use 1 to 65535, or 0 for a free one.",
        )


def _check_topic(topic: str) -> None:
    if not _TOPIC_PATTERN.fullmatch(topic) or topic.startswith("$"):
        raise BrokerError(
            "bad-option",
            f"Legacy topic {topic!r} cannot be used: give a topic name without spaces, "
            "'+' or '#', not starting with '$' (the default is 'deviceOne/line').",
        )


def _ws_bind(version: tuple[int, int, int] | None) -> str:
    old = version is not None and version < FIRST_VERSION_BINDING_WS_ADDRESS
    return LOOPBACK_INTERFACE if old and sys.platform.startswith("linux") else LOOPBACK_ADDRESS


def _user_name() -> str | None:
    """Who we run as, for Mosquitto's ``user`` option (None: a uid without a name)."""
    try:
        return pwd.getpwuid(os.geteuid()).pw_name
    except KeyError:
        return None


def _indent(text: str) -> str:
    return "\n".join(f"  {line}" for line in text.splitlines()) or "  (the log is empty)"


def _publish_clock(credentials: Credentials) -> None:
    """This machine's time on feelmysign/clock (retained), for sleeves to check their clock
    against (feelmysign.broker_clock). Best effort: a sleeve without it only checks nothing."""
    from feelmysign.broker_clock import publish_clock
    from feelmysign.connection import connect_client
    from feelmysign.errors import FeelMySignError

    try:
        client = connect_client(
            credentials.settings("sender"),
            f"feelmysign-clock-{os.getpid()}",
            timeout_s=READY_PROBE_TIMEOUT_S,
            note=lambda _: None,
        )
    except FeelMySignError:
        return
    try:
        publish_clock(client, timeout_s=READY_PROBE_TIMEOUT_S)
    except (RuntimeError, ValueError, OSError):
        pass  # refused (an ACL from before the clock) or cut: no clock this time
    finally:
        client.disconnect()
        client.loop_stop()
