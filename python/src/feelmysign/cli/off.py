"""``feelmysign off``: switch every motor of the sleeve off, whatever state the chips are in.

    feelmysign off --layout /etc/feelmysign/layout.toml
    feelmysign off --layout deploy/layouts/paper-sleeve.toml --emulate-state bus.json

With an enable line in the layout (``i2c.enable``), drives it low first, so
every motor stops at once whether its chip answers or not, and leaves it low.
Then writes "off" to every DRV2605L the layout wires (real-time level 0, then
standby), trying each one even when another does not answer, and checks
nothing first. Meant for after a crash: the sleeve's service runs it as soon
as the sleeve process has ended, however it ended (``ExecStopPost``), so a
motor left on by a ``kill -9`` or a crash is not left on until the restart.
Exit 0 when every chip took the "off", 1 (naming the chips) otherwise; with an
enable line, 0 naming them (the line, left low, holds every motor off).

Never refused, not even while a sleeve runs on the same bus: the "off" goes out
all the same. But that sleeve drives the motors again with its next stroke (and
holds the enable line, which off cannot drop then), so off then names it (PID,
command), says how to stop it (``sudo systemctl stop feelmysign-sleeve`` for
the service, Ctrl-C where it runs otherwise; it switches every motor off as it
stops) and exits 1. Likewise, naming it, beside a running buzz or scan.
"""

from __future__ import annotations

import argparse
import os

from feelmysign.backends.bus_lock import Holder, holder_of, lock_for
from feelmysign.backends.drv2605 import Drv2605Backend
from feelmysign.backends.emulated_state import open_state_bus
from feelmysign.backends.factory import enable_line_for
from feelmysign.backends.i2c import I2CBus
from feelmysign.cli.options.emulation import add_emulate_state_option
from feelmysign.cli.options.layout import LAYOUT_ENV
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.errors import HardwareError, LayoutError
from feelmysign.layout import load_layout


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "off",
        help="switch every motor of the sleeve off (after a crash)",
        description=__doc__,
    )
    parser.add_argument(
        "--layout",
        metavar="FILE",
        help=f"sleeve layout TOML file with an [i2c] table (default: ${LAYOUT_ENV})",
    )
    add_emulate_state_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    path = args.layout or os.environ.get(LAYOUT_ENV, "")
    if not path:
        raise LayoutError(
            "feelmysign off",
            [f"no layout: give --layout FILE (or set {LAYOUT_ENV}) with the sleeve's [i2c] wiring"],
        )
    layout = load_layout(path)
    if not layout.wiring:
        raise LayoutError(
            layout.name,
            ["i2c.wiring: missing, so there is no chip to switch off; give the sleeve's layout"],
        )
    bus: I2CBus | None = None
    where = f"/dev/i2c-{layout.i2c_bus}"
    # Who else drives this bus, if anyone: looked at, never waited for.
    holder = holder_of(lock_for(layout.i2c_bus, args.emulate_state or None).path)
    if args.emulate_state:
        bus, where = (
            open_state_bus(args.emulate_state, layout),
            f"the emulated bus in {args.emulate_state}",
        )
    enable = enable_line_for(layout, bus)
    problems = Drv2605Backend(layout, bus=bus, enable=enable).switch_off_unchecked()
    if holder is not None:
        return _held_by(holder, problems, f"{len(layout.wiring)} DRV2605L on {where}")
    if problems and enable is not None and not any("enable line" in p for p in problems):
        listed = "\n".join(f"  - {p}" for p in problems)
        print(
            f"The {enable.description} is low, so every motor is off; these chips did not take "
            f"the I2C off too ({where}):\n{listed}",
            flush=True,
        )
        return 0
    if problems:
        listed = "\n".join(f"  - {p}" for p in problems)
        raise HardwareError(
            f"Not every motor could be switched off on {where}; if one keeps vibrating, cut the "
            f"sleeve's power:\n{listed}"
        )
    line = "" if enable is None else f", and the {enable.description} is low"
    print(f"Every motor is off ({len(layout.wiring)} DRV2605L on {where}{line}).", flush=True)
    return 0


def _held_by(holder: Holder, problems: list[str], chips: str) -> int:
    """The "off" went out while another process holds the bus: say what was done, then who
    will drive the motors again and how to stop it (HardwareError: exit 1)."""
    if problems:
        listed = "\n".join(f"  - {p}" for p in problems)
        print(f"The off went out to every chip that answered ({chips}), but:\n{listed}", flush=True)
    else:
        print(f"Every motor is off for now ({chips}).", flush=True)
    if holder.is_sleeve:
        again = (
            f"A sleeve runs on this bus, {holder.describe()}: it drives the motors again "
            "with its next stroke"
        )
    else:
        again = (
            f"Another feelmysign command uses this bus, {holder.describe()}: it may switch "
            "a motor on again until it ends"
        )
    raise HardwareError(f"{again}. To keep every motor off, {holder.how_to_stop()}.")
