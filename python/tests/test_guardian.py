"""The sleeve's guardian (feelmysign.guard): a sleeve killed or stopped mid-stroke, and no
restart, no systemd: every motor it drove goes off within a second all the same.

Each sleeve is a process of its own (``feelmysign sleeve --backend drv2605 --emulate-state
FILE``) against a real Mosquitto; the state file is the chips' registers, which outlive the
sleeve as real chips' do. Without the guardian every one of these tests fails: the motors
run on after ``kill -9`` and through a stop, and no guardian process is found.
"""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from sleeve_watch import SleeveWatch, online, reaped

from feelmysign.backends.emulated_state import drive_levels
from feelmysign.bench import restart_off
from feelmysign.broker import Broker, load_credentials
from feelmysign.guard import STOPPED_S, guardian_pids, process_state
from feelmysign.stroke import Stroke

WAIT_S = 60.0  # generous: a loaded 2-core machine starts Python slowly
OFF_WITHIN_S = 1.0  # after a kill, or a stop: every motor off within this, or the test fails
GUARDIAN_MARK = "feelmysign.guard"


def guardians_anywhere(sleeve: int) -> list[int]:
    """Every guardian process on this machine that watches ``sleeve`` (as ps would list them)."""
    listed = subprocess.run(
        ["ps", "-eo", "pid=,stat=,args="], capture_output=True, text=True, check=True
    ).stdout
    found = []
    for line in listed.splitlines():
        pid, stat, *args = line.split()
        if stat.startswith("Z"):
            continue  # ended, not yet reaped: it runs nothing
        if GUARDIAN_MARK in line and str(sleeve) in args:
            found.append(int(pid))
    return found


def wait_until(condition: Callable[[], bool], what: str, within_s: float = WAIT_S) -> float:
    """Seconds until ``condition`` held; AssertionError naming ``what`` past ``within_s``."""
    started = time.monotonic()
    while not condition():
        if time.monotonic() - started > within_s:
            raise AssertionError(f"{what}: not within {within_s} s")
        time.sleep(0.005)
    return time.monotonic() - started


def driving(state: Path) -> bool:
    return any(level > 0 for level in drive_levels(state).values())


def start_sleeve(broker: Broker, state: Path, *, own_group: bool = False) -> subprocess.Popen[str]:
    """The sleeve; ``own_group``: leading a process group (and session) of its own, as a job."""
    return subprocess.Popen(
        restart_off.sleeve_command(broker.credentials_path, state),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=own_group,  # (process_group= needs Python 3.11)
    )


@pytest.fixture
def watcher(broker: Broker) -> Iterator[SleeveWatch]:
    with SleeveWatch(broker.credentials, "status", "events") as watching:
        yield watching


def playing(watcher: SleeveWatch, state: Path, stroke: Stroke) -> None:
    watcher.next(online, "the sleeve online")
    watcher.send(stroke)
    wait_until(lambda: driving(state), "a motor on")


def its_guardian(sleeve: subprocess.Popen[str]) -> int:
    found: list[int] = []

    def started() -> bool:
        found[:] = guardian_pids(sleeve.pid)
        return bool(found)

    wait_until(started, "the sleeve's guardian started", 10.0)
    assert len(found) == 1, found
    return found[0]


def test_a_sleeve_killed_mid_stroke_has_every_motor_switched_off_by_its_guardian(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    with reaped(start_sleeve(broker, state)) as sleeve:
        playing(watcher, state, restart_off.LONG_STROKE)  # 8 s
        guardian = its_guardian(sleeve)
        # Its own session: a Ctrl-C to the terminal's process group does not reach it.
        assert os.getsid(guardian) == guardian != os.getsid(sleeve.pid)
        sleeve.send_signal(signal.SIGKILL)
        took = wait_until(lambda: not driving(state), "every motor off", OFF_WITHIN_S)
        print(f"kill -9 -> every motor off: {took * 1000:.0f} ms")
        _, errors = sleeve.communicate(timeout=WAIT_S)  # EOF: the guardian has ended too
    assert set(drive_levels(state).values()) == {0.0}, took
    assert f"the sleeve (process {sleeve.pid}) ended without switching" in errors, errors
    wait_until(lambda: not guardians_anywhere(sleeve.pid), "the guardian ended", 5.0)


def test_a_stopped_sleeve_has_its_motors_switched_off_and_plays_on_once_continued(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path
) -> None:
    state = tmp_path / "bus.json"
    with reaped(start_sleeve(broker, state)) as sleeve:
        playing(watcher, state, Stroke((0.0, 1.0), (3.0, 1.0), 4000.0, 0.9, "long", 0))
        guardian = its_guardian(sleeve)
        os.kill(sleeve.pid, signal.SIGSTOP)
        took = wait_until(lambda: not driving(state), "every motor off", OFF_WITHIN_S)
        print(f"SIGSTOP -> every motor off: {took * 1000:.0f} ms")
        assert took >= STOPPED_S * 0.9  # not before the stop lasted STOPPED_S
        time.sleep(0.5)
        assert process_state(sleeve.pid) == "T"  # still stopped, and the motors stay off
        assert not driving(state)
        assert guardian_pids(sleeve.pid) == [guardian]  # it stays while its sleeve lives
        os.kill(sleeve.pid, signal.SIGCONT)
        # The sleeve goes on: a stroke sent now plays.
        watcher.send(Stroke((0.0, 0.0), (3.0, 0.0), 300.0, 0.9, "after", 0))
        played = watcher.next(
            lambda name, body: body.get("drawing") == "after", "the stroke after the stop"
        )
        assert played["type"] == "played", played
        sleeve.send_signal(signal.SIGTERM)
        _, errors = sleeve.communicate(timeout=WAIT_S)
        assert sleeve.returncode == 0, errors
    assert f"the sleeve (process {sleeve.pid}) stopped for" in errors, errors
    assert "Traceback" not in errors, errors
    assert set(drive_levels(state).values()) == {0.0}
    assert guardians_anywhere(sleeve.pid) == []


@pytest.mark.parametrize("how", ["SIGTERM", "Ctrl-C to its process group"])
def test_a_sleeve_stopped_cleanly_dismisses_its_guardian_which_leaves_the_bus_alone(
    broker: Broker, watcher: SleeveWatch, tmp_path: Path, how: str
) -> None:
    state = tmp_path / "bus.json"
    with reaped(start_sleeve(broker, state, own_group=True)) as sleeve:
        playing(watcher, state, restart_off.LONG_STROKE)
        guardian = its_guardian(sleeve)
        if how == "SIGTERM":
            sleeve.send_signal(signal.SIGTERM)
        else:  # as a terminal's Ctrl-C: SIGINT to every process of the foreground group
            os.killpg(sleeve.pid, signal.SIGINT)
        _, errors = sleeve.communicate(timeout=WAIT_S)
        assert sleeve.returncode == 0, errors
    # The sleeve switched every motor off itself, then dismissed the guardian (and reaped it):
    # the guardian wrote nothing.
    assert set(drive_levels(state).values()) == {0.0}
    assert "feelmysign guardian" not in errors, errors
    assert process_state(guardian) is None  # gone, reaped by the sleeve
    assert guardians_anywhere(sleeve.pid) == []


def test_a_sleeve_of_the_simulator_starts_no_guardian(broker: Broker, watcher: SleeveWatch) -> None:
    command = restart_off.sleeve_command(broker.credentials_path, Path("unused"))
    at = command.index("--backend")
    del command[at : at + 4]  # --backend drv2605 --emulate-state FILE: the default, sim
    with reaped(
        subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, text=True)
    ) as sleeve:
        watcher.next(online, "the sleeve online")
        time.sleep(0.5)
        assert guardian_pids(sleeve.pid) == []


@pytest.mark.broker
def test_the_sleeve_of_up_on_an_emulated_bus_is_guarded_too(tmp_path: Path) -> None:
    """``feelmysign up --sleeve-backend drv2605``: its sleeve runs in up's process, which a
    Ctrl-Z stops whole; the guardian switches its motors off, and goes at Ctrl-C."""
    state = tmp_path / "bus.json"
    web = tmp_path / "web"
    web.mkdir()
    (web / "index.html").write_text("<!doctype html><title>feelmysign</title>\n")
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    env["XDG_STATE_HOME"] = str(tmp_path / "xdg")
    command = [
        *restart_off.feelmysign_command(),
        "up",
        *("--state-dir", str(tmp_path / "state"), "--web-dir", str(web)),
        *("--port", "0", "--ws-port", "0", "--http-port", "0"),
        *("--sleeve-backend", "drv2605", "--emulate-state", str(state)),
        *("--layout", str(restart_off.PAPER)),
    ]
    up = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env
    )
    output: list[str] = []
    try:
        assert up.stdout is not None
        for line in up.stdout:
            output.append(line)
            if line.startswith("Press Ctrl-C to stop."):
                break
        else:
            raise AssertionError("".join(output))
        threading.Thread(target=lambda: output.extend(up.stdout or ()), daemon=True).start()
        credentials = load_credentials(tmp_path / "state" / "credentials.json")
        with SleeveWatch(credentials, "status", "events") as watcher:
            watcher.send(restart_off.LONG_STROKE)
            wait_until(lambda: driving(state), "a motor on")
        guardian = its_guardian(up)
        os.kill(up.pid, signal.SIGSTOP)
        wait_until(lambda: not driving(state), "every motor off", OFF_WITHIN_S)
        os.kill(up.pid, signal.SIGCONT)
        up.send_signal(signal.SIGINT)
        assert up.wait(WAIT_S) == 0, "".join(output)
    finally:
        if up.poll() is None:
            up.kill()
            up.wait(WAIT_S)
    assert set(drive_levels(state).values()) == {0.0}
    assert process_state(guardian) is None
    assert guardians_anywhere(up.pid) == []
    # The banner says what drives the motors: not "simulated".
    assert "  Sleeve:      sleeve1 (DRV2605L chips over I2C)\n" in output, "".join(output)


GUARDIAN_PROBE = """
import os, sys
sys.path.insert(0, {root!r})
import feelmysign.early_off as early

seen = []
real_off = early.off

def spy_off(*args, **kwargs):
    seen.append(sorted(sys.modules))
    return real_off(*args, **kwargs)

early.off = spy_off
read_end, write_end = os.pipe()
os.close(write_end)  # the "sleeve" is gone at once: end of file
from feelmysign.guard import main

main([str(os.getpid()), str(read_end), "", "mux 99 0x70 0 1 2 3 4 5 6 7"])
print(repr(seen))
"""


def test_the_guardian_imports_no_more_than_the_early_all_off_before_it_writes() -> None:
    """What the guardian has loaded when it switches off: none of what the early all-off
    must not load either (test_cli_imports), and no JSON on a real bus."""
    from test_cli_imports import NOT_BEFORE_ALL_OFF, NOT_BEFORE_REAL_BUS

    import feelmysign

    root = str(Path(feelmysign.__file__).resolve().parents[1])
    done = subprocess.run(
        [sys.executable, "-I", "-S", "-c", GUARDIAN_PROBE.format(root=root)],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
    )
    assert done.returncode == 0, done.stderr
    # No /dev/i2c-99 here: the off says so, and it is what the sleeve's stderr would show.
    assert "ended without switching its motors off" in done.stderr, done.stderr
    (modules,) = ast.literal_eval(done.stdout.strip().splitlines()[-1])
    loaded = [
        name
        for name in modules
        for banned in (*NOT_BEFORE_ALL_OFF, *NOT_BEFORE_REAL_BUS)
        if name == banned or name.startswith(banned + ".")
    ]
    assert not loaded, loaded


@pytest.mark.parametrize("busy", [False, True])
def test_the_guardian_leaves_a_running_or_sleeping_process_alone_and_acts_once_per_stop(
    busy: bool,
) -> None:
    """``watch`` on a stand-in for the sleeve (a process that sleeps, or one that spins): never
    while it runs or sleeps, however long; once when it has been stopped STOPPED_S, not again
    during that stop, and again at the next stop."""
    from feelmysign.guard import watch

    spin = "while True: pass" if busy else "import time; time.sleep(60)"
    stand_in = subprocess.Popen([sys.executable, "-c", spin])
    read_end, write_end = os.pipe()
    calls: list[tuple[float, str]] = []
    watcher = threading.Thread(
        target=watch,
        args=(stand_in.pid, read_end, lambda why: calls.append((time.monotonic(), why))),
    )
    try:
        watcher.start()
        time.sleep(STOPPED_S * 4)
        assert calls == []  # running (R) or sleeping (S): never acted on
        for _ in range(2):
            stopped_at = time.monotonic()
            os.kill(stand_in.pid, signal.SIGSTOP)
            wait_until(lambda: len(calls) == 1, "the off for the stop", OFF_WITHIN_S * 3)
            assert calls[0][0] - stopped_at >= STOPPED_S
            assert calls[0][1].startswith("stopped for"), calls
            time.sleep(STOPPED_S * 2)
            assert len(calls) == 1  # once per stop
            os.kill(stand_in.pid, signal.SIGCONT)
            time.sleep(STOPPED_S * 2)
            assert len(calls) == 1
            calls.clear()
        os.write(write_end, b"\x00")  # dismissed: it returns without an off
        watcher.join(WAIT_S)
        assert not watcher.is_alive() and calls == []
    finally:
        os.close(write_end)
        watcher.join(WAIT_S)
        os.close(read_end)
        stand_in.kill()
        stand_in.wait(WAIT_S)
