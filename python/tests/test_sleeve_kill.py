"""``kill -9`` of a real sleeve mid-stroke, then a restart: every motor it can reach is off.

The sleeve runs as its own process (``feelmysign sleeve --backend drv2605
--emulate-state FILE``) against a real Mosquitto. The state file is the
chips' registers, which outlive the process as real chips' do, so the test
sees what a crash leaves on the skin and what the restart does about it.
Timings are not asserted (``make bench`` reports the restart-to-all-off time);
the order is: the restarted sleeve switches every motor off before it says it
is online, and before it would refuse to start for a missing chip.
"""

from __future__ import annotations

import json
import signal
import subprocess
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from sleeve_watch import (
    SleeveWatch,
    exit_code_after,
    killed_with_its_guardian,
    online,
    reaped,
    settings,
)

from feelmysign.backends.emulated_state import drive_levels
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.connection import new_client
from feelmysign.daemon import sleeve_client_id
from feelmysign.stroke import Stroke

WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly


def sleeve_command(broker: Broker, state: Path) -> list[str]:
    return restart_off.sleeve_command(broker.credentials_path, state)


def start_sleeve(broker: Broker, state: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        sleeve_command(broker, state),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


@pytest.fixture
def watcher(broker: Broker) -> Iterator[SleeveWatch]:
    with SleeveWatch(broker.credentials, "status", "events") as watching:
        yield watching


def wait_until(condition: Callable[[], bool]) -> None:
    event = threading.Event()
    for _ in range(int(WAIT_S / 0.005)):
        if condition():
            return
        event.wait(0.005)
    raise AssertionError("the state file never got there")


def kill_mid_stroke(broker: Broker, watcher: SleeveWatch, state: Path) -> dict[str, float]:
    """Start a sleeve, send it a long stroke, SIGKILL it while a motor is on; what it left."""
    with reaped(start_sleeve(broker, state)) as sleeve:
        watcher.next(online, "the sleeve online")
        watcher.send(restart_off.LONG_STROKE)  # row 1, 8 s
        wait_until(lambda: any(level > 0 for level in drive_levels(state).values()))
        assert killed_with_its_guardian(sleeve) == -signal.SIGKILL
    left = drive_levels(state)
    # Nothing ran after SIGKILL: the chips still drive what they drove. Without
    # this the rest of the test would prove nothing.
    assert any(level > 0 for level in left.values()), left
    return left


def forget_sleeve_session(broker: Broker) -> None:
    """Drop the killed sleeve's session: the stroke cut by the kill was never acknowledged,
    so the broker would deliver it again at once (docs/protocol.md, Delivery) and drive a
    motor right after the restart; here only what comes before going online counts."""
    c = broker.credentials
    client_id = sleeve_client_id(c.sleeve_id, c.sleeve.password)
    client = new_client(settings(c, "sleeve"), client_id=client_id)  # a clean session replaces it
    connected = threading.Event()
    client.on_connect = lambda *args: connected.set()
    client.connect(c.mqtt_host, c.mqtt_port)
    client.loop_start()
    assert connected.wait(WAIT_S)
    client.disconnect()
    client.loop_stop()


def test_a_restart_after_sigkill_mid_stroke_switches_every_motor_off_before_going_online(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    kill_mid_stroke(broker, watcher, state)
    forget_sleeve_session(broker)

    with reaped(start_sleeve(broker, state)) as restarted:
        status = watcher.next(online, "the sleeve online")
        # Online is said only after the backend opened, so the off came first.
        assert status["backend"] == "drv2605 (emulated bus)"
        assert set(drive_levels(state).values()) == {0.0}
        # And the restarted sleeve plays again.
        watcher.send(Stroke((0.0, 0.0), (3.0, 0.0), 300.0, 0.9, "after", 0))
        # (The stroke cut by the kill was never acknowledged: the broker may deliver it again.)
        played = watcher.next(
            lambda name, body: body.get("type") == "played" and body.get("drawing") == "after",
            "the stroke after the restart played",
        )
        assert played["seq"] == 0
        assert exit_code_after(restarted, signal.SIGTERM) == 0
    assert set(drive_levels(state).values()) == {0.0}


@pytest.mark.parametrize("fault", ["missing", "wrong_id"])
def test_a_restart_with_one_bad_chip_refuses_to_start_but_switches_the_others_off(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path, fault: str
) -> None:
    state = tmp_path / "bus.json"
    left = kill_mid_stroke(broker, watcher, state)
    # A chip that is off fails (the one that plays could not be reached by anyone).
    bad = next(key for key, level in sorted(left.items()) if level == 0.0)
    saved = json.loads(state.read_text())
    if fault == "missing":
        del saved["chips"][bad]
    else:
        saved["chips"][bad]["device_id"] = 4  # a DRV2604
    state.write_text(json.dumps(saved))
    before = drive_levels(state)
    assert any(level > 0 for level in before.values())

    restarted = subprocess.run(
        sleeve_command(broker, state), capture_output=True, text=True, timeout=WAIT_S
    )
    assert restarted.returncode == 1
    multiplexer, channel = bad.split("/")
    assert f"multiplexer {multiplexer} channel {channel}" in restarted.stderr
    assert restarted.stderr.startswith("Error: ")
    assert "Traceback" not in restarted.stderr
    assert set(drive_levels(state).values()) == {0.0}
    # The same again, as systemd would restart it: still off, still the same error.
    again = subprocess.run(
        sleeve_command(broker, state), capture_output=True, text=True, timeout=WAIT_S
    )
    assert (again.returncode, again.stderr) == (1, restarted.stderr)
    assert set(drive_levels(state).values()) == {0.0}
