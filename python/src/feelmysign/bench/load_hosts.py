"""The worker processes of the load bench: each hosts a share of the sleeves, senders or receivers.

N sleeves in one Python process measure that process (one interpreter lock for N
players, N network loops and N event publishers) more than the broker: at N = 100 it
fell seconds behind and refused most strokes as late. So the bench spreads every kind
of client over processes of ``PER_PROCESS`` clients each, started with ``spawn`` (a
fresh interpreter, no inherited threads or sockets). A process talks to the bench over
one queue, as ``(kind, payload)``:

- ``("ready", count)`` once its clients are logged in (and subscribed);
- ``("error", message)`` when it could not start them;
- a sender host: ``("sent", {key: sent_at_ms}, [keys the broker never acknowledged])``;
- a receiver host: ``("arrived", {key: arrival_ms})`` batches while it runs;
- a sleeve host, once its sleeves stopped: ``("cpu", seconds)``, the processor time its
  sleeves used from ``ready`` on (every thread: players, network loops, events).

A stroke's key is ``drawing/seq``.
"""

from __future__ import annotations

import json
import logging
import resource
import sys
import threading
import time
import traceback
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from typing import Any

import paho.mqtt.client as mqtt

from feelmysign.backends.sim import SimBackend
from feelmysign.broker.credentials import Account
from feelmysign.connection import new_client, parse_broker_url
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.protocol import format_json
from feelmysign.stroke import Stroke
from feelmysign.topics import strokes_topic

PER_PROCESS = 40  # clients of one kind per process: a few processes per core at N = 200
STROKES = 10  # per sender: one short drawing
STROKE_MS = 100.0  # each stroke's duration, and the pause between two (a quick hand)
CONNECT_S = 120.0  # N logins (and, on NATS, N durable sessions) on a loaded machine
PUBACK_S = 60.0  # the longest a sender waits for the broker to acknowledge its strokes
FLUSH_S = 0.2  # how often a receiver host sends what arrived
DEFAULT_SWITCH_INTERVAL_S = sys.getswitchinterval()  # Python's own, before a player lowers it

Reports = Any  # a multiprocessing queue (its type is not public)
Flag = Any  # a multiprocessing Event


def stroke_key(payload: bytes) -> str | None:
    try:
        data = json.loads(payload)
    except ValueError:
        return None
    if not isinstance(data, dict) or "drawing" not in data or "seq" not in data:
        return None
    return f"{data['drawing']}/{data['seq']}"


def _quiet() -> None:
    # The sleeves' own log lines (a stroke delayed on the way, ...) would bury the figures.
    logging.getLogger("feelmysign").setLevel(logging.ERROR)


@contextmanager
def _reporting(reports: Reports) -> Iterator[None]:
    """Any failure of a host goes to the bench as ("error", ...), never as a silent exit."""
    try:
        yield
    except BaseException as error:  # reported, then the process ends
        reports.put(("error", f"{type(error).__name__}: {error}\n{traceback.format_exc()}"))


def _connect_all(
    logins: list[tuple[str, str, Account, str]],
    on_message: Callable[[Any, Any, mqtt.MQTTMessage], None] | None = None,
    subscribe: Callable[[str], str | None] = lambda _sleeve_id: None,
) -> list[mqtt.Client]:
    """Log every (URL, client id, account, sleeve id) in at once, subscribed where asked.

    The clients come back in the order of ``logins``.
    """
    clients: list[mqtt.Client] = []
    ready: list[threading.Event] = []
    for url, client_id, account, sleeve_id in logins:
        settings = parse_broker_url(
            url, username=account.username, password=account.password, sleeve_id=sleeve_id
        )
        client = new_client(settings, client_id=client_id)
        done = threading.Event()
        topic = subscribe(sleeve_id)
        if topic is None:
            client.on_connect = lambda *_args, done=done: done.set()
        else:
            client.on_connect = lambda c, *_args, topic=topic: c.subscribe(topic, qos=1)
            client.on_subscribe = lambda *_args, done=done: done.set()
        if on_message is not None:
            client.on_message = on_message
        client.connect_async(settings.host, settings.port)
        client.loop_start()
        clients.append(client)
        ready.append(done)
    deadline = time.monotonic() + CONNECT_S
    for (url, client_id, _account, _sleeve), done in zip(logins, ready, strict=True):
        if not done.wait(max(0.0, deadline - time.monotonic())):
            raise TimeoutError(f"{client_id} could not log in to {url} within {CONNECT_S:g} s")
    return clients


def _close(clients: list[mqtt.Client]) -> None:
    """Log every client out; their network threads end by themselves with the process.

    paho's loop_stop() waits for one client's thread at a time, up to a second each:
    minutes for a few hundred clients.
    """
    for client in clients:
        client.disconnect()


def sleeve_host(
    urls: list[str],
    sleeves: list[tuple[str, Account]],
    tuning: dict[str, float],
    reports: Reports,
    stop: Flag,
) -> None:
    """Run ``sleeves`` (sleeve id, account) as sleeve daemons on the simulator until ``stop``.

    Sleeve i connects to ``urls[i]`` first (the server list, rotated, on a cluster).
    ``tuning``: SleeveOptions fields (max_age_ms, max_lag_ms, spin_ms) instead of the
    sleeve's defaults.
    """
    _quiet()
    running: list[tuple[Sleeve, threading.Thread, SimBackend]] = []
    with _reporting(reports):
        for url, (sleeve_id, account) in zip(urls, sleeves, strict=True):
            settings = parse_broker_url(
                url, username=account.username, password=account.password, sleeve_id=sleeve_id
            )
            backend = SimBackend(PAPER_SLEEVE)
            options = SleeveOptions(sleeve_id=sleeve_id, legacy_topic=None)
            options = replace(
                options,
                max_age_ms=tuning.get("max_age_ms", options.max_age_ms),
                max_lag_ms=tuning.get("max_lag_ms", options.max_lag_ms),
                spin_ms=tuning.get("spin_ms", options.spin_ms),
            )
            sleeve = Sleeve(settings, PAPER_SLEEVE, backend, options)
            thread = threading.Thread(target=sleeve.run, daemon=True)
            thread.start()
            running.append((sleeve, thread, backend))
        deadline = time.monotonic() + CONNECT_S
        for sleeve, _thread, _backend in running:
            if not sleeve.connected.wait(max(0.0, deadline - time.monotonic())):
                raise TimeoutError(f"a sleeve could not subscribe within {CONNECT_S:g} s")
        # Each player lowers the interpreter's switch interval to 0.2 ms, so that on a Pi,
        # where it is alone, a stroke's first command follows its message at once. With
        # PER_PROCESS sleeves in one process, 3 threads each, that many hand-overs tripled
        # the processor time a stroke costs (4.2 instead of 1.4 ms at N = 100) and made
        # the sleeves fall behind: back to Python's default here.
        sys.setswitchinterval(DEFAULT_SWITCH_INTERVAL_S)
        reports.put(("ready", len(running)))
        started_s = _cpu_s()
        stop.wait()
    for sleeve, _thread, _backend in running:
        sleeve.stop()
    for _sleeve, thread, backend in running:
        thread.join(10)
        backend.close()
    if running:
        reports.put(("cpu", _cpu_s() - started_s))


def _cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def receiver_host(
    urls: list[str], sleeves: list[tuple[str, Account]], reports: Reports, stop: Flag
) -> None:
    """Bare receivers, each logged in as its sleeve, subscribed to its strokes, until ``stop``."""
    arrived: dict[str, float] = {}
    lock = threading.Lock()

    def on_message(_client: Any, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        now_ms = time.time_ns() / 1e6
        key = stroke_key(bytes(message.payload))
        if key is not None:
            with lock:
                arrived.setdefault(key, now_ms)

    def flush() -> None:
        with lock:
            batch = dict(arrived)
            arrived.clear()
        if batch:
            reports.put(("arrived", batch))

    clients: list[mqtt.Client] = []
    with _reporting(reports):
        logins = [
            (url, f"bare-{i}-{uuid.uuid4()}", account, i)
            for url, (i, account) in zip(urls, sleeves, strict=True)
        ]
        clients = _connect_all(logins, on_message, strokes_topic)
        reports.put(("ready", len(clients)))
        while not stop.wait(FLUSH_S):
            flush()
        flush()
    _close(clients)


def sender_host(
    urls: list[str],
    sender: Account,
    sleeve_ids: list[str],
    reports: Reports,
    go: Flag,
) -> None:
    """One sender per sleeve id; at ``go`` all draw at once, then report what they sent."""
    clients: list[mqtt.Client] = []
    with _reporting(reports):
        logins = [
            (url, f"sender-{i}-{uuid.uuid4()}", sender, i)
            for url, i in zip(urls, sleeve_ids, strict=True)
        ]
        clients = _connect_all(logins)
        reports.put(("ready", len(clients)))
        go.wait()
        sent, infos = _draw_all(clients, sleeve_ids)
        deadline = time.monotonic() + PUBACK_S
        for info in infos.values():
            info.wait_for_publish(max(0.1, deadline - time.monotonic()))
        unacknowledged = [key for key, info in infos.items() if not info.is_published()]
        reports.put(("sent", sent, unacknowledged))
    _close(clients)


def _draw_all(
    clients: list[mqtt.Client], sleeve_ids: list[str]
) -> tuple[dict[str, float], dict[str, mqtt.MQTTMessageInfo]]:
    """Every client draws STROKES strokes to its sleeve at once, at a hand's pace."""
    sent: dict[str, float] = {}
    infos: dict[str, mqtt.MQTTMessageInfo] = {}
    lock = threading.Lock()

    def draw(client: mqtt.Client, sleeve_id: str) -> None:
        drawing = str(uuid.uuid4())
        for seq in range(STROKES):
            now_ms = time.time_ns() / 1e6
            stroke = replace(
                Stroke((0.0, 1.0), (1.0, 1.0), STROKE_MS, 0.5, drawing, seq), sent_at_ms=now_ms
            )
            info = client.publish(strokes_topic(sleeve_id), format_json(stroke), qos=1)
            with lock:
                sent[f"{drawing}/{seq}"] = now_ms
                infos[f"{drawing}/{seq}"] = info
            time.sleep(STROKE_MS / 1000)

    threads = [
        threading.Thread(target=draw, args=(client, sleeve_id))
        for client, sleeve_id in zip(clients, sleeve_ids, strict=True)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return sent, infos
