"""The sleeve's guardian: a small process that switches every motor off when the sleeve cannot.

A DRV2605L keeps driving its motor after the process that set it dies or freezes. Under
systemd the unit restarts a dead sleeve (whose early all-off, :mod:`feelmysign.early_off`,
switches everything off within milliseconds) and its watchdog kills a frozen one; a sleeve
started by hand (``feelmysign sleeve``, or the sleeve inside ``feelmysign up``) has neither.
So every sleeve that drives DRV2605L chips (the real bus, or an emulated one kept in a file:
``--emulate-state``) starts this guardian once its first all-off is done, in the background,
off the path of the first motor command. The guardian:

- holds the reading end of a pipe whose writing end only the sleeve holds (not inherited by
  anything the sleeve starts). When the sleeve dies, however it dies (``kill -9`` included),
  the kernel closes its end: the guardian reads end-of-file, switches every motor of the
  sleeve's wiring off (the early all-off's own sequence, :func:`feelmysign.early_off.off`)
  and exits. A sleeve that stops cleanly switches its motors off itself, then writes one byte
  (:meth:`Guardian.dismiss`): the guardian exits without touching the bus. A sleeve whose own
  all-off failed closes the pipe without the byte: the guardian tries once more.
- reads the state of each of the sleeve's threads in ``/proc/PID/task/TID/stat`` every
  POLL_S. A sleeve *stopped* (every thread ``T``, SIGSTOP or Ctrl-Z; or ``t``, a debugger)
  for more than STOPPED_S gets every motor switched off,
  once per stop. A stopped process cannot be half-way through an I2C transaction, so the
  guardian's writes cannot interleave with its own. It may have been stopped between a
  multiplexer select and its chip write: the off ends with every multiplexer channel disabled
  (as every all-off does), so when the sleeve is continued that write reaches no chip at all
  (not another chip): the sleeve takes it as a chip that stopped answering, switches it off
  and sets it up again (as for a loose wire). Its later writes find chips in standby and RTP 0:
  they may under-drive a stroke until the sleeve's next all-off, never drive a motor it meant
  off. A sleeve that is merely slow or busy (``R``, ``S``, ``D``) is never acted on: two
  writers on one bus can send a write to the wrong chip (:mod:`feelmysign.backends.bus_lock`).
  The guardian takes no bus lock: its off is an emergency off, like ``feelmysign off``.
  On the emulated bus kept in a file the continued sleeve writes its whole model of the
  chips back at its next write (one process at a time should drive a state file), so the
  file may show the stroke's motors on again where real chips, left in standby, would not.

It never dies with the sleeve by a signal: no parent-death signal, and a session of its own,
so that a Ctrl-C to the terminal's process group reaches the sleeve (which then stops cleanly
and dismisses it) but not the guardian; it ignores SIGINT, SIGHUP and SIGTERM (systemd's
stop sends SIGTERM to every process of the unit). It exits by itself once its work is done.

What it cannot cover: a guardian itself killed (``kill -9`` of both, a cgroup killed whole),
a SIGCONT that lands during the few milliseconds of its off (the two writers may then
interleave: only the sleeve's next all-off puts a misdirected write right), and a loss of
power of the Pi (the chips lose theirs too, unless powered apart). Only an enable line
(``[i2c] enable``, docs/sleeve-hardware.md) stops every motor whatever happens to the software.

The child imports what the early all-off imports and nothing else (no TOML, no MQTT, no
logging): it is started as ``python -I -S -c`` with this package's folder on its path.
"""

from __future__ import annotations

import os
import sys

TYPE_CHECKING = False  # typing itself costs a start-up import; mypy reads this name as True
if TYPE_CHECKING:
    import subprocess
    import threading

    from feelmysign.early_off import Targets

# How often the guardian looks at the sleeve's state while it waits on the pipe.
POLL_S = 0.05
# How long the sleeve must have been stopped before its motors are switched off: longer than a
# debugger's or the kernel's brief stops, far shorter than a wearer would bear a stuck motor.
STOPPED_S = 0.3
STOPPED_STATES = ("T", "t")  # /proc/PID/stat field 3: stopped by a signal, or being traced
DISMISSED = b"\x00"  # the sleeve switched its motors off itself
_DISMISS_WAIT_S = 2.0  # how long a clean stop waits for the guardian to end


class Guardian:
    """The sleeve's side: starts the guardian on a thread of its own, dismisses it at a clean
    stop. ``targets``: the sleeve's wiring (bus -> multiplexer -> channels); ``state_path``:
    the emulated bus's state file, None for the real bus."""

    def __init__(self, targets: Targets, state_path: str | None) -> None:
        self._targets = targets
        self._state_path = state_path
        self._write_end: int | None = None
        self._process: subprocess.Popen[bytes] | None = None
        self._thread: threading.Thread | None = None
        self.problem: str | None = None  # why it could not be started, if it could not

    @property
    def pid(self) -> int | None:
        return None if self._process is None else self._process.pid

    def start(self) -> None:
        """Start the guardian in the background: returns at once."""
        import threading

        self._thread = threading.Thread(target=self._spawn, name="feelmysign-guardian", daemon=True)
        self._thread.start()

    def wait_started(self, timeout: float | None = None) -> None:
        if self._thread is not None:
            self._thread.join(timeout)

    def _spawn(self) -> None:
        import subprocess

        read_end, write_end = os.pipe()  # both close-on-exec: nothing else inherits them
        command = guardian_command(os.getpid(), read_end, self._targets, self._state_path)
        try:
            self._process = subprocess.Popen(
                command,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                pass_fds=(read_end,),
                start_new_session=True,  # Ctrl-C to the terminal's group does not reach it
            )
        except OSError as error:
            os.close(write_end)
            self.problem = f"the guardian could not be started: {error}"
            print(f"feelmysign: {self.problem}", file=sys.stderr, flush=True)
            return
        finally:
            os.close(read_end)
        self._write_end = write_end

    def dismiss(self, *, switched_off: bool = True) -> None:
        """The sleeve stops. ``switched_off``: it switched every motor off itself, so the
        guardian exits without touching the bus; else it tries the off once more."""
        self.wait_started()
        write_end, self._write_end = self._write_end, None
        if write_end is None:
            return
        try:
            if switched_off:
                os.write(write_end, DISMISSED)
        except OSError:
            pass  # it is gone already
        finally:
            os.close(write_end)
        process = self._process
        if process is not None:
            import contextlib
            import subprocess

            # Reaped: no zombie left beside a running `up`. Past the wait it goes on by itself.
            with contextlib.suppress(subprocess.TimeoutExpired):
                process.wait(_DISMISS_WAIT_S)


def guardian_command(
    parent: int, read_end: int, targets: Targets, state_path: str | None
) -> list[str]:
    """The guardian's command line: this Python, isolated, with this package on its path."""
    from feelmysign.early_off import wiring_lines

    package_root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    code = (
        f"import sys; sys.path.insert(0, {package_root!r}); "
        "from feelmysign.guard import main; sys.exit(main(sys.argv[1:]))"
    )
    return [
        sys.executable,
        "-I",  # no PYTHONPATH, no user site: the same modules whatever the environment
        "-S",  # no site-packages: it needs none, and starts faster
        "-c",
        code,
        str(parent),
        str(read_end),
        state_path or "",
        *wiring_lines(targets),
    ]


def main(arguments: list[str]) -> int:
    """The guardian: PARENT_PID PIPE_FD STATE_FILE_OR_EMPTY WIRING_LINE..."""
    import signal

    # Its end is the sleeve's: a Ctrl-C, a hang-up or a SIGTERM (systemd's stop reaches every
    # process of the unit) is the sleeve's to act on, and the sleeve dismisses it once every
    # motor is off, or dies, and then it acts. Only SIGKILL ends it before that.
    for ignored in (signal.SIGINT, signal.SIGHUP, signal.SIGTERM):
        signal.signal(ignored, signal.SIG_IGN)
    from feelmysign.early_off import targets_from_lines

    parent, read_end = int(arguments[0]), int(arguments[1])
    state_path = arguments[2] or None
    targets = targets_from_lines(arguments[3:])
    if targets is None:
        print(f"feelmysign guardian: unreadable wiring {arguments[3:]}", file=sys.stderr)
        return 2
    return watch(parent, read_end, lambda why: _switch_off(targets, state_path, parent, why))


def watch(parent: int, read_end: int, switch_off: Callable[[str], None]) -> int:
    """Wait on the pipe from ``parent``; call ``switch_off`` when it dies or stays stopped."""
    import select
    import time

    stopped_since: float | None = None
    acted_on_stop = False
    while True:
        ready, _, _ = select.select([read_end], [], [], POLL_S)
        if ready:
            try:
                data = os.read(read_end, 1)
            except OSError:
                data = b""
            if data == DISMISSED:
                return 0  # a clean stop: the sleeve switched its motors off itself
            switch_off("ended without switching its motors off")
            return 0
        if stopped(parent):
            now = time.monotonic()
            if stopped_since is None:
                stopped_since = now
            elif not acted_on_stop and now - stopped_since >= STOPPED_S:
                switch_off(f"stopped for {now - stopped_since:.1f} s")
                acted_on_stop = True
        else:
            stopped_since, acted_on_stop = None, False


def stopped(pid: int) -> bool:
    """Every thread of ``pid`` stopped (``T``, ``t``). One thread stopped alone (a debugger
    may stop only the one it traces) is not enough: another may be writing to the bus."""
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return False
    states = [process_state(pid, task) for task in tasks]
    return bool(states) and all(state in STOPPED_STATES for state in states)


def process_state(pid: int, thread: str | None = None) -> str | None:
    """The state letter of ``pid`` (or of its ``thread``) in /proc/PID/stat (``R``, ``S``,
    ``T``...); None if gone."""
    path = f"/proc/{pid}/stat" if thread is None else f"/proc/{pid}/task/{thread}/stat"
    try:
        with open(path, "rb") as stat:
            text = stat.read()
    except OSError:
        return None
    # "PID (COMMAND) STATE ...": the command may hold spaces and parentheses.
    rest = text[text.rfind(b")") + 2 :]
    return rest[:1].decode("ascii", "replace") or None


def guardian_pids(parent: int) -> list[int]:
    """The guardians among ``parent``'s children (for tests and benches that kill both: the
    case only the restart's early all-off, or an enable line, covers)."""
    found = []
    try:
        tasks = os.listdir(f"/proc/{parent}/task")
    except OSError:
        return []
    for task in tasks:
        try:
            with open(f"/proc/{parent}/task/{task}/children", "rb") as listed:
                children = listed.read().split()
        except OSError:
            continue
        for child in children:
            try:
                with open(f"/proc/{int(child)}/cmdline", "rb") as command:
                    if b"feelmysign.guard import main" in command.read():
                        found.append(int(child))
            except OSError:
                continue
    return found


def _switch_off(targets: Targets, state_path: str | None, parent: int, why: str) -> None:
    from feelmysign.early_off import off

    problems = off(targets, state_path)
    said = f"feelmysign guardian: the sleeve (process {parent}) {why}; every motor switched off"
    if problems:
        said += ", except:\n" + "\n".join(f"  - {problem}" for problem in problems)
        said += "\nIf a motor keeps vibrating, unplug the sleeve's power."
    import contextlib

    with contextlib.suppress(OSError, ValueError):  # nobody may read it now: the off counts
        print(said, file=sys.stderr, flush=True)


if TYPE_CHECKING:
    from collections.abc import Callable
