"""The sleeve compares its clock with the broker's at start (feelmysign/clock, retained with an
MQTT 5 expiry the broker counts down): a real Mosquitto started by ``feelmysign broker``'s
code, a real ``feelmysign sleeve`` process, and a broker machine whose clock is a minute off,
as its clock message says."""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import threading
import time

from paho.mqtt.packettypes import PacketTypes
from paho.mqtt.properties import Properties
from sleeve_watch import SleeveWatch, online, settings, stop_loop

from feelmysign.bench.restart_off import feelmysign_command
from feelmysign.broker import Broker
from feelmysign.broker_clock import CLOCK_EXPIRY_S
from feelmysign.connection import connect_client
from feelmysign.topics import CLOCK_TOPIC

WAIT_S = 60.0


def sleeve_log(broker: Broker) -> str:
    """What a sleeve (sim) logs from its start until it is online and has checked its clock."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    with SleeveWatch(broker.credentials, "status") as watcher:
        sleeve = subprocess.Popen(
            [*feelmysign_command(), "sleeve", "--credentials", str(broker.credentials_path)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        lines: queue.Queue[str] = queue.Queue()
        assert sleeve.stderr is not None
        stream = sleeve.stderr

        def read() -> None:
            for line in stream:
                lines.put(line)

        reader = threading.Thread(target=read)
        reader.start()
        seen: list[str] = []
        try:
            watcher.next(online, "the sleeve online")
            # The check runs beside the start, on a connection of its own: its line comes.
            while not any("clock" in line for line in seen):
                seen.append(lines.get(timeout=WAIT_S))
        finally:
            sleeve.send_signal(signal.SIGTERM)
            sleeve.wait(WAIT_S)
            reader.join(WAIT_S)
    while not lines.empty():
        seen.append(lines.get())
    return "".join(seen)


def test_a_sleeve_on_time_says_so(broker: Broker) -> None:
    log = sleeve_log(broker)
    assert "sleeve sleeve1: clock within" in log and "of the broker's" in log, log
    assert "WARNING" not in log, log


def test_a_clock_a_minute_off_the_broker_s_is_a_warning_at_start(broker: Broker) -> None:
    # The broker's machine says it took its clock a minute ago... at the time ours says now:
    # its time now is a minute ahead of ours, so ours is a minute behind.
    client = connect_client(settings(broker.credentials, "sender"), "test-clock")
    try:
        properties = Properties(PacketTypes.PUBLISH)  # type: ignore[no-untyped-call]
        properties.MessageExpiryInterval = CLOCK_EXPIRY_S - 60
        payload = json.dumps({"at_ms": round(time.time() * 1000), "expiry_s": CLOCK_EXPIRY_S})
        sent = client.publish(CLOCK_TOPIC, payload, qos=1, retain=True, properties=properties)
        sent.wait_for_publish(WAIT_S)
    finally:
        client.disconnect()
        stop_loop(client)
    log = sleeve_log(broker)
    warning = [line for line in log.splitlines() if "WARNING" in line and "clock" in line]
    assert len(warning) == 1, log
    # A minute, to within the whole seconds the broker counts the interval in.
    seconds = float(warning[0].split("this machine's clock is ", 1)[1].split(" s ", 1)[0])
    assert 58.5 <= seconds <= 62.5, warning
    assert "behind the broker's, more than the 10 s" in warning[0], warning
    assert "timedatectl" in warning[0]
