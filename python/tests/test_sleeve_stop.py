"""Stopping the sleeve: the last actuators frame says every motor is off, and paho's thread
race at stop cannot take the sleeve down."""

from __future__ import annotations

import signal
import subprocess
import threading
import types
import uuid
from collections.abc import Callable, Iterator
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from sleeve_watch import SleeveWatch, online, settings

from feelmysign.backends.sim import SimBackend
from feelmysign.bench.sleeve import sleeve_command
from feelmysign.broker import Broker
from feelmysign.connection import new_client
from feelmysign.daemon import NETWORK_STOP_S, Sleeve, SleeveOptions
from feelmysign.layout import Layout
from feelmysign.stroke import Stroke

WAIT_S = 60.0
PAPER = Layout(rows=3, columns=4, spacing_cm=3.0)


@pytest.fixture
def watch(broker: Broker) -> Iterator[SleeveWatch]:
    with SleeveWatch(broker.credentials, "status", "actuators") as watching:
        yield watching


def _on(name: str, body: dict[str, Any]) -> bool:
    return name == "actuators" and any(any(row) for row in body["intensities"])


def test_sigterm_mid_stroke_publishes_an_all_off_frame_before_going_offline(
    broker: Broker, watch: SleeveWatch
) -> None:
    sleeve = subprocess.Popen(
        sleeve_command(broker.credentials_path, "--no-legacy"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        watch.next(online, "the sleeve online")
        watch.send(Stroke((0, 1), (3, 1), 8000.0, 0.9, "stop", 0))
        watch.next(_on, "a motor on")
        sleeve.send_signal(signal.SIGTERM)
        _, errors = sleeve.communicate(timeout=WAIT_S)
    finally:
        sleeve.kill()
    assert sleeve.returncode == 0, errors
    watch.next(lambda n, body: n == "status" and not body["online"], "the sleeve offline")
    with watch._changed:
        messages = list(watch.history)
    offline = next(i for i, (n, b) in enumerate(messages) if n == "status" and not b["online"])
    frames = [body for name, body in messages[:offline] if name == "actuators"]
    assert any(_on("actuators", frame) for frame in frames)  # the stroke was playing
    assert not _on("actuators", frames[-1]), frames[-1]  # and the last word is: all off


# How long paho's ending network thread is held before it clears its handle: far longer
# than a caller takes from disconnect() to loop_stop(), far shorter than NETWORK_STOP_S.
HOLD_S = 2.0


class _RaceGate:
    """Widens, to certainty, the moment between loop_stop's two reads of paho's network
    thread, which a loaded machine hits by chance.

    paho's thread clears ``client._thread`` as it ends. Held here, an ending thread keeps
    its handle (up to HOLD_S) until some caller's loop_stop has read it once; that caller's
    ``threading.current_thread()`` then waits for the thread to end, so loop_stop's second
    read finds None. A caller that joins the thread itself, as the sleeve does, never
    enters loop_stop while the thread lives, and the held thread ends after HOLD_S."""

    def __init__(self) -> None:
        self._read = threading.Event()

    def thread_main(self) -> Callable[[mqtt.Client], None]:
        """paho's ``Client._thread_main``, holding its last step."""
        return lambda client: self._thread_main(client)

    def _thread_main(self, client: mqtt.Client) -> None:
        try:
            client.loop_forever(retry_first_connection=True)
        finally:
            self._read.wait(HOLD_S)
            client._thread = None

    def threading_module(self) -> types.SimpleNamespace:
        names = [k for k in dir(threading) if k[0] != "_" and k != "current_thread"]
        return types.SimpleNamespace(
            current_thread=self._current_thread, **{k: getattr(threading, k) for k in names}
        )

    def _current_thread(self) -> threading.Thread:
        me = threading.current_thread()
        self._read.set()
        for thread in threading.enumerate():
            if thread is not me and thread.name.startswith("paho-mqtt-client-"):
                thread.join(WAIT_S)
        self._read.clear()
        return me


def test_paho_loop_stop_after_disconnect_races_its_thread_and_the_sleeve_never_hits_it(
    broker: Broker, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert HOLD_S < NETWORK_STOP_S
    c = broker.credentials
    gate = _RaceGate()
    monkeypatch.setattr(mqtt.Client, "_thread_main", gate.thread_main())
    monkeypatch.setattr(mqtt, "threading", gate.threading_module())
    # The race itself, with a bare client: what a sleeve stopped this way would hit.
    bare = new_client(settings(c, "sender"), client_id=f"race-{uuid.uuid4()}")
    bare.connect(c.mqtt_host, c.mqtt_port)
    bare.loop_start()
    bare.disconnect()
    with pytest.raises(AttributeError):
        bare.loop_stop()

    sleeve = Sleeve(
        settings(c, "sleeve"), PAPER, SimBackend(PAPER), SleeveOptions(sleeve_id=c.sleeve_id)
    )
    errors: list[BaseException] = []

    def run() -> None:
        try:
            sleeve.run()
        except BaseException as error:
            errors.append(error)

    thread = threading.Thread(target=run)
    thread.start()
    assert sleeve.connected.wait(WAIT_S)
    sleeve.stop()
    thread.join(WAIT_S)
    assert not thread.is_alive() and errors == []
