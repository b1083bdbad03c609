"""One process at a time on a sleeve's bus, with real processes: a real sleeve on the emulated
bus (``--emulate-state FILE``) against a real Mosquitto, and ``buzz``, ``scan``, ``off`` and a
second sleeve run beside it as the commands a sleeve builder types.

The emulated bus kept in a file takes the same lock as ``/dev/i2c-N`` (``FILE.lock``
beside it, :mod:`feelmysign.backends.bus_lock`), so what is checked here is what happens on
the hardware: ``buzz`` and ``scan`` refuse, naming the sleeve; ``off`` switches off all the
same and says that the sleeve drives the motors again; a second sleeve is refused; and a
``kill -9`` of the sleeve lets go of the bus at once.
"""

from __future__ import annotations

import os
import signal
import subprocess
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from lost_chip import paper_with_enable
from sleeve_watch import SleeveWatch, killed_with_its_guardian, online, reaped

from feelmysign.backends.bus_lock import holder_of, lock_for
from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_state import drive_levels, open_state_bus
from feelmysign.bench import restart_off
from feelmysign.broker import Broker
from feelmysign.layout import load_layout
from feelmysign.stroke import Stroke

WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly
PAPER = str(restart_off.PAPER)


def feelmysign(*arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*restart_off.feelmysign_command(), *arguments],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )


def start_sleeve(broker: Broker, state: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        restart_off.sleeve_command(broker.credentials_path, state),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_until(condition: Callable[[], bool], what: str) -> None:
    event = threading.Event()
    for _ in range(int(WAIT_S / 0.01)):
        if condition():
            return
        event.wait(0.01)
    raise AssertionError(f"never: {what}")


def driving(state: Path) -> bool:
    return any(level > 0 for level in drive_levels(state).values())


@pytest.fixture
def watcher(broker: Broker) -> Iterator[SleeveWatch]:
    with SleeveWatch(broker.credentials, "status", "events") as watching:
        yield watching


@pytest.fixture
def playing(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path
) -> Iterator[tuple[subprocess.Popen[str], Path]]:
    """A real sleeve online on the emulated bus in ``bus.json``, playing an 8 s stroke."""
    state = tmp_path / "bus.json"
    with reaped(start_sleeve(broker, state)) as sleeve:
        watcher.next(online, "the sleeve online")
        watcher.send(restart_off.LONG_STROKE)  # row 1, 8 s
        wait_until(lambda: driving(state), "a motor driven by the sleeve")
        yield sleeve, state


def refused_naming(result: subprocess.CompletedProcess[str], sleeve: subprocess.Popen[str]) -> str:
    """The one ``Error:`` line of a command refused because ``sleeve`` holds the bus."""
    assert result.returncode == 1, result
    assert result.stderr.startswith("Error: "), result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    message = result.stderr
    assert "is in use by a running sleeve" in message
    assert f"process {sleeve.pid} (feelmysign sleeve --backend drv2605" in message
    # Not the systemd service here: Ctrl-C or kill, with its PID.
    assert f"Ctrl-C where it runs, or 'kill {sleeve.pid}'" in message
    return message


def test_buzz_and_scan_refuse_while_a_sleeve_plays_naming_it_and_touch_nothing(
    playing: tuple[subprocess.Popen[str], Path], watcher: SleeveWatch
) -> None:
    sleeve, state = playing
    buzz = feelmysign(
        "buzz", "0", "0", "--layout", PAPER, "--emulate-state", str(state), "--duration-ms", "200"
    )
    assert "Nothing was buzzed." in refused_naming(buzz, sleeve)
    assert "Buzzing" not in buzz.stdout

    scan = feelmysign("scan", "--layout", PAPER, "--emulate-state", str(scan_state := state))
    assert "Nothing was scanned." in refused_naming(scan, sleeve)
    assert scan.stdout == ""
    assert scan_state.exists()

    # Neither took anything from the sleeve: it plays its stroke to the end, and runs on.
    watcher.next(
        lambda name, body: body.get("type") == "played" and body.get("drawing") == "bench-kill",
        "the long stroke played to its end",
    )
    assert sleeve.poll() is None


def test_off_is_never_refused_it_switches_off_and_says_the_sleeve_drives_again(
    playing: tuple[subprocess.Popen[str], Path], watcher: SleeveWatch
) -> None:
    sleeve, state = playing
    off = feelmysign("off", "--layout", PAPER, "--emulate-state", str(state))
    assert off.returncode == 1, off
    assert off.stdout.startswith("Every motor is off for now (12 DRV2605L on the emulated bus")
    assert off.stderr.startswith("Error: A sleeve runs on this bus, ")
    assert f"process {sleeve.pid} (feelmysign sleeve --backend drv2605" in off.stderr
    assert "drives the motors again with its next stroke" in off.stderr
    assert f"'kill {sleeve.pid}'" in off.stderr
    assert "Traceback" not in off.stderr

    # What off said is so: the sleeve runs on and plays the next stroke.
    assert sleeve.poll() is None
    watcher.send(Stroke((0.0, 0.0), (3.0, 0.0), 300.0, 0.9, "after-off", 0))
    watcher.next(
        lambda name, body: body.get("type") == "played" and body.get("drawing") == "after-off",
        "the stroke after off played",
    )


def test_a_second_sleeve_on_the_same_bus_is_refused_and_the_first_plays_on(
    broker: Broker, playing: tuple[subprocess.Popen[str], Path], watcher: SleeveWatch
) -> None:
    first, state = playing
    second = subprocess.run(
        restart_off.sleeve_command(broker.credentials_path, state),
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert "This sleeve does not start" in refused_naming(second, first)
    # It never reached the broker: the first sleeve keeps its session and plays on.
    assert first.poll() is None
    watcher.send(Stroke((0.0, 0.0), (3.0, 0.0), 300.0, 0.9, "after-second", 0))
    watcher.next(
        lambda name, body: body.get("type") == "played" and body.get("drawing") == "after-second",
        "the first sleeve still plays",
    )


def test_kill_9_of_the_sleeve_lets_go_of_the_bus_at_once(
    playing: tuple[subprocess.Popen[str], Path],
) -> None:
    sleeve, state = playing
    lock_file = f"{state}.lock"
    held = holder_of(lock_file)
    assert held is not None and (held.pid, held.role) == (sleeve.pid, "sleeve")

    assert killed_with_its_guardian(sleeve) == -signal.SIGKILL
    assert holder_of(lock_file) is None
    assert driving(state)  # nothing ran after the kill: the chips drive what they drove
    assert Path(lock_file).exists()  # the file stays; the lock went with the process

    buzz = feelmysign(
        "buzz", "0", "0", "--layout", PAPER, "--emulate-state", str(state), "--duration-ms", "50"
    )
    assert buzz.returncode == 0, buzz
    assert "Every motor is off." in buzz.stdout
    # buzz's start switched off what the killed sleeve left on, and so did its end.
    assert not driving(state)
    off = feelmysign("off", "--layout", PAPER, "--emulate-state", str(state))
    assert (off.returncode, off.stderr) == (0, "")
    assert off.stdout.startswith("Every motor is off (12 DRV2605L")


def test_a_sleeve_starting_on_a_held_bus_switches_every_motor_off_first_then_refuses(
    broker: Broker, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    layout = load_layout(PAPER)
    backend = Drv2605Backend(layout, bus=open_state_bus(state, layout))
    backend.open()
    backend.set_intensity(1, 1, 1.0)  # left on by a sleeve that died
    holder = lock_for(layout.i2c_bus, state)  # and a process that holds the bus now
    assert holder.try_acquire("sleeve") is None
    try:
        started = subprocess.run(
            restart_off.sleeve_command(broker.credentials_path, state),
            capture_output=True,
            text=True,
            timeout=WAIT_S,
        )
    finally:
        holder.release()
    assert started.returncode == 1, started
    assert started.stderr.startswith("Error: The emulated I2C bus in ")
    assert f"in use by a running sleeve, process {os.getpid()} " in started.stderr
    assert "This sleeve does not start: one bus drives one sleeve." in started.stderr
    assert "Traceback" not in started.stderr
    # The restart's all-off came first, whatever holds the bus (make bench's restart path).
    assert not driving(state)


def test_off_beside_a_sleeve_holding_the_enable_line_names_the_sleeve_as_without_one(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path
) -> None:
    """The enable line guarded part of this before the lock (off could not take the line);
    now the words are the lock's, with the line's own problem listed."""
    state, layout = tmp_path / "bus.json", paper_with_enable(tmp_path)
    command = restart_off.sleeve_command(broker.credentials_path, state)
    command[command.index("--layout") + 1] = str(layout)
    with reaped(
        subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    ) as sleeve:
        watcher.next(online, "the sleeve online")
        off = feelmysign("off", "--layout", str(layout), "--emulate-state", str(state))
        buzz = feelmysign("buzz", "0", "0", "--layout", str(layout), "--emulate-state", str(state))
        assert sleeve.poll() is None
    print(off.stdout, off.stderr, sep="\n")
    assert off.returncode == 1, off
    assert off.stdout.startswith("The off went out to every chip that answered (12 DRV2605L on ")
    assert f"in use by process {sleeve.pid}" in off.stdout  # the line: the sleeve holds it
    assert off.stderr.startswith(f"Error: A sleeve runs on this bus, process {sleeve.pid} (")
    assert "Traceback" not in off.stderr
    assert "Nothing was buzzed." in refused_naming(buzz, sleeve)
