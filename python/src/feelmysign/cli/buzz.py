"""``feelmysign buzz``: switch one motor on for a moment, to check its wiring.

    feelmysign buzz 0 0 --layout /etc/feelmysign/layout.toml          # row 0, column 0
    feelmysign buzz 1 2 --intensity 0.5 --duration-ms 300 --layout deploy/layouts/paper-sleeve.toml
    feelmysign buzz 1 2 --backend sim                                   # no hardware needed

Row and column are grid indices (row 0 = y 0, column 0 = x 0; see the layout
file's drawing). The intensity is capped at the layout's safety.max_intensity
and the duration at its safety.max_on_time_ms. Every motor is switched off
afterwards, also on Ctrl-C or an error. With an enable line in the layout
(``i2c.enable``) the line goes high for the buzz, once every chip is off and
checked, and low again before the "off" goes out over I2C.

A DRV2605L that does not answer does not keep the others from being tried: it is
named on stderr and left out, and buzzing its own motor is the error (with an
enable line, which switches every chip, a missing chip keeps every motor off).

While a sleeve runs on the same bus (or another buzz or scan), buzz refuses
before any I2C traffic, naming that process (PID, command), exit 1: two
processes must not drive one bus. Stop the sleeve first (``sudo systemctl stop
feelmysign-sleeve`` for the service, Ctrl-C where it runs otherwise).
"""

from __future__ import annotations

import argparse
import math
import sys
import time

from feelmysign.backends.base import Backend, check_actuator
from feelmysign.backends.factory import BACKEND_NAMES, open_backend
from feelmysign.backends.sim import SimBackend
from feelmysign.cli.options.emulation import add_emulate_state_option
from feelmysign.cli.options.layout import add_layout_options, layout_from_args
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.errors import HardwareError, ParameterError
from feelmysign.layout import Layout
from feelmysign.services.stop_signals import interrupt_on_stop_signals

DEFAULT_DURATION_MS = 1000.0  # long enough to feel and to find by touch which motor it is


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "buzz",
        help="switch one motor on for a moment, to check its wiring",
        description=__doc__,
    )
    parser.add_argument("row", type=int, metavar="ROW", help="the motor's row, from 0")
    parser.add_argument("column", type=int, metavar="COLUMN", help="the motor's column, from 0")
    parser.add_argument(
        "--intensity",
        type=float,
        metavar="A",
        help="drive level in [0, 1], capped at the layout's safety.max_intensity "
        "(default: the layout's default_intensity)",
    )
    parser.add_argument(
        "--duration-ms",
        type=float,
        default=DEFAULT_DURATION_MS,
        metavar="D",
        help=f"how long the motor stays on, in ms, capped at the layout's safety.max_on_time_ms "
        f"(default: {DEFAULT_DURATION_MS:g})",
    )
    parser.add_argument(
        "--backend",
        choices=BACKEND_NAMES,
        default="drv2605",
        help="drv2605: the sleeve's chips over I2C; sim: the simulator (default: drv2605)",
    )
    parser.add_argument(
        "--emulate",
        action="store_true",
        help="with drv2605: an emulated I2C bus wired as the layout says, instead of the hardware",
    )
    add_emulate_state_option(parser)
    add_layout_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    layout = layout_from_args(args)
    check_actuator(layout, args.row, args.column)
    intensity, intensity_note = _intensity(args.intensity, layout)
    duration_ms, duration_note = _duration_ms(args.duration_ms, layout)
    backend = open_backend(
        args.backend,
        layout,
        emulate=args.emulate,
        emulate_state=args.emulate_state,
        leave_out_missing=True,
        role="buzz",
    )
    try:
        _check_not_missing(backend, args.row, args.column)
    except BaseException:
        backend.close()
        raise
    where = _where(args, layout)
    line = layout.enable
    for note in (intensity_note, duration_note):
        if note:
            print(note, flush=True)
    if line is not None and args.backend == "drv2605":
        print(f"Enable line {line.name} high: every chip is off and checked.", flush=True)
    print(
        f"Buzzing row {args.row}, column {args.column}{where} at intensity {intensity:g} "
        f"for {duration_ms:g} ms...",
        flush=True,
    )
    started_s = time.monotonic()
    interrupt_on_stop_signals()
    try:
        backend.set_intensity(args.row, args.column, intensity)
        # The motor is meant to run this long: a timed wait, not a wait for an event.
        time.sleep(duration_ms / 1000)
    except KeyboardInterrupt:
        elapsed_ms = (time.monotonic() - started_s) * 1000
        print(f"Interrupted after {elapsed_ms:.0f} ms.", flush=True)
        raise
    finally:
        backend.close()  # all off first (the enable line low before that), then the bus
        after = (
            "" if line is None or args.backend != "drv2605" else f" Enable line {line.name} low."
        )
        print(f"Every motor is off.{after}", flush=True)
    if isinstance(backend, SimBackend):
        for change in backend.changes:
            print(
                f"  t = {change.t_ms:8.1f} ms  row {change.row}, column {change.column}: "
                f"intensity {change.intensity:g}"
            )
    return 0


def _check_not_missing(backend: Backend, row: int, column: int) -> None:
    """Name the chips that did not answer (left out); HardwareError when ours is one."""
    missing = getattr(backend, "missing", {})
    for where in missing.values():
        print(
            f"Note: no DRV2605L answered on {where}: left out (check its wiring, or run "
            "'feelmysign scan').",
            file=sys.stderr,
            flush=True,
        )
    if (row, column) in missing:
        raise HardwareError(
            f"Cannot buzz row {row}, column {column}: its DRV2605L, on {missing[(row, column)]}, "
            "did not answer. Check that chip's wiring and power, or run 'feelmysign scan' to "
            "see what answers where; every other motor was switched off."
        )


def _intensity(requested: float | None, layout: Layout) -> tuple[float, str]:
    if requested is None:
        requested = layout.default_intensity
    if not (math.isfinite(requested) and 0.0 <= requested <= 1.0):
        raise ParameterError("--intensity", requested, "a number in [0, 1]")
    return _capped("Intensity", requested, "max_intensity", layout.max_intensity)


def _duration_ms(requested: float, layout: Layout) -> tuple[float, str]:
    if not (math.isfinite(requested) and requested > 0):
        raise ParameterError("--duration-ms", requested, "a number of milliseconds above 0")
    return _capped("Duration", requested, "max_on_time_ms", layout.max_on_time_ms, unit=" ms")


def _where(args: argparse.Namespace, layout: Layout) -> str:
    if args.backend == "sim":
        return " on the simulator"
    wire = next(w for w in layout.wiring if (w.row, w.column) == (args.row, args.column))
    bus = f"/dev/i2c-{layout.i2c_bus}"
    if args.emulate_state:
        bus = f"the emulated I2C bus in {args.emulate_state}"
    elif args.emulate:
        bus = "an emulated I2C bus"
    return f" (DRV2605L on multiplexer 0x{wire.multiplexer:02X} channel {wire.channel}, {bus})"


def _capped(
    what: str, requested: float, limit_name: str, limit: float, *, unit: str = ""
) -> tuple[float, str]:
    """``requested`` held to the layout's safety limit, with the note saying so when it was."""
    if requested > limit:
        note = f"{what} {requested:g}{unit} capped at the layout's safety.{limit_name}"
        return limit, f"{note} {limit:g}{unit}."
    return requested, ""
