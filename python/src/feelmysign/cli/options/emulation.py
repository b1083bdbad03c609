"""``--emulate-state FILE``, for the commands that drive or probe chips: sleeve, up, scan, buzz."""

from __future__ import annotations

import argparse

from feelmysign.cli.options.values import MAX_STATE_BYTES, existing_or_new_file


def add_emulate_state_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--emulate-state",
        metavar="FILE",
        type=existing_or_new_file("emulated state file", MAX_STATE_BYTES),
        help="like --emulate, but the emulated chips keep their registers in FILE across "
        "processes, as real chips do when a process dies (created, every chip at its reset "
        "values, if missing; see docs/sleeve-hardware.md)",
    )
