"""Every DRV2605L off, with nothing imported but ``os``: the first act of a starting sleeve.

A DRV2605L in RTP mode drives its motor at RTP_INPUT until told otherwise, also
after the process that set it was killed. A sleeve restarted after a crash
therefore switches the chips off before it imports anything else (see
``feelmysign.early_off``), and this module is what it may import for that:
the few registers it writes, the off sequence, and ``/dev/i2c-N`` through the
kernel's plain read/write interface (Documentation/i2c/dev-interface.rst),
without smbus2 and the ctypes it loads. On the wire, a two-byte write is the
same transaction as SMBus "write byte data", and a one-byte write the same as
"write byte": exactly what the backend's full all-off sends.

The backend (:mod:`feelmysign.backends.drv2605`) takes its register map from
here, so the two can never switch a chip off differently.
"""

from __future__ import annotations

import errno
import os

TYPE_CHECKING = False  # typing itself costs a start-up import; mypy reads this name as True
if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping
    from typing import Protocol

    class WriteBus(Protocol):
        """What the off sequence needs of a bus: an ``I2CBus``, or a :class:`RawI2CBus`."""

        def write_byte(self, i2c_addr: int, value: int, /) -> None: ...

        def write_byte_data(self, i2c_addr: int, register: int, value: int, /) -> None: ...

        def close(self) -> None: ...


DRV2605_ADDRESS = 0x5A  # fixed in silicon: the reason for the multiplexers
REG_MODE = 0x01
REG_RTP_INPUT = 0x02
MODE_STANDBY = 0x40  # STANDBY (bit 6): low power, output off, registers kept
MULTIPLEXER_ADDRESSES = range(0x70, 0x78)  # TCA9548A, set by the A2..A0 pins
CHANNELS = range(8)
CONTROL_NONE = 0x00  # TCA9548A control register with every channel disabled

_I2C_SLAVE = 0x0703  # linux/i2c-dev.h: the address the next read/write goes to


def switch_off(bus: WriteBus, channels: Mapping[int, Iterable[int]]) -> list[str]:
    """RTP 0, then standby, to the DRV2605L on each of ``channels`` (multiplexer -> channels);
    then every multiplexer deselected. What failed, in words; it never raises for a part
    that does not answer, so one missing chip or multiplexer cannot keep the others on.

    The order is the backend's: RTP 0 on every chip first (the quickest way to silence
    them all), then standby on every chip (either alone silences a motor). Exactly one
    channel is enabled at any moment: every DRV2605L answers at the same address.
    """
    targets = [(mux, channel) for mux in sorted(channels) for channel in sorted(channels[mux])]
    selector = _Selector(bus, sorted(channels))
    failed: dict[tuple[int, int], str] = {}
    for register, value in ((REG_RTP_INPUT, 0), (REG_MODE, MODE_STANDBY)):
        for mux, channel in targets:
            try:
                selector.select(mux, channel)
                bus.write_byte_data(DRV2605_ADDRESS, register, value)
            except OSError as error:
                selector.forget()
                failed.setdefault(
                    (mux, channel),
                    f"DRV2605L on multiplexer 0x{mux:02X} channel {channel}: {_why(error)}",
                )
    problems = list(failed.values())
    for mux in sorted(channels):
        try:
            bus.write_byte(mux, CONTROL_NONE)
        except OSError as error:
            problems.append(f"TCA9548A multiplexer 0x{mux:02X} not deselected: {_why(error)}")
    return problems


class _Selector:
    """Enables one channel of one multiplexer and no other, writing only what changes.

    A multiplexer whose state is unknown (at first, and after a failed write) is
    written again; one that does not answer does not stop the others being used.
    """

    def __init__(self, bus: WriteBus, multiplexers: list[int]) -> None:
        self._bus = bus
        self._multiplexers = multiplexers
        self._controls: dict[int, int | None] = dict.fromkeys(multiplexers)

    def select(self, multiplexer: int, channel: int) -> None:
        for other in self._multiplexers:
            if other != multiplexer and self._controls[other] != CONTROL_NONE:
                self._write(other, CONTROL_NONE, quiet=True)
        if self._controls[multiplexer] != 1 << channel:
            self._write(multiplexer, 1 << channel, quiet=False)

    def forget(self) -> None:
        self._controls = dict.fromkeys(self._multiplexers)

    def _write(self, multiplexer: int, control: int, *, quiet: bool) -> None:
        self._controls[multiplexer] = None  # unknown until acknowledged
        try:
            self._bus.write_byte(multiplexer, control)
        except OSError:
            # Deselecting another multiplexer is best effort: one that does not answer must
            # not keep this chip from being reached (the final deselect reports it).
            if not quiet:
                raise
            return
        self._controls[multiplexer] = control


def _why(error: OSError) -> str:
    if error.errno == errno.EREMOTEIO:  # nothing acknowledged the address
        return "no answer"
    return error.strerror or str(error)


class RawI2CBus:
    """``/dev/i2c-<number>`` written through i2c-dev's read/write interface (writes only).

    Raises OSError as ``open``, ``ioctl`` and ``write`` do: FileNotFoundError for
    a bus that does not exist, EREMOTEIO (121) for an address nobody acknowledges.
    """

    def __init__(self, number: int) -> None:
        import fcntl  # a small C module, and only where a real bus is opened

        self._ioctl = fcntl.ioctl
        self._fd = os.open(f"/dev/i2c-{number}", os.O_RDWR | os.O_CLOEXEC)
        self._address: int | None = None

    def write_byte(self, i2c_addr: int, value: int, /) -> None:
        self._write(i2c_addr, bytes((value,)))

    def write_byte_data(self, i2c_addr: int, register: int, value: int, /) -> None:
        self._write(i2c_addr, bytes((register, value)))

    def close(self) -> None:
        os.close(self._fd)

    def _write(self, address: int, data: bytes) -> None:
        if address != self._address:
            self._address = None
            self._ioctl(self._fd, _I2C_SLAVE, address)
            self._address = address
        written = os.write(self._fd, data)
        if written != len(data):
            raise OSError(errno.EIO, f"short I2C write ({written} of {len(data)} bytes)")
