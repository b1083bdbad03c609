"""The ``feelmysign`` command: one subcommand per module in this package.

Each subcommand module defines ``register(subparsers)``, which adds its parser
and sets ``handler`` to a function ``(args) -> int``. Errors a person can act on
print ``Error: ...`` on stderr and exit 1; usage errors exit 2 (argparse).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from feelmysign import __version__
from feelmysign.errors import FeelMySignError

# Subcommand modules, in the order `feelmysign --help` lists them.
SUBCOMMANDS = (
    "up",
    "plan",
    "simplify",
    "replay",
    "evaluate",
    "validate",
    "sleeve",
    "broker",
    "send",
    "scan",
    "buzz",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="feelmysign",
        description="Draw a shape and have it felt, as it is drawn, on a vibrotactile sleeve.",
    )
    parser.add_argument("--version", action="version", version=f"feelmysign {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in SUBCOMMANDS:
        module = importlib.import_module(f"feelmysign.cli.{name}")
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        code: int = args.handler(args)
    except FeelMySignError as error:
        print(f"Error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return 0
    return code


if __name__ == "__main__":
    sys.exit(main())
