"""``--wearer FILE``: the wearer's measured limits, for the subcommands that run a sleeve."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the planner's constants: not imported by 'feelmysign --help'
    from feelmysign.layout import Layout
    from feelmysign.wearer import Wearer


def add_wearer_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--wearer",
        metavar="FILE",
        help="the wearer's shortest felt stroke (JSON, written by 'feelmysign study threshold "
        "--save'): the sleeve advertises it in its status, and senders keep strokes above it",
    )


def wearer_from_args(args: argparse.Namespace, layout: Layout) -> Wearer | None:
    """The wearer file's limits, checked before the sleeve starts (against its ``layout``
    too: limits no stroke on it can keep are refused); None without --wearer."""
    from feelmysign.wearer import check_wearer_fits, read_wearer

    if args.wearer is None:
        return None
    wearer = read_wearer(args.wearer)
    check_wearer_fits(wearer, layout, args.wearer)
    return wearer
