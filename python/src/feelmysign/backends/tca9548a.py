"""TCA9548A I2C multiplexers: several on one bus, at most one channel enabled among them all.

Every DRV2605L answers at the same address (0x5A), so two enabled channels
with a chip each, on one multiplexer or on two, put two chips on the bus at
once. ``Multiplexers`` therefore deselects every other multiplexer before
selecting a channel, and remembers what it selected so that consecutive
accesses to one channel cost no extra I2C transaction (each costs about
0.2 ms at 100 kHz, which the player's timing budget cannot spare).

A ``MuxChannel`` looks exactly like a bus (Adafruit style), so a chip driver
works unchanged behind it.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from contextlib import contextmanager

from feelmysign.backends.all_off import CHANNELS as CHANNELS  # re-exported
from feelmysign.backends.all_off import CONTROL_NONE
from feelmysign.backends.all_off import MULTIPLEXER_ADDRESSES as MULTIPLEXER_ADDRESSES
from feelmysign.backends.i2c import I2CBus
from feelmysign.errors import HardwareError, ParameterError

_CONTROL_NONE = CONTROL_NONE


def _hex(address: int) -> str:
    return f"0x{address:02X}"


class Multiplexers:
    """The TCA9548A multiplexers at ``addresses`` on ``bus``, keeping at most one channel enabled.

    The state of each multiplexer is tracked; unknown at first and after any
    failed write, so that the next selection writes every multiplexer again.
    """

    def __init__(self, bus: I2CBus, addresses: Iterable[int]) -> None:
        self._bus = bus
        self._addresses = tuple(addresses)
        for address in self._addresses:
            if address not in MULTIPLEXER_ADDRESSES:
                raise ParameterError("multiplexer address", _hex(address), "0x70..0x77 (TCA9548A)")
        if len(set(self._addresses)) != len(self._addresses):
            raise ValueError(f"multiplexer addresses repeat: {[_hex(a) for a in self._addresses]}")
        self._controls: dict[int, int | None] = dict.fromkeys(self._addresses)
        self._best_effort = False

    @property
    def bus(self) -> I2CBus:
        return self._bus

    @property
    def addresses(self) -> tuple[int, ...]:
        return self._addresses

    @property
    def selected(self) -> tuple[int, int] | None:
        """(multiplexer, channel) known to be the only enabled channel, or None."""
        enabled: list[tuple[int, int]] = []
        for address, control in self._controls.items():
            if control is None:
                return None
            if control != _CONTROL_NONE:
                enabled.append((address, control.bit_length() - 1))
        return enabled[0] if len(enabled) == 1 else None

    def channel(self, multiplexer: int, channel: int) -> MuxChannel:
        self._check(multiplexer, channel)
        return MuxChannel(self, multiplexer, channel)

    def select(self, multiplexer: int, channel: int) -> None:
        """Enable ``channel`` of ``multiplexer`` and no other channel of any multiplexer."""
        self._check(multiplexer, channel)
        for other in self._addresses:
            if other != multiplexer and self._controls[other] != _CONTROL_NONE:
                try:
                    self._write_control(other, _CONTROL_NONE)
                except HardwareError:
                    if not self._best_effort:
                        raise
        target = 1 << channel
        if self._controls[multiplexer] != target:
            self._write_control(multiplexer, target)

    def deselect_all(self) -> None:
        """Disable every channel of every multiplexer; HardwareError listing those that failed."""
        problems: list[str] = []
        for address in self._addresses:
            try:
                self._write_control(address, _CONTROL_NONE)
            except HardwareError as error:
                problems.append(str(error))
        if problems:
            raise HardwareError("\n".join(problems))

    @contextmanager
    def best_effort(self) -> Iterator[None]:
        """Within: a multiplexer that cannot be deselected does not stop selecting the others.

        For switching everything off: reaching the chips that can be reached
        matters more than the (unlikely) chance that a multiplexer which does
        not answer still has a channel enabled. The caller reports the failure
        through a final :meth:`deselect_all`.
        """
        previous, self._best_effort = self._best_effort, True
        try:
            yield
        finally:
            self._best_effort = previous

    def invalidate(self) -> None:
        """Forget the tracked state (after an I2C error), so the next selection rewrites it all."""
        self._controls = dict.fromkeys(self._addresses)

    def _write_control(self, address: int, control: int) -> None:
        self._controls[address] = None  # unknown until the write is acknowledged
        try:
            self._bus.write_byte(address, control)
        except OSError as error:
            raise HardwareError(
                f"TCA9548A multiplexer {_hex(address)} did not answer ({error}); check its power, "
                "wiring and address pins (A0-A2), or run 'feelmysign scan'"
            ) from error
        self._controls[address] = control

    def _check(self, multiplexer: int, channel: int) -> None:
        if multiplexer not in self._controls:
            known = ", ".join(_hex(a) for a in self._addresses) or "none"
            raise ParameterError("multiplexer", _hex(multiplexer), f"one of this bus's: {known}")
        if channel not in CHANNELS:
            raise ParameterError("channel", channel, "0..7 (TCA9548A)")


class MuxChannel:
    """One multiplexer channel that looks like a bus: every access selects the channel first.

    Closing it does nothing: the channel does not own the bus.
    """

    def __init__(self, multiplexers: Multiplexers, multiplexer: int, channel: int) -> None:
        self._multiplexers = multiplexers
        self.multiplexer = multiplexer
        self.channel = channel

    def __repr__(self) -> str:
        return f"MuxChannel(multiplexer={_hex(self.multiplexer)}, channel={self.channel})"

    def read_byte(self, i2c_addr: int, /) -> int:
        self._multiplexers.select(self.multiplexer, self.channel)
        return self._multiplexers.bus.read_byte(i2c_addr)

    def write_byte(self, i2c_addr: int, value: int, /) -> None:
        self._multiplexers.select(self.multiplexer, self.channel)
        self._multiplexers.bus.write_byte(i2c_addr, value)

    def read_byte_data(self, i2c_addr: int, register: int, /) -> int:
        self._multiplexers.select(self.multiplexer, self.channel)
        return self._multiplexers.bus.read_byte_data(i2c_addr, register)

    def write_byte_data(self, i2c_addr: int, register: int, value: int, /) -> None:
        self._multiplexers.select(self.multiplexer, self.channel)
        self._multiplexers.bus.write_byte_data(i2c_addr, register, value)

    def close(self) -> None:
        pass
