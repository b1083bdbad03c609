"""The enable line: one GPIO that every DRV2605L's EN pin hangs on, pulled down to ground.

EN low puts a DRV2605L into shutdown whatever its registers say, so the line
is a hardware off switch for every motor at once, that needs no I2C: the
sleeve drops it before any I2C "off", on a chip lost and on a failed check,
and raises it only once every chip is off and checked. It is also a dead
man's switch: when no process drives the line (the sleeve killed, the Pi
rebooting or without power) the pull-down holds it low and every motor is off.
See docs/sleeve-hardware.md for the wiring.

The real line is driven through libgpiod's Python bindings (``gpiod`` v2),
imported only when a layout has an enable line. The emulated bus has its own
line (:class:`feelmysign.backends.emulated_i2c.EmulatedEnableLine`), which
has the same methods.
"""

from __future__ import annotations

import errno
from typing import TYPE_CHECKING, Any, Protocol

from feelmysign.errors import HardwareError

if TYPE_CHECKING:
    from feelmysign.layout import EnableLine

CONSUMER = "feelmysign"  # what gpioinfo shows as the line's user while the sleeve holds it


class Line(Protocol):
    """What the backend needs of an enable line."""

    @property
    def description(self) -> str: ...

    @property
    def high(self) -> bool:
        """What this process drives the line to (False before ``request`` and after ``release``)."""
        ...

    def request(self) -> None:
        """Take the line as an output, driven low; HardwareError when it cannot be had."""

    def set_high(self, high: bool) -> None:
        """Drive the line high (motors may run) or low (every motor in shutdown)."""

    def release(self) -> None:
        """Drive it low, then let it go (the pull-down keeps it low); idempotent."""


class GpiodLine:
    """The enable line on a real GPIO chip, through libgpiod v2 (``pip install gpiod``)."""

    def __init__(self, enable: EnableLine) -> None:
        self._enable = enable
        self._request: Any = None
        self._high = False
        self._values: Any = None

    @property
    def description(self) -> str:
        return f"enable line {self._enable.name}"

    @property
    def high(self) -> bool:
        return self._high

    def request(self) -> None:
        if self._request is not None:
            return
        gpiod = import_gpiod()
        self._values = gpiod.line.Value
        settings = gpiod.LineSettings(
            direction=gpiod.line.Direction.OUTPUT, output_value=gpiod.line.Value.INACTIVE
        )
        try:
            self._request = gpiod.request_lines(
                self._enable.path, consumer=CONSUMER, config={self._enable.line: settings}
            )
        except (OSError, ValueError) as error:
            raise HardwareError(line_error(self._enable, error)) from error
        self._high = False

    def set_high(self, high: bool) -> None:
        if self._request is None:
            raise HardwareError(f"the {self.description} is not requested; this is a bug")
        value = self._values.ACTIVE if high else self._values.INACTIVE
        try:
            self._request.set_value(self._enable.line, value)
        except OSError as error:
            raise HardwareError(line_error(self._enable, error)) from error
        self._high = high

    def release(self) -> None:
        request, self._request = self._request, None
        if request is None:
            return
        try:
            request.set_value(self._enable.line, self._values.INACTIVE)
        except OSError:
            pass  # released below all the same: the pull-down takes the line low
        finally:
            self._high = False
            request.release()


def import_gpiod() -> Any:
    """The ``gpiod`` module (libgpiod v2's bindings), or a HardwareError saying how to get it."""
    try:
        import gpiod
    except ImportError as error:
        raise HardwareError(
            "the layout has an enable line (i2c.enable) and libgpiod's Python bindings are not "
            "installed: .venv/bin/pip install 'gpiod>=2.2' (or reinstall feelmysign), or remove "
            "i2c.enable from the layout"
        ) from error
    if not hasattr(gpiod, "request_lines"):
        raise HardwareError(
            f"the gpiod module found ({getattr(gpiod, '__file__', '?')}) is libgpiod 1.x, "
            "without request_lines; install version 2: .venv/bin/pip install 'gpiod>=2.2'"
        )
    return gpiod


def line_error(enable: EnableLine, error: Exception) -> str:
    """What went wrong taking or driving ``enable``, and what to do about it."""
    where = f"the enable line ({enable.name}, from i2c.enable)"
    number = getattr(error, "errno", None)
    if number == errno.ENOENT:
        return (
            f"{where}: there is no {enable.path}; list the GPIO chips with 'gpiodetect' and fix "
            "i2c.enable.chip"
        )
    if number in (errno.EACCES, errno.EPERM):
        return (
            f"{where}: permission denied on {enable.path}; add the sleeve's user to the gpio "
            "group (sudo usermod -aG gpio $USER, then log in again)"
        )
    if number == errno.EBUSY:
        return (
            f"{where}: the line is in use by another process (another sleeve, or a program "
            "using it); see 'gpioinfo' for its user, stop it, then try again"
        )
    if number == errno.EINVAL or isinstance(error, ValueError):
        return (
            f"{where}: {enable.chip} has no line {enable.line} ({error}); list its lines with "
            f"'gpioinfo {enable.chip}' and fix i2c.enable.line"
        )
    return f"{where}: {error}"


def read_free_line(enable: EnableLine) -> tuple[str, bool | None]:
    """For ``feelmysign scan``: who holds the line and, when nobody does, what it reads.

    Returns (a description, the level read or None when it could not be read). A
    line nobody holds is read as an input: it must read low (the pull-down).
    """
    gpiod = import_gpiod()
    try:
        with gpiod.Chip(enable.path) as chip:
            info = chip.get_line_info(enable.line)
            if info.used:
                direction = "output" if info.direction == gpiod.line.Direction.OUTPUT else "input"
                return f"held by {info.consumer or 'another process'!r} as an {direction}", None
        settings = gpiod.LineSettings(direction=gpiod.line.Direction.INPUT)
        with gpiod.request_lines(
            enable.path, consumer=f"{CONSUMER}-scan", config={enable.line: settings}
        ) as request:
            level = request.get_value(enable.line) == gpiod.line.Value.ACTIVE
    except (OSError, ValueError) as error:
        raise HardwareError(line_error(enable, error)) from error
    return "free (nobody drives it)", level
