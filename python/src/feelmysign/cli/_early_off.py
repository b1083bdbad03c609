"""Every motor off first thing, before a starting command pays for its imports.

A DRV2605L keeps driving its motor after the process that set it dies, so a
sleeve restarted after a crash must switch the motors off as its first act.
Its normal start-up does (the backend switches every chip off before it checks
any), but only after importing the MQTT client and the broker tools, which
takes a few hundred milliseconds on a busy Raspberry Pi. This reads only the
options that say where the chips are and switches them off at once, before
the full command line is even parsed.

It is best effort and quiet on purpose: whatever goes wrong here (no layout,
no bus, a missing chip) the command's own start-up switches everything off
again and then reports the problem with the usual error.
"""

from __future__ import annotations

import argparse
import logging
import os
import stat
from collections.abc import Sequence
from typing import NoReturn

log = logging.getLogger(__name__)

# The commands that drive motors, and their --backend default ("scan" only reads).
EARLY_COMMANDS = {"sleeve": "sim", "buzz": "drv2605"}
LAYOUT_ENV = "FEELMYSIGN_LAYOUT"  # as cli/_options.py reads it
MAX_LAYOUT_BYTES = 1_000_000  # a layout is a few kB; this pass reads nothing bigger


class _Unparsable(Exception):
    pass


class _QuietParser(argparse.ArgumentParser):
    """Raises instead of printing usage and exiting: the real parser does that later."""

    def error(self, message: str) -> NoReturn:
        raise _Unparsable(message)


def switch_off_early(command: str | None, arguments: Sequence[str]) -> None:
    """If ``command`` drives the sleeve's chips, switch every one of them off now."""
    if command not in EARLY_COMMANDS:
        return
    parser = _QuietParser(add_help=False, allow_abbrev=False)
    parser.add_argument("--backend", default=EARLY_COMMANDS[command])
    parser.add_argument("--layout", default=os.environ.get(LAYOUT_ENV) or None)
    parser.add_argument("--emulate", action="store_true")
    parser.add_argument("--emulate-state")
    try:
        options, _ = parser.parse_known_args(list(arguments))
    except _Unparsable:
        return
    if options.backend != "drv2605" or options.layout is None:
        return  # the simulator, or a bare grid (which wires no chip)
    if options.emulate and options.emulate_state is None:
        return  # a fresh emulated bus starts with every motor off
    if not _plain_small_file(options.layout):
        return  # a fifo or a device would hang or flood this pass: the real parser refuses it
    _switch_off(options.layout, options.emulate_state)


def _plain_small_file(path: str) -> bool:
    try:
        status = os.stat(path)
    except OSError:
        return False
    return stat.S_ISREG(status.st_mode) and status.st_size <= MAX_LAYOUT_BYTES


def _switch_off(layout_path: str, emulate_state: str | None) -> None:
    from feelmysign.backends.drv2605 import Drv2605Backend
    from feelmysign.backends.i2c import I2CBus
    from feelmysign.errors import FeelMySignError
    from feelmysign.layout import load_layout

    try:
        # Both files are read through feelmysign.input_files: a fifo or /dev/zero is refused
        # without waiting (the command says why later).
        layout = load_layout(layout_path)
        bus: I2CBus | None = None
        if emulate_state is not None:
            from feelmysign.backends.emulated_state import open_state_bus

            bus = open_state_bus(emulate_state, layout)
        problems = Drv2605Backend(layout, bus=bus).switch_off_unchecked()
    except (FeelMySignError, OSError) as error:
        problems = [str(error)]
    for problem in problems:  # reported again, with advice, by the command's own start-up
        log.debug("early all-off: %s", problem)
