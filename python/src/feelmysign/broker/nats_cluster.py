"""A 3-node NATS cluster on loopback, from ``deploy/nats/``, for tests and benchmarks.

::

    with NatsCluster(state_dir, credentials) as cluster:
        cluster.nodes[0].mqtt_url      # "mqtt://127.0.0.1:40123"
        cluster.mqtt_urls              # all three, comma separated, for failover
        cluster.kill(0)                # SIGKILL node a

Every node runs the same configuration (``deploy/nats/*.conf``, copied into the state
directory next to the ``accounts.conf`` rendered from ``credentials``), its ports and
routes given through the environment, as in production: ``node-loopback.conf``, or
with ``tls=`` (a certificate for 127.0.0.1 from ``broker.tls.ensure_local_ca``)
``node.conf``, whose MQTT and WebSocket listeners and routes speak only TLS
(``mqtts://``, ``wss://``; a route only with a certificate from the same CA).
``python -m feelmysign.broker.nats_cluster DIR``
runs one until Ctrl-C and prints its URLs and accounts as JSON (the browser tests use it).

A started cluster is settled, however busy the machine: JetStream has a meta leader that
sees the other two nodes current, every node has taken an MQTT login (the first one
creates the MQTT streams, with three replicas) and every node's share of those streams is
current (its ``/healthz`` on the monitoring port, ``NatsNode.monitor_port``). Each is a
condition waited for, never a fixed time: on a loaded machine an MQTT login that comes
before the meta leader hangs for seconds, and one that comes before the leader has heard
from every node is refused ("no suitable peers for placement"), and is tried again.
"""

from __future__ import annotations

import functools
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from feelmysign.broker import _process as process_
from feelmysign.broker.credentials import (
    Account,
    Credentials,
    load_credentials,
    reuse_or_create,
    write_credentials,
    write_private_file,
)
from feelmysign.broker.nats_accounts import render_nats_accounts
from feelmysign.broker.tls import TlsFiles
from feelmysign.connection.client import probe_login
from feelmysign.errors import BrokerError
from feelmysign.lifecycle import Started
from feelmysign.topics import LEGACY_TOPIC

REPO = Path(__file__).resolve().parents[4]
DEPLOY_DIR = REPO / "deploy" / "nats"
TLS_CONF, LOOPBACK_CONF = "node.conf", "node-loopback.conf"
NATS_SERVER_ENV = "FEELMYSIGN_NATS_SERVER"
DEFAULT_NATS_SERVER = REPO / ".cache" / "go-bin" / "nats-server"
NODE_NAMES = ("a", "b", "c")
# JetStream elects its meta leader and creates the MQTT streams (R3) after the routes are up:
# seconds on an idle machine; the limit is for a machine busy with other work, which only
# a failure waits for.
READY_TIMEOUT_S = 120.0
READY_POLL_S = 0.2
# One MQTT login of the readiness check: the first creates the MQTT streams, each a request
# to JetStream that times out after 5 s (nats-server's default for MQTT).
PROBE_TIMEOUT_S = 10.0
MONITOR_TIMEOUT_S = 5.0
STOP_TIMEOUT_S = 10.0
# Each node's ports are picked free, but another program may take one before the node binds
# it (the node then stops at once, "address already in use"): the cluster is started again
# on other ports, this many times in all.
PORT_ATTEMPTS = 3


@dataclass(frozen=True)
class NatsNode:
    name: str
    client_port: int
    cluster_port: int
    mqtt_port: int
    ws_port: int
    tls: bool = False
    # nats-server's HTTP monitoring (/healthz, /jsz) on 127.0.0.1; None: not served
    monitor_port: int | None = None

    @property
    def mqtt_url(self) -> str:
        return f"{'mqtts' if self.tls else 'mqtt'}://127.0.0.1:{self.mqtt_port}"

    @property
    def ws_url(self) -> str:
        return f"{'wss' if self.tls else 'ws'}://127.0.0.1:{self.ws_port}/mqtt"


def nats_server_path() -> Path:
    """The pinned nats-server that ``make nats`` builds; BrokerError saying how if missing."""
    path = Path(os.environ.get(NATS_SERVER_ENV) or DEFAULT_NATS_SERVER)
    if not path.is_file():
        raise BrokerError(
            "nats-missing",
            f"nats-server was not found at {path}: run 'make nats' in the repository (it "
            f"builds nats-server v2.15.2 with go), or set ${NATS_SERVER_ENV}.",
        )
    return path


class NatsCluster(Started):
    """Three nats-server processes on 127.0.0.1 with JetStream, MQTT and MQTT over WebSockets."""

    def __init__(
        self,
        state_dir: Path,
        credentials: Credentials,
        *,
        other_sleeves: dict[str, Account] | None = None,
        tls: TlsFiles | None = None,
    ) -> None:
        self.state_dir = state_dir
        self.credentials = credentials
        self.tls = tls
        self._others = other_sleeves or {}
        self.nodes: list[NatsNode] = []
        self._processes: list[subprocess.Popen[bytes] | None] = []

    @property
    def mqtt_urls(self) -> str:
        return ",".join(node.mqtt_url for node in self.nodes)

    def start(self) -> None:
        executable = nats_server_path()
        self.state_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
        for conf in DEPLOY_DIR.glob("*.conf"):
            shutil.copyfile(conf, self.state_dir / conf.name)
        accounts = render_nats_accounts(self.credentials, self._others, legacy_topic=LEGACY_TOPIC)
        write_private_file(self.state_dir / "accounts.conf", accounts)
        for attempt in range(1, PORT_ATTEMPTS + 1):
            self.nodes = self._free_nodes()
            try:
                self._processes = [self._spawn(executable, node) for node in self.nodes]
                self._wait_ready()
                return
            except BrokerError as error:
                self.stop()
                if attempt == PORT_ATTEMPTS or "address already in use" not in str(error):
                    raise
            except BaseException:
                self.stop()
                raise

    def _free_nodes(self) -> list[NatsNode]:
        free = process_.free_port
        return [
            NatsNode(
                name,
                free("127.0.0.1"),
                free("127.0.0.1"),
                free("127.0.0.1"),
                free("127.0.0.1"),
                tls=self.tls is not None,
                monitor_port=free("127.0.0.1"),
            )
            for name in NODE_NAMES
        ]

    def _spawn(self, executable: Path, node: NatsNode) -> subprocess.Popen[bytes]:
        others = [n for n in self.nodes if n is not node]
        return self.spawn(executable, node, others, self.tls)

    def spawn(
        self,
        executable: Path,
        node: NatsNode,
        routes_to: list[NatsNode],
        tls: TlsFiles | None,
        *args: str,
    ) -> subprocess.Popen[bytes]:
        """nats-server for ``node``, with its routes to two ``routes_to``, on this cluster's
        configuration and TLS files ``tls`` (its CA trusted on the routes), with the
        command-line options ``args``. Not one of ``nodes``: for a test of a server trying
        to join the cluster."""
        if tls is not None and tls.ca is None:
            raise BrokerError("tls", "the routes need a CA of the cluster's own to trust")
        env = {
            **os.environ,
            "NODE_NAME": node.name,
            "BIND_HOST": "127.0.0.1",
            "CLIENT_PORT": str(node.client_port),
            "CLUSTER_PORT": str(node.cluster_port),
            "MQTT_PORT": str(node.mqtt_port),
            "WS_PORT": str(node.ws_port),
            "STORE_DIR": str(self.state_dir / f"store-{node.name}"),
            "ROUTE_1": f"nats-route://127.0.0.1:{routes_to[0].cluster_port}",
            "ROUTE_2": f"nats-route://127.0.0.1:{routes_to[1].cluster_port}",
        }
        if tls is not None:
            cert, key = str(tls.cert), str(tls.key)
            env |= {"TLS_CERT": cert, "TLS_KEY": key, "ROUTE_CERT": cert, "ROUTE_KEY": key}
            env["ROUTE_CA"] = str(tls.ca)
        conf = TLS_CONF if tls is not None else LOOPBACK_CONF
        if node.monitor_port is not None:
            args = ("-m", str(node.monitor_port), *args)  # on the node's host, 127.0.0.1
        log = (self.state_dir / f"{node.name}.log").open("ab")
        with log:
            return subprocess.Popen(
                [str(executable), "-c", str(self.state_dir / conf), *args],
                env=env,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=log,
                start_new_session=True,
                # Killed with us: a test that dies must not leave a cluster behind.
                preexec_fn=process_._parent_death_signal(os.getpid()),
            )

    def _wait_ready(self) -> None:
        """Until the cluster is settled (see the top of this module), each step a condition."""
        deadline = time.monotonic() + READY_TIMEOUT_S
        indexes = range(len(self.nodes))
        self._until(
            deadline,
            self._meta_settled,
            "JetStream has no meta leader that sees every node current",
        )
        for index in indexes:
            self._until(
                deadline,
                functools.partial(self._accepts_login, index),
                f"nats-server {self.nodes[index].name} took no MQTT login",
            )
        self._until(
            deadline,
            lambda: all(self._monitor(index, "healthz") is not None for index in indexes),
            "the MQTT streams are not current on every node",
        )

    def _until(self, deadline: float, condition: Callable[[], bool], what: str) -> None:
        while True:
            for index, process in enumerate(self._processes):
                if process is not None and process.poll() is not None:
                    raise BrokerError(
                        "start-failed",
                        f"nats-server {self.nodes[index].name} exited: {self.log(index)}",
                    )
            if condition():
                return
            if time.monotonic() > deadline:
                logs = "\n".join(
                    f"--- {node.name}.log:\n{self.log(index)}"
                    for index, node in enumerate(self.nodes)
                )
                raise BrokerError(
                    "start-failed", f"{what} after {READY_TIMEOUT_S:g} s; the logs end:\n{logs}"
                )
            time.sleep(READY_POLL_S)

    def _monitor(self, index: int, endpoint: str) -> dict[str, Any] | None:
        """Node ``index``'s answer on its monitoring port; None unless 200 OK (``/healthz``
        answers 503 while the node is not current)."""
        url = f"http://127.0.0.1:{self.nodes[index].monitor_port}/{endpoint}"
        try:
            with urllib.request.urlopen(url, timeout=MONITOR_TIMEOUT_S) as reply:
                answer = json.load(reply)
        except (OSError, ValueError):  # not listening yet, 503, a timeout, half an answer
            return None
        return answer if isinstance(answer, dict) else None

    def _meta_settled(self) -> bool:
        """Every node is current with one meta leader, and that leader has heard from the
        other nodes (by name) and sees them current: streams can be placed on all three."""
        indexes = range(len(self.nodes))
        if not all(self._monitor(i, "healthz?js-meta-only=true") is not None for i in indexes):
            return False
        for index in indexes:
            jsz = self._monitor(index, "jsz?leader-only=true")
            if jsz is None:
                continue  # not the leader (or gone): it answers 400
            meta = jsz.get("meta_cluster") or {}
            others = meta.get("replicas") or []
            names = {peer.get("name") for peer in others}
            return (
                len(others) == len(self.nodes) - 1
                and names <= set(NODE_NAMES)
                and all(peer.get("current") and not peer.get("offline") for peer in others)
            )
        return False

    def _accepts_login(self, index: int) -> bool:
        """Whether node ``index`` takes an MQTT login (the first one creates the MQTT streams;
        a refused one is tried again)."""
        node = self.nodes[index]
        sender = replace(self.credentials, mqtt_url=node.mqtt_url).settings("sender")
        if self.tls is not None:
            sender = replace(sender, ca_file=str(self.tls.ca) if self.tls.ca else None)
        probe_id = f"ready-{os.getpid()}"
        return bool(probe_login(sender, client_id=probe_id, timeout_s=PROBE_TIMEOUT_S, poll_s=0.1))

    def log(self, index: int) -> str:
        path = self.state_dir / f"{self.nodes[index].name}.log"
        return process_.log_tail(path)

    def kill(self, index: int) -> None:
        """SIGKILL node ``index``: a crash, not a shutdown."""
        process = self._processes[index]
        if process is not None:
            process.kill()
            process.wait()
            self._processes[index] = None

    def stop(self) -> None:
        # All three at once: each may take seconds to shut down with many sessions.
        for process in self._processes:
            if process is not None:
                process.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + STOP_TIMEOUT_S
        for index, process in enumerate(self._processes):
            if process is not None:
                try:
                    process.wait(timeout=max(0.1, deadline - time.monotonic()))
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
                self._processes[index] = None


def main(argv: list[str]) -> int:
    """Run a cluster in DIR until SIGINT/SIGTERM; print its URLs and accounts as one JSON line.

    SIGUSR1 kills node a.
    """
    state_dir = Path(argv[0] if argv else "nats-cluster").absolute()
    state_dir.mkdir(parents=True, exist_ok=True)
    path = state_dir / "credentials.json"
    credentials = (
        load_credentials(path)
        if path.exists()
        else reuse_or_create(path, sleeve_id="sleeve1", mqtt_url="mqtt://unused", ws_url="ws://x")
    )
    write_credentials(path, credentials)
    stop: list[int] = []
    kills: list[int] = []
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda number, _frame: stop.append(number))
    # SIGUSR1 kills node a (SIGKILL), as a crash would: the failover tests' trigger.
    signal.signal(signal.SIGUSR1, lambda number, _frame: kills.append(number))
    with NatsCluster(state_dir, credentials) as cluster:
        first, last = cluster.nodes[0], cluster.nodes[-1]
        credentials = replace(credentials, mqtt_url=first.mqtt_url, ws_url=last.ws_url)
        info = {
            "nodes": [
                {"name": n.name, "mqtt_url": n.mqtt_url, "ws_url": n.ws_url} for n in cluster.nodes
            ],
            "credentials": credentials.to_json(),
        }
        print(json.dumps(info), flush=True)
        print("Ready.", flush=True)
        while not stop:
            if kills:
                kills.clear()
                cluster.kill(0)
                print("Killed a.", flush=True)
            time.sleep(0.1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
