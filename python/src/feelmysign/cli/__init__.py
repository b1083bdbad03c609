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
from feelmysign.cli._early_off import switch_off_early
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
    "stop",
    "scan",
    "buzz",
)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The whole command; with ``only``, just that subcommand (its module alone is imported)."""
    parser = argparse.ArgumentParser(
        prog="feelmysign",
        description="Draw a shape and have it felt, as it is drawn, on a vibrotactile sleeve.",
    )
    parser.add_argument("--version", action="version", version=f"feelmysign {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in SUBCOMMANDS if only is None else (only,):
        module = importlib.import_module(f"feelmysign.cli.{name}")
        module.register(subparsers)
    return parser


def _named_subcommand(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` names, if it names a known one first; else None (parse it all).

    Importing every subcommand costs several hundred ms (the broker, the research
    tools); a sleeve restarted after a crash must switch its motors off sooner.
    """
    first = next((arg for arg in argv if not arg.startswith("-")), None)
    return first if first in SUBCOMMANDS else None


def main(argv: Sequence[str] | None = None) -> int:
    arguments = sys.argv[1:] if argv is None else list(argv)
    command = _named_subcommand(arguments)
    switch_off_early(command, arguments)  # before the imports of build_parser
    parser = build_parser(command)
    args = parser.parse_args(arguments)
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
