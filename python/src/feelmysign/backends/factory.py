"""One place that turns ``--backend sim|drv2605 [--emulate | --emulate-state FILE]`` into a backend.

Used by the sleeve daemon and by ``feelmysign buzz``, so both refuse the same
mistakes with the same words, before any I2C traffic: an unknown backend, a
layout without wiring for the hardware, options that only one backend has.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Literal

from feelmysign.backends.actuator_config import (
    CalibrationStore,
    calibration_path,
    store_name_for_bus,
    store_name_for_state_file,
)
from feelmysign.backends.base import Backend
from feelmysign.backends.bus_lock import lock_for
from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_i2c import EmulatedI2CBus
from feelmysign.backends.emulated_state import open_state_bus
from feelmysign.backends.enable import GpiodLine, Line
from feelmysign.backends.i2c import I2CBus
from feelmysign.backends.sim import SimBackend
from feelmysign.backends.telemetry import ActuatorTelemetry
from feelmysign.early_off import targets_of
from feelmysign.errors import LayoutError, ParameterError
from feelmysign.guard import Guardian
from feelmysign.layout import ButtonLine, Layout

if TYPE_CHECKING:
    from feelmysign.backends.button import ButtonInput

BackendName = Literal["sim", "drv2605"]
BACKEND_NAMES: tuple[BackendName, ...] = ("sim", "drv2605")
# What opens a backend on a shared bus; what it does not do when another process holds it.
BusRole = Literal["sleeve", "buzz"]
REFUSED: dict[BusRole, str] = {
    "sleeve": "This sleeve does not start: one bus drives one sleeve.",
    "buzz": "Nothing was buzzed.",
}


def open_backend(
    name: BackendName,
    layout: Layout,
    *,
    record: str | os.PathLike[str] | None = None,
    telemetry: ActuatorTelemetry | None = None,
    emulate: bool = False,
    emulate_state: str | os.PathLike[str] | None = None,
    leave_out_missing: bool = False,
    role: BusRole = "sleeve",
) -> Backend:
    """An open backend for ``layout``, every actuator silent; close it (or use ``with``).

    ``sim`` records what would be felt (``record``: a JSON-lines file of every
    change). ``drv2605`` drives the chips on ``/dev/i2c-<layout.i2c_bus>``, or,
    with ``emulate``, on an emulated bus wired as the layout says (to try the
    hardware path without hardware); ``emulate_state`` keeps that bus's registers
    in a file across processes (see :mod:`feelmysign.backends.emulated_state`)
    and implies ``emulate``; ``leave_out_missing``: see ``Drv2605Backend``.

    A bus shared with other processes (the real one, or one kept in a file) is locked
    for ``role`` (``sleeve``, ``buzz``: see :mod:`feelmysign.backends.bus_lock`) before
    any I2C traffic, until the backend is closed. Raises ParameterError for a bad choice,
    LayoutError for a layout without wiring, BusBusyError (a HardwareError) when another
    process holds the bus, HardwareError when the chips do not answer (see
    :meth:`Drv2605Backend.open`).
    """
    if name not in BACKEND_NAMES:
        raise ParameterError(
            "backend", name, "'sim' (the simulator) or 'drv2605' (DRV2605L chips over I2C)"
        )
    if name == "sim":
        return _open_sim(
            layout, record=record, telemetry=telemetry, emulate=emulate or emulate_state is not None
        )
    if record is not None:
        raise ParameterError(
            "record",
            os.fspath(record),
            "left out with the drv2605 backend: only the simulator records (--backend sim)",
        )
    check_wired(layout)
    # An emulated bus without a file is this process's own: nobody to share it with.
    lock = None if emulate and emulate_state is None else lock_for(layout.i2c_bus, emulate_state)
    if lock is not None:
        lock.acquire(role, refused=REFUSED[role])
    try:
        bus: I2CBus | None = None
        if emulate_state is not None:
            bus = open_state_bus(emulate_state, layout)
        elif emulate:
            bus = EmulatedI2CBus.for_layout(layout)
        backend = Drv2605Backend(
            layout,
            bus=bus,
            telemetry=telemetry,
            enable=enable_line_for(layout, bus),
            calibration=calibration_store_for(layout, emulate_state),
            # An emulated bus without a file starts from reset values every time: a fresh sleeve.
            calibrate=emulate and emulate_state is None,
            leave_out_missing=leave_out_missing,
            bus_lock=lock,
        )
        backend.open()
        if lock is not None and role == "sleeve":
            # After the first all-off, in the background: off the first command's path.
            backend.guard(Guardian(targets_of(layout), _fspath(emulate_state)))
    except BaseException:
        if lock is not None:
            lock.release()  # open() failed with every motor it reached off
        raise
    return backend


def _fspath(path: str | os.PathLike[str] | None) -> str | None:
    return None if path is None else os.path.abspath(os.fspath(path))


def calibration_store_for(
    layout: Layout, emulate_state: str | os.PathLike[str] | None
) -> CalibrationStore:
    """Where the chips' auto-calibration results are kept: the sleeve's state directory, one
    file per I2C bus (an emulated bus kept in a file counts as a bus of its own)."""
    if emulate_state is not None:
        return CalibrationStore(calibration_path(store_name_for_state_file(emulate_state)))
    return CalibrationStore(calibration_path(store_name_for_bus(layout.i2c_bus)))


def enable_line_for(layout: Layout, bus: I2CBus | None) -> Line | None:
    """The layout's enable line: the emulated bus's own, or the real GPIO (gpiod is imported
    only when the line is requested); None for a layout without one."""
    if layout.enable is None:
        return None
    if isinstance(bus, EmulatedI2CBus):
        return bus.add_enable_line(layout.enable.chip, layout.enable.line)
    return GpiodLine(layout.enable)


def button_inputs(
    layout: Layout, backend: Backend, *, sim_pipe: str | None = None
) -> list[tuple[ButtonLine, ButtonInput]]:
    """The wearer's buttons of ``layout`` ([controls]), each with its line: the emulated bus's
    own when ``backend`` drives one (pressed through the pipe next to its state file, if it
    has one); emulated too with the simulator when ``sim_pipe`` is given, pressed through it
    (``feelmysign up``: a sender trying a sleeve builder's layout on a machine with no GPIO);
    else the real GPIO line (gpiod is imported when it is requested)."""
    from feelmysign.backends.button import GpiodButton
    from feelmysign.backends.emulated_button import ButtonPipe, EmulatedButton, pipe_path

    if isinstance(backend, SimBackend) and sim_pipe is not None:
        buttons = {(b.chip, b.line): EmulatedButton(b.chip, b.line) for b in layout.buttons}
        if buttons:
            ButtonPipe(buttons, sim_pipe).open()
        return [(b, buttons[(b.chip, b.line)]) for b in layout.buttons]
    bus = getattr(backend, "bus", None)
    if not isinstance(bus, EmulatedI2CBus):
        return [(button, GpiodButton(button)) for button in layout.buttons]
    found: list[tuple[ButtonLine, ButtonInput]] = [
        (button, bus.add_button(button.chip, button.line)) for button in layout.buttons
    ]
    if found and bus.state_path is not None:
        ButtonPipe(bus.buttons, pipe_path(bus.state_path)).open()
    return found


def _open_sim(
    layout: Layout,
    *,
    record: str | os.PathLike[str] | None,
    telemetry: ActuatorTelemetry | None,
    emulate: bool,
) -> SimBackend:
    if emulate:
        raise ParameterError(
            "emulate",
            emulate,
            "False with the sim backend: --emulate and --emulate-state stand in for the "
            "drv2605 hardware; use them with --backend drv2605",
        )
    backend = SimBackend(layout, record=record, telemetry=telemetry)
    try:
        backend.open()
    except OSError as error:  # only the record file can fail here
        raise ParameterError(
            "record", os.fspath(record or ""), f"a file that can be written ({error.strerror})"
        ) from error
    return backend


def check_wired(layout: Layout) -> None:
    """LayoutError unless ``layout`` says which chip drives each actuator (its [i2c] table)."""
    if layout.wiring:
        return  # the rest (every actuator once, channels unique) is checked on open
    raise LayoutError(
        layout.name,
        [
            "i2c.wiring: missing, so the drv2605 backend cannot know which DRV2605L drives "
            "which motor; give --layout FILE with an [i2c] table (start from "
            "deploy/layouts/paper-sleeve.toml, see docs/sleeve-hardware.md), or use "
            "--backend sim to run without hardware"
        ],
    )
