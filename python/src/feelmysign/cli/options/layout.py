"""Options shared by the subcommands that need a sleeve layout (validate, plan, simplify, sleeve).

Either ``--layout FILE`` (or the ``FEELMYSIGN_LAYOUT`` environment variable) or
a bare grid ``--rows R --columns C --spacing-cm S``; any grid option left out
takes the paper's sleeve value. Giving both ``--layout`` and a grid option is a
usage error (exit 2), found while parsing.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from feelmysign.cli.options.values import (
    MAX_LAYOUT_BYTES,
    check_input_file,
    not_empty,
    number,
    whole_number,
)
from feelmysign.layout import (
    MAX_GRID_SIDE,
    MAX_SPACING_CM,
    PAPER_SLEEVE,
    Layout,
    check_layout,
    load_layout,
)

LAYOUT_ENV = "FEELMYSIGN_LAYOUT"
_GRID_DESTS = ("rows", "columns", "spacing_cm")


class _Exclusive(argparse.Action):
    """Stores the value, refusing --layout together with a grid option in either order.

    argparse's mutually exclusive groups cannot say "A, or any of B, C, D".
    """

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        others = _GRID_DESTS if self.dest == "layout" else ("layout",)
        given = [d for d in others if getattr(namespace, d, None) is not None]
        if given:
            flags = ", ".join("--" + d.replace("_", "-") for d in given)
            parser.error(
                f"{option_string} cannot be combined with {flags}: the layout file already "
                "sets the grid; edit the file or leave --layout out"
            )
        setattr(namespace, self.dest, values)


def add_layout_options(parser: argparse.ArgumentParser) -> None:
    """Add --layout and --rows/--columns/--spacing-cm (defaults: the paper's 3 x 4 sleeve)."""
    group = parser.add_argument_group(
        "sleeve layout",
        f"Give a layout file, or a bare grid; default: ${LAYOUT_ENV} if set,\nelse the "
        f"paper's sleeve ({PAPER_SLEEVE.rows} rows x {PAPER_SLEEVE.columns} columns, "
        f"{PAPER_SLEEVE.spacing_cm:g} cm apart).",
    )
    group.add_argument(
        "--layout",
        metavar="FILE",
        type=not_empty("layout file"),
        action=_Exclusive,
        help=f"sleeve layout TOML file, e.g. deploy/layouts/paper-sleeve.toml "
        f"(default: ${LAYOUT_ENV}, if set)",
    )
    for side, metavar, default in (
        ("rows", "R", PAPER_SLEEVE.rows),
        ("columns", "C", PAPER_SLEEVE.columns),
    ):
        group.add_argument(
            f"--{side}",
            metavar=metavar,
            type=whole_number(1, MAX_GRID_SIDE),
            action=_Exclusive,
            help=f"number of actuator {side}, 1 to 64 (default: {default})",
        )
    group.add_argument(
        "--spacing-cm",
        metavar="S",
        type=number(0, MAX_SPACING_CM, unit="cm", above_low=True),
        action=_Exclusive,
        help=f"distance between neighbouring actuators in cm, above 0 and at most 20 "
        f"(default: {PAPER_SLEEVE.spacing_cm:g})",
    )


def layout_given(args: argparse.Namespace) -> bool:
    """Whether a layout was asked for (--layout, a grid option, or $FEELMYSIGN_LAYOUT), rather
    than left to the default: a sender then asks the sleeve for its own."""
    given = args.layout is not None or any(getattr(args, d) is not None for d in _GRID_DESTS)
    return given or bool(os.environ.get(LAYOUT_ENV, ""))


def layout_from_args(args: argparse.Namespace) -> Layout:
    """The layout the options ask for; raises LayoutError (exit 1) for a bad file or grid."""
    if args.layout is not None:
        return _load(args.layout)
    asked = {dest: getattr(args, dest) for dest in _GRID_DESTS}
    geometry = {dest: value for dest, value in asked.items() if value is not None}
    if geometry:
        # The paper's sleeve, caps and all: only the geometry was asked to change.
        grid = replace(PAPER_SLEEVE, name="grid", **geometry)
        return check_layout(grid, f"grid {grid.rows} x {grid.columns}")
    from_env = os.environ.get(LAYOUT_ENV, "")
    if from_env:
        return _load(from_env)
    return PAPER_SLEEVE


def _load(path: str) -> Layout:
    check_input_file(path, what="layout file", max_bytes=MAX_LAYOUT_BYTES)
    return load_layout(path)
