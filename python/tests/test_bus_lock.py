"""The bus lock itself (feelmysign.backends.bus_lock), the early all-off beside it, and the
words ``buzz``, ``scan`` and ``off`` say when another process holds the bus.

A flock belongs to an open file, not to a process: a second ``BusLock`` on the same file
in this process is refused as another process would be, which is what lets these tests
hold a bus without starting a sleeve (test_bus_lock_sleeve.py starts real ones).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from feelmysign.backends.bus_lock import (
    BusBusyError,
    BusLock,
    Holder,
    bus_lock_path,
    holder_of,
    lock_for,
    state_lock_path,
    unit_of,
)
from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_state import drive_levels, open_state_bus
from feelmysign.backends.factory import open_backend
from feelmysign.cli import main
from feelmysign.early_off import switch_off_early
from feelmysign.layout import load_layout

PAPER = str(Path(__file__).resolve().parents[2] / "deploy" / "layouts" / "paper-sleeve.toml")
WAIT_S = 60.0


@pytest.fixture(autouse=True)
def state_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state-home"))
    monkeypatch.delenv("FEELMYSIGN_LAYOUT", raising=False)


@pytest.fixture
def state(tmp_path: Path) -> Path:
    return tmp_path / "bus.json"


@pytest.fixture
def held(state: Path) -> Iterator[BusLock]:
    """The emulated bus in ``state`` held as a sleeve holds it (by this process)."""
    lock = lock_for(1, state)
    assert lock.try_acquire("sleeve") is None
    try:
        yield lock
    finally:
        lock.release()


def hold_as(lock: BusLock, holder: Holder) -> None:
    """Make the held ``lock``'s file name ``holder``, as that process would have written it."""
    Path(lock.path).write_text(holder.as_text())


def left_on(path: Path) -> None:
    """A sleeve on the paper's layout that dies with row 2, column 2 on."""
    layout = load_layout(PAPER)
    backend = Drv2605Backend(layout, bus=open_state_bus(path, layout))
    backend.open()
    backend.set_intensity(2, 2, 1.0)  # and the process "dies": nothing closes it
    assert max(drive_levels(path).values()) == 1.0


def test_a_held_bus_is_refused_to_any_other_open_naming_the_holder(state: Path) -> None:
    first, second = lock_for(1, state), lock_for(1, state)
    assert first.path == second.path == f"{state}.lock" == state_lock_path(state)
    assert first.try_acquire("sleeve") is None
    holder = second.try_acquire("buzz")
    assert holder is not None
    assert (holder.pid, holder.role, holder.is_sleeve) == (os.getpid(), "sleeve", True)
    assert holder.command.startswith("feelmysign")
    with pytest.raises(BusBusyError) as refused:
        second.acquire("buzz", refused="Nothing was buzzed.")
    assert refused.value.holder.pid == os.getpid()
    assert holder_of(first.path) is not None
    first.release()
    assert holder_of(first.path) is None
    second.acquire("buzz", refused="Nothing was buzzed.")  # free now
    assert second.held
    assert holder_of(first.path) is not None
    second.release()


def test_the_lock_goes_with_a_process_killed_with_sigkill(state: Path) -> None:
    path = state_lock_path(state)
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time\n"
            "from feelmysign.backends.bus_lock import BusLock\n"
            "lock = BusLock(sys.argv[1], 'bus')\n"
            "assert lock.try_acquire('sleeve') is None\n"
            "print('held', flush=True)\n"
            "time.sleep(600)\n",
            path,
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout is not None
        assert child.stdout.readline() == "held\n"
        holder = holder_of(path)
        assert holder is not None and holder.pid == child.pid
        assert "since" in holder.describe()
        child.send_signal(signal.SIGKILL)
        child.wait(WAIT_S)
    finally:
        child.kill()
        child.wait(WAIT_S)
    assert os.path.exists(path)  # the file is left behind, and holds nothing
    assert holder_of(path) is None
    lock = BusLock(path, "bus")
    assert lock.try_acquire("buzz") is None
    lock.release()


def test_the_real_bus_lock_is_in_the_first_writable_lock_folder_else_the_temporary_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    writable = tmp_path / "lock"
    writable.mkdir()
    missing = str(tmp_path / "no-such-folder")
    name = "feelmysign-i2c-3.lock"
    assert bus_lock_path(3) == os.path.join(os.environ["FEELMYSIGN_LOCK_DIR"], name)
    monkeypatch.delenv("FEELMYSIGN_LOCK_DIR")
    assert bus_lock_path(3, (missing, str(writable))) == str(writable / name)
    monkeypatch.setenv("TMPDIR", str(tmp_path))  # a user's own: not shared, not used
    assert bus_lock_path(3, (missing,)) == f"/tmp/{name}"
    assert lock_for(1).bus == "the I2C bus /dev/i2c-1"


def test_a_lock_file_is_made_readable_and_writable_by_every_user(state: Path) -> None:
    old = os.umask(0o077)  # as the systemd unit runs the sleeve
    try:
        lock = lock_for(1, state)
        assert lock.try_acquire("sleeve") is None
    finally:
        os.umask(old)
    try:
        assert os.stat(lock.path).st_mode & 0o777 == 0o666
    finally:
        lock.release()


def test_the_holder_is_read_back_as_written_and_a_file_naming_nobody_is_said_so() -> None:
    holder = Holder(
        pid=4242,
        command="feelmysign sleeve --backend drv2605\n--layout x.toml",
        unit="feelmysign-sleeve.service",
        since="2026-11-27 22:10:03",
        role="sleeve",
    )
    back = Holder.from_text(holder.as_text())
    assert (back.pid, back.role, back.unit, back.since) == (
        4242,
        "sleeve",
        "feelmysign-sleeve.service",
        "2026-11-27 22:10:03",
    )
    assert back.command == "feelmysign sleeve --backend drv2605 --layout x.toml"
    assert "sudo systemctl stop feelmysign-sleeve'" in back.how_to_stop()
    nobody = Holder.from_text("")
    assert nobody.pid is None and not nobody.is_sleeve
    assert "has not recorded its PID" in nobody.describe()
    assert "fuser" in nobody.how_to_stop()


def test_the_early_all_off_of_buzz_leaves_a_held_bus_alone_that_of_sleeve_and_off_do_not(
    state: Path, held: BusLock
) -> None:
    left_on(state)
    problems = switch_off_early(
        "buzz", ["buzz", "2", "2", "--layout", PAPER, "--emulate-state", str(state)]
    )
    assert problems == ["I2C bus 1: in use by another process, left alone"]
    assert max(drive_levels(state).values()) == 1.0
    # The sleeve switches off first, and only then looks at the lock (and refuses).
    arguments = ["--backend", "drv2605", "--layout", PAPER, "--emulate-state", str(state)]
    assert switch_off_early("sleeve", ["sleeve", *arguments]) == []
    assert set(drive_levels(state).values()) == {0.0}
    left_on(state)
    assert switch_off_early("off", ["off", "--layout", PAPER, "--emulate-state", str(state)]) == []
    assert set(drive_levels(state).values()) == {0.0}


def test_a_sleeve_or_buzz_opening_a_held_bus_is_refused_before_any_i2c_traffic(
    state: Path, held: BusLock
) -> None:
    left_on(state)
    layout = load_layout(PAPER)
    for role, refusal in (("sleeve", "This sleeve does not start"), ("buzz", "Nothing was buzzed")):
        with pytest.raises(BusBusyError) as refused:
            open_backend("drv2605", layout, emulate_state=state, role=role)  # type: ignore[arg-type]
        assert refused.value.holder.pid == os.getpid()
        assert refusal in str(refused.value)
    assert max(drive_levels(state).values()) == 1.0  # untouched: the holder's bus
    # A bus of this process's own (--emulate without a file) takes no lock.
    open_backend("drv2605", layout, emulate=True, role="buzz").close()


def test_buzz_and_scan_beside_the_sleeve_service_say_to_stop_it_with_systemctl(
    state: Path, held: BusLock, capsys: pytest.CaptureFixture[str]
) -> None:
    hold_as(
        held,
        Holder(
            pid=os.getpid(),
            command="feelmysign sleeve --backend drv2605 --layout /etc/feelmysign/layout.toml",
            unit="feelmysign-sleeve.service",
            since="2026-11-27 22:10:03",
            role="sleeve",
        ),
    )
    for command in (["buzz", "0", "0"], ["scan"]):
        code = main([*command, "--layout", PAPER, "--emulate-state", str(state)])
        err = capsys.readouterr().err
        assert code == 1
        assert err.startswith(
            f"Error: The emulated I2C bus in {state} is in use by a running sleeve, process "
            f"{os.getpid()} (feelmysign sleeve --backend drv2605 --layout "
            "/etc/feelmysign/layout.toml, the systemd service feelmysign-sleeve.service, "
            "since 2026-11-27 22:10:03)."
        ), err
        assert "stop it with 'sudo systemctl stop feelmysign-sleeve'" in err
    assert not state.exists()  # neither opened the bus


def test_off_beside_a_buzz_switches_off_and_says_it_may_switch_a_motor_on_again(
    state: Path, held: BusLock, capsys: pytest.CaptureFixture[str]
) -> None:
    left_on(state)
    hold_as(held, Holder(pid=os.getpid(), command="feelmysign buzz 2 2", role="buzz"))
    code = main(["off", "--layout", PAPER, "--emulate-state", str(state)])
    out, err = capsys.readouterr()
    assert code == 1
    assert set(drive_levels(state).values()) == {0.0}  # never refused: the off went out
    assert out.startswith("Every motor is off for now (12 DRV2605L on the emulated bus")
    assert err.startswith(
        f"Error: Another feelmysign command uses this bus, process {os.getpid()} "
        "(feelmysign buzz 2 2): it may switch a motor on again until it ends."
    ), err
    assert "wait for it to end" in err


def test_the_command_a_lock_file_names_leaves_out_passwords_and_logins(
    state: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(
        sys,
        "argv",
        [
            "/opt/feelmysign/bin/feelmysign",
            "sleeve",
            "--password",
            "hunter2",
            "--join=fms1.secret",
            "--broker",
            "mqtts://arm:hunter3@broker.lan:8883",
        ],
    )
    lock = lock_for(1, state)
    assert lock.try_acquire("sleeve") is None
    try:
        text = Path(lock.path).read_text()
    finally:
        lock.release()
    assert "hunter" not in text and "secret" not in text, text
    assert (
        "command feelmysign sleeve --password *** --join=*** --broker mqtts://***@broker.lan:8883\n"
    ) in text


def test_the_systemd_service_a_holder_runs_in_is_read_from_its_cgroup() -> None:
    assert unit_of("0::/system.slice/feelmysign-sleeve.service\n") == "feelmysign-sleeve.service"
    assert unit_of("1:name=systemd:/system.slice/feelmysign-sleeve.service\n0::/\n") == (
        "feelmysign-sleeve.service"
    )
    # A person's shell: a session scope, or a terminal's scope under the user's manager.
    assert unit_of("0::/user.slice/user-1000.slice/session-3.scope\n") == ""
    assert unit_of("0::/user.slice/user-1000.slice/user@1000.service/app.slice/vte.scope\n") == ""
