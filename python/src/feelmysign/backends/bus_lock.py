"""One process at a time on the sleeve's I2C bus: an exclusive lock, flock(2) on a file per bus.

Every DRV2605L sits at the same address behind a multiplexer channel, so two
processes on one bus do not merely take turns: one's channel select between
the other's select and its write sends that write to the wrong chip, and a
``feelmysign off`` beside a running sleeve is undone by the sleeve's next
stroke. So whatever drives the bus holds this lock while it does: the sleeve
for as long as it runs, ``buzz`` and ``scan`` for their few seconds. A second
sleeve, ``buzz`` or ``scan`` on a held bus is refused (:class:`BusBusyError`,
naming the process that holds it); ``feelmysign off`` is never refused, and says
who will drive the motors again.

The lock is ``flock(LOCK_EX | LOCK_NB)`` on a file, so it is the kernel's: it
goes with its process however that ends, ``kill -9`` included, and a lock file
left behind holds nothing. Which file:

- the real bus ``/dev/i2c-N``: ``/run/lock/feelmysign-i2c-N.lock`` (``/run/lock``
  is writable by everyone on Debian and Raspberry Pi OS, and shared by every
  user, so the service's sleeve and a builder's ``buzz`` meet there; the systemd
  unit lists it in ``ReadWritePaths``). Where ``/run/lock`` cannot be written,
  ``/var/lock``, then ``/tmp`` (not ``$TMPDIR``: the same for every user);
  ``$FEELMYSIGN_LOCK_DIR`` instead, when set (the tests set it);
- the emulated bus kept in a file (``--emulate-state FILE``): ``FILE.lock``
  beside it, so that it behaves as the hardware does (``--emulate`` alone is a
  bus of the process's own: nothing to share, no lock).

The holder writes who it is into the file (PID, what it does, its command
without secrets, its systemd service, since when), for the message of whoever
finds the bus held. Nothing here but ``os`` and (when a lock is taken)
``fcntl``: the early all-off of ``buzz`` looks at the lock before any other
import (:mod:`feelmysign.early_off`).
"""

from __future__ import annotations

import contextlib
import errno
import os
import sys

from feelmysign.errors import HardwareError

LOCK_DIRS = ("/run/lock", "/var/lock")
FALLBACK_DIR = "/tmp"  # where none of LOCK_DIRS can be written
# Another folder for the real buses' lock files: for the tests (which must not meet the
# machine's own sleeve, or each other), or a system without /run/lock. Every process on a
# bus must then see the same value, or they do not see each other's lock.
LOCK_DIR_ENV = "FEELMYSIGN_LOCK_DIR"
LOCK_SUFFIX = ".lock"
MAX_HOLDER_BYTES = 4096  # a few lines; more is not a holder's record
# Options whose value is a secret: left out of the command the lock file names.
SECRET_OPTIONS = ("--password", "--join")


def bus_lock_path(bus_number: int, dirs: tuple[str, ...] = LOCK_DIRS) -> str:
    """The lock file of ``/dev/i2c-<bus_number>``: in ``$FEELMYSIGN_LOCK_DIR`` when set, else
    in the first of ``dirs`` this process can write, else in ``/tmp``."""
    name = f"feelmysign-i2c-{bus_number}{LOCK_SUFFIX}"
    chosen = os.environ.get(LOCK_DIR_ENV)
    if chosen:
        return os.path.join(chosen, name)
    for folder in dirs:
        if os.path.isdir(folder) and os.access(folder, os.W_OK | os.X_OK):
            return os.path.join(folder, name)
    # Not tempfile.gettempdir() nor $TMPDIR: one place for every user and every process.
    return os.path.join(FALLBACK_DIR, name)


def state_lock_path(state_path: str | os.PathLike[str]) -> str:
    """The lock file of the emulated bus kept in ``state_path``: ``FILE.lock`` beside it."""
    return os.path.abspath(os.fspath(state_path)) + LOCK_SUFFIX


def lock_for(bus_number: int, emulate_state: str | os.PathLike[str] | None = None) -> BusLock:
    """The lock of ``/dev/i2c-<bus_number>``, or of the emulated bus kept in ``emulate_state``."""
    if emulate_state is not None:
        return BusLock(
            state_lock_path(emulate_state), f"the emulated I2C bus in {os.fspath(emulate_state)}"
        )
    return BusLock(bus_lock_path(bus_number), f"the I2C bus /dev/i2c-{bus_number}")


class Holder:
    """Who holds a bus, as its lock file says: PID, command, systemd unit, since when."""

    def __init__(
        self,
        pid: int | None = None,
        command: str = "",
        unit: str = "",
        since: str = "",
        role: str = "",
    ) -> None:
        self.pid = pid
        self.command = command
        self.unit = unit
        self.since = since
        self.role = role  # what holds the bus: "sleeve", "buzz", "scan", "off"

    @property
    def is_sleeve(self) -> bool:
        """A sleeve: it plays on until stopped (``buzz`` and ``scan`` end by themselves)."""
        return self.role == "sleeve"

    def describe(self) -> str:
        """``process 1234 (feelmysign sleeve ..., the systemd service X, since 22:10:03)``."""
        if self.pid is None:
            return "another process (it has not recorded its PID)"
        details = [self.command or "its command not recorded"]
        if self.unit:
            details.append(f"the systemd service {self.unit}")
        if self.since:
            details.append(f"since {self.since}")
        return f"process {self.pid} ({', '.join(details)})"

    def how_to_stop(self) -> str:
        """What to do so that the holder lets go of the bus."""
        if self.pid is None:
            return "find it with 'fuser -v' on the lock file and stop it"
        if not self.is_sleeve:
            return "wait for it to end (it lets go of the bus by itself), or stop it"
        if self.unit:
            name = self.unit.removesuffix(".service")
            return (
                f"stop it with 'sudo systemctl stop {name}' (it switches every motor off as "
                "it stops)"
            )
        return (
            f"stop it with Ctrl-C where it runs, or 'kill {self.pid}' (it switches every "
            "motor off as it stops)"
        )

    def as_text(self) -> str:
        lines = [f"pid {self.pid}" if self.pid is not None else ""]
        fields = (
            ("role", self.role),
            ("command", self.command),
            ("unit", self.unit),
            ("since", self.since),
        )
        for key, value in fields:
            if value:
                lines.append(f"{key} {' '.join(value.split())}")
        return "\n".join(line for line in lines if line) + "\n"

    @classmethod
    def from_text(cls, text: str) -> Holder:
        """The holder a lock file names; a Holder without a PID for one that names none."""
        fields: dict[str, str] = {}
        for line in text.splitlines():
            key, _, value = line.partition(" ")
            fields[key] = value.strip()
        pid = fields.get("pid", "")
        return cls(
            pid=int(pid) if pid.isdigit() else None,
            command=fields.get("command", ""),
            unit=fields.get("unit", ""),
            since=fields.get("since", ""),
            role=fields.get("role", ""),
        )

    @classmethod
    def this_process(cls, role: str) -> Holder:
        import time

        return cls(
            pid=os.getpid(),
            command=_this_command(),
            unit=_this_unit(),
            since=time.strftime("%Y-%m-%d %H:%M:%S"),
            role=role,
        )


class BusBusyError(HardwareError):
    """Another process holds the bus: ``holder`` names it, ``bus`` is the bus in words."""

    def __init__(self, bus: str, holder: Holder, message: str) -> None:
        super().__init__(message)
        self.bus = bus
        self.holder = holder


class BusLock:
    """The exclusive lock on one bus, by its lock file ``path``; ``bus`` names the bus in
    messages (``/dev/i2c-1``, ``the emulated bus in bus.json``)."""

    def __init__(self, path: str, bus: str) -> None:
        self.path = path
        self.bus = bus
        self._fd: int | None = None

    @property
    def held(self) -> bool:
        return self._fd is not None

    def try_acquire(self, role: str) -> Holder | None:
        """Take the lock if nobody holds it, and write this process (doing ``role``: "sleeve",
        "buzz", "scan") into the file: None.
        When another process holds it: that process (nothing taken). OSError when the lock
        file can be neither opened nor made (a message says so: see :meth:`acquire`)."""
        if self._fd is not None:
            return None
        import fcntl

        fd = _open_lock_file(self.path)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _read_holder(fd)
            os.close(fd)
            return holder
        except BaseException:
            os.close(fd)
            raise
        self._fd = fd
        try:
            text = Holder.this_process(role).as_text().encode()
            os.ftruncate(fd, 0)
            os.pwrite(fd, text, 0)
        except OSError:
            pass  # opened read-only (another user's file): held all the same, just not named
        return None

    def acquire(self, role: str, *, refused: str) -> None:
        """Take the lock for ``role``, or raise BusBusyError naming who holds it (``refused``:
        what this process does not do then, a sentence: "Nothing was buzzed.")."""
        try:
            holder = self.try_acquire(role)
        except OSError as error:
            raise HardwareError(
                f"cannot use the lock file {self.path} of {self.bus} ({error.strerror or error}), "
                "which keeps two processes from driving one bus; make its folder writable for "
                "this user, or remove the file"
            ) from error
        if holder is not None:
            raise BusBusyError(self.bus, holder, busy_message(self.bus, holder, refused=refused))

    def release(self) -> None:
        """Let go (closing the file lets go of the flock); idempotent."""
        fd, self._fd = self._fd, None
        if fd is not None:
            os.close(fd)

    def __enter__(self) -> BusLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def holder_of(path: str) -> Holder | None:
    """Who holds the lock ``path`` now, or None when nobody does (or there is no lock file).
    Takes the lock for a moment when it is free (writing nothing), so it never blocks."""
    import fcntl

    try:
        fd = _open_lock_file(path, create=False)
    except OSError:
        return None  # no file: nobody ever held it here (a holder made it and keeps it)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return _read_holder(fd)
    except OSError:
        return None
    finally:
        os.close(fd)  # lets go of the lock, when it was taken
    return None


def busy_message(bus: str, holder: Holder, *, refused: str) -> str:
    """Why this process does nothing on ``bus`` (``refused`` says what it does not do): who
    holds the bus, and what to do."""
    what = "a running sleeve" if holder.is_sleeve else "another feelmysign command"
    return (
        f"{bus[:1].upper()}{bus[1:]} is in use by {what}, {holder.describe()}. {refused} "
        "Two processes must not drive one bus (one's multiplexer select would send the "
        f"other's write to the wrong chip): first {holder.how_to_stop()}, then try again."
    )


def _open_lock_file(path: str, *, create: bool = True) -> int:
    """The lock file opened for writing (read-only when another user made it without write
    permission for us, which is enough for flock), made when missing (with ``create``)."""
    flags = os.O_CLOEXEC | getattr(os, "O_NOFOLLOW", 0)
    while True:
        # An existing file first without O_CREAT: in a sticky, world-writable folder such as
        # /run/lock, fs.protected_regular refuses O_CREAT on another user's file, root too.
        for mode in (os.O_RDWR, os.O_RDONLY):
            try:
                return os.open(path, mode | flags)
            except PermissionError:
                continue
            except FileNotFoundError:
                if not create:
                    raise
                break
        else:
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), path)
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL | flags, 0o666)
        except FileExistsError:
            continue  # made by another process a moment ago: open that one
        with contextlib.suppress(OSError):  # whatever the umask: the service and a builder
            os.fchmod(fd, 0o666)  # share the file
        return fd


def _read_holder(fd: int) -> Holder:
    try:
        data = os.pread(fd, MAX_HOLDER_BYTES, 0)
    except OSError:
        return Holder()
    return Holder.from_text(data.decode("utf-8", errors="replace"))


def _this_command() -> str:
    """This process's command line, as a person would type it: ``feelmysign sleeve ...``,
    without its secrets (the file is for everyone to read)."""
    words: list[str] = []
    hide_next = False
    for word in sys.argv[1:]:
        name, equals, _value = word.partition("=")
        if hide_next:
            word = "***"
        elif name in SECRET_OPTIONS and equals:
            word = f"{name}=***"
        elif "://" in word and "@" in word:  # a URL with a login in it
            scheme, _, rest = word.partition("://")
            word = f"{scheme}://***@{rest.rpartition('@')[2]}"
        hide_next = word in SECRET_OPTIONS
        words.append(word)
    return " ".join(["feelmysign", *words])[:500]


def _this_unit() -> str:
    """The systemd service this process runs in, or ""."""
    try:
        with open("/proc/self/cgroup", encoding="utf-8", errors="replace") as cgroup:
            return unit_of(cgroup.read(MAX_HOLDER_BYTES))
    except OSError:
        return ""


def unit_of(cgroup: str) -> str:
    """The systemd service a process runs in, from its /proc/PID/cgroup: the last part of its
    cgroup's path when that is a ``.service`` (``""`` for a login session's ``.scope``)."""
    for line in cgroup.splitlines():
        last = line.rpartition("/")[2]
        if last.endswith(".service"):
            return last
    return ""
