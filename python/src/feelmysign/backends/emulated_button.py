"""The wearer's button on the emulated bus: a line a test presses and lets go.

It has the methods of the real button (:class:`feelmysign.backends.button.ButtonInput`),
so the sleeve's watcher runs on it unchanged. A test in the same process calls
``press()`` and ``let_go()``; a test in another process (a real ``feelmysign sleeve``
with ``--emulate-state FILE``) writes a line to the named pipe ``FILE.buttons``, which
the sleeve opens when it takes its buttons::

    press gpiochip0 27
    release gpiochip0 27

(:func:`press_in` and :func:`release_in` write them, and say when no sleeve reads the
pipe; a shell's plain ``echo`` into it then waits forever, a FIFO having no reader, so the
commands the sleeve prints run it under ``timeout 2``, see :func:`press_command`.) The pipe
wakes the sleeve the way a real line's edge does, with no polling, and the button records
when it saw each change as the bus records everything else, in the state file: ``pressed_at`` and
``released_at`` (the wall clock in ms, and the bus's transaction count then), the number
of ``presses``, and ``driven_at_press`` (how many motors were driven at the last press).
With the bus's ``silent_since`` (when every motor was last found off) a test reads how
soon after a press every motor was off, on one clock, from the emulation's own record.
"""

from __future__ import annotations

import errno
import os
import shlex
import stat
import threading
import time
from collections.abc import Mapping

# The emulated bus imports this; it stays light (see emulated_i2c).
TYPE_CHECKING = False
if TYPE_CHECKING:
    from feelmysign.backends.emulated_i2c import EmulatedI2CBus

PIPE_SUFFIX = ".buttons"


class EmulatedButton:
    """A button on an emulated GPIO line: ``press()`` and ``let_go()`` move it."""

    def __init__(self, chip: str, line: int) -> None:
        self.chip = chip
        self.line = line
        self.is_pressed = False
        self.presses = 0
        self.pressed_at: tuple[float, int] | None = None
        self.released_at: tuple[float, int] | None = None
        self.driven_at_press: int | None = None
        self._edges: list[tuple[bool, float]] = []  # (pressed, monotonic ms), not yet taken
        self._changed = threading.Condition()
        self._bus: EmulatedI2CBus | None = None

    @property
    def description(self) -> str:
        return f"emulated button ({self.chip} line {self.line})"

    # --- a finger -------------------------------------------------------------------------

    def press(self) -> None:
        self._move(True)

    def let_go(self) -> None:
        self._move(False)

    def _move(self, pressed: bool) -> None:
        at_ms = time.monotonic() * 1000.0  # the edge's time, as the kernel stamps a real one
        if pressed == self.is_pressed:
            return
        bus = self._bus
        if bus is not None:
            bus.button_moved(self, pressed)
        else:
            self.record(pressed, 0, None)
        with self._changed:
            self._edges.append((pressed, at_ms))
            self._changed.notify_all()

    def record(self, pressed: bool, transactions: int, driven: int | None) -> None:
        """The bus's part of a change (its lock held): when, and what was driven then."""
        if pressed == self.is_pressed:
            return
        self.is_pressed = pressed
        at = (round(time.time() * 1000, 3), transactions)
        if pressed:
            self.presses += 1
            self.pressed_at = at
            self.driven_at_press = driven
        else:
            self.released_at = at

    # --- what the sleeve reads (ButtonInput) ------------------------------------------------

    def request(self) -> None:
        pass  # always there: a test that wants it missing leaves it out of the bus

    def pressed(self) -> bool:
        return self.is_pressed

    def edges(self, timeout_s: float) -> list[tuple[bool, float]]:
        """As a real line's edge events: queued until taken, each with its time."""
        with self._changed:
            self._changed.wait_for(lambda: bool(self._edges), timeout_s)
            taken, self._edges = self._edges, []
            return taken

    def close(self) -> None:
        pass


def pipe_path(state_path: str | os.PathLike[str]) -> str:
    return os.fspath(state_path) + PIPE_SUFFIX


class ButtonPipe:
    """The named pipe next to a state file, read on a thread of its own: each line moves one
    of ``buttons``. Opened for reading and writing, so it never reads end-of-file when
    a writer goes away (Linux lets a FIFO be opened so)."""

    def __init__(self, buttons: Mapping[tuple[str, int], EmulatedButton], path: str) -> None:
        self._buttons = buttons  # (chip, line) -> its button
        self._path = path
        self._fd: int | None = None
        self._thread: threading.Thread | None = None

    def open(self) -> None:
        from feelmysign.errors import HardwareError

        try:
            if not os.path.exists(self._path):
                os.makedirs(os.path.dirname(self._path) or ".", mode=0o700, exist_ok=True)
                os.mkfifo(self._path, 0o600)
            elif not stat.S_ISFIFO(os.stat(self._path).st_mode):
                raise HardwareError(
                    f"{self._path} is not a named pipe: the emulated buttons are pressed through "
                    "it; delete it and start again"
                )
            self._fd = os.open(self._path, os.O_RDWR)
        except OSError as error:
            raise HardwareError(
                f"cannot open the emulated buttons' pipe {self._path}: {error.strerror}; check "
                "that the state file's folder can be written"
            ) from error
        self._thread = threading.Thread(target=self._run, name="feelmysign-buttons", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        assert self._fd is not None
        with os.fdopen(self._fd, "r", encoding="ascii", errors="replace") as pipe:
            for line in pipe:
                self._take(line.split())

    def _take(self, words: list[str]) -> None:
        if len(words) != 3 or words[0] not in ("press", "release") or not words[2].isdigit():
            return  # not ours: a pipe anyone may write to must not stop the sleeve
        button = self._buttons.get((words[1], int(words[2])))
        if button is None:
            return
        if words[0] == "press":
            button.press()
        else:
            button.let_go()


def press_command(pipe: str, chip: str, line: int, what: str = "press") -> str:
    """The shell command that presses (``what="release"``: lets go) a button through ``pipe``.
    Under ``timeout``: with no sleeve reading the pipe, a plain ``echo`` into it would wait
    for one forever."""
    return f"timeout 2 sh -c 'echo {what} {chip} {line} > {shlex.quote(pipe)}'"


def press_in(state_path: str | os.PathLike[str], chip: str, line: int) -> None:
    """Press the button on ``chip`` line ``line`` of the sleeve running on ``state_path``."""
    _write(state_path, f"press {chip} {line}\n")


def release_in(state_path: str | os.PathLike[str], chip: str, line: int) -> None:
    _write(state_path, f"release {chip} {line}\n")


def _write(state_path: str | os.PathLike[str], text: str) -> None:
    try:
        fd = os.open(pipe_path(state_path), os.O_WRONLY | os.O_NONBLOCK)
    except OSError as error:
        if error.errno in (errno.ENXIO, errno.ENOENT):
            raise OSError(
                error.errno, f"no sleeve has the buttons of {os.fspath(state_path)} open"
            ) from error
        raise
    try:
        os.write(fd, text.encode("ascii"))
    finally:
        os.close(fd)
