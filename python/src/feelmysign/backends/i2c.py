"""The I2C bus the hardware backends talk to; opening a real one with errors a person can act on.

``I2CBus`` is the part of ``smbus2.SMBus`` the drivers use, so the driver code
runs unchanged on a real bus, on one multiplexer channel
(:class:`~feelmysign.backends.tca9548a.MuxChannel`) or on the emulated bus
(:class:`~feelmysign.backends.emulated_i2c.EmulatedI2CBus`).
"""

from __future__ import annotations

import errno
from typing import Protocol

from feelmysign.errors import HardwareError

# What Linux's i2c-dev returns when no device acknowledges its address.
REMOTE_IO_ERRNO = errno.EREMOTEIO  # 121, "Remote I/O error"

_SIM_HINT = "or use --backend sim to run without hardware"


class I2CBus(Protocol):
    """The SMBus byte transactions the drivers use (a subset of ``smbus2.SMBus``)."""

    def read_byte(self, i2c_addr: int, /) -> int: ...

    def write_byte(self, i2c_addr: int, value: int, /) -> None: ...

    def read_byte_data(self, i2c_addr: int, register: int, /) -> int: ...

    def write_byte_data(self, i2c_addr: int, register: int, value: int, /) -> None: ...

    def close(self) -> None: ...


def is_no_answer(error: OSError) -> bool:
    """True when ``error`` means that nothing acknowledged the address (a missing chip)."""
    return error.errno == REMOTE_IO_ERRNO


def open_smbus(bus_number: int) -> I2CBus:
    """Open ``/dev/i2c-<bus_number>``, turning the usual set-up mistakes into a HardwareError."""
    device = f"/dev/i2c-{bus_number}"
    try:
        import smbus2  # imported here so the simulator never needs it
    except ImportError as error:
        raise HardwareError(
            f"The smbus2 package is missing, so {device} cannot be opened: "
            f"install it with 'pip install smbus2', {_SIM_HINT}."
        ) from error
    try:
        bus: I2CBus = smbus2.SMBus(bus_number)
    except FileNotFoundError as error:
        raise HardwareError(
            f"I2C bus {bus_number} does not exist ({device} not found): enable I2C with "
            f"'sudo raspi-config' (Interface Options > I2C) and reboot, check the bus number "
            f"('bus' in the [i2c] table of the sleeve layout; 'ls /dev/i2c-*' lists the buses), "
            f"{_SIM_HINT}."
        ) from error
    except PermissionError as error:
        raise HardwareError(
            f"No permission to open {device}: add the user to the i2c group "
            f"('sudo adduser $USER i2c', then log out and in again), {_SIM_HINT}."
        ) from error
    except OSError as error:
        raise HardwareError(
            f"Cannot open I2C bus {bus_number} ({device}): {error}; check that I2C is enabled "
            f"('sudo raspi-config') and 'bus' in the [i2c] table of the sleeve layout, {_SIM_HINT}."
        ) from error
    return bus
