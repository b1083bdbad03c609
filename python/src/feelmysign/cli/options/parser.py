"""The parser of every ``feelmysign`` command: one ``Error:`` line per usage error.

argparse prints its usage block and ``prog: error: ...``; a person then has to
find the one line that matters. Here a usage error is that line alone, as
``Error: ...`` on stderr with a pointer to ``--help``, and exit status 2.

A negative stroke such as ``-1,0,1,0,500`` is a positional argument, not an
unknown option: no option of ours starts with a digit (Python 3.13 reads any
``-<digit>`` this way too).
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from typing import Any, NoReturn, TypeAlias

from feelmysign.cli.options.values import decimal_float_option, decimal_int_option

USAGE_ERROR_EXIT = 2
# '-' then a digit, or '-.' then a digit: a number or a stroke, never one of our options.
_NEGATIVE_NUMBER = re.compile(r"^-\.?\d")
_ARGUMENT_PREFIX = re.compile(r"^argument (?=\S+: )")


class CliParser(argparse.ArgumentParser):
    """An ArgumentParser whose subparsers are CliParsers too (argparse copies the class)."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self._negative_number_matcher = _NEGATIVE_NUMBER
        # Every type=float and type=int option takes decimal digits only: "1_0" is not 10.
        self.register("type", float, decimal_float_option)
        self.register("type", int, decimal_int_option)

    def parse_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> argparse.Namespace:
        """As argparse's, but an argument no command takes is told with the help of the
        command it was given to ('feelmysign stop --help'), not the program's."""
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            command = getattr(parsed, "command", None)
            prog = f"{self.prog} {command}" if isinstance(command, str) else self.prog
            self._fail(f"unrecognized arguments: {' '.join(extras)}", prog)
        return parsed

    def error(self, message: str) -> NoReturn:
        self._fail(message, self.prog)

    def _fail(self, message: str, prog: str) -> NoReturn:
        text = " ".join(message.split()).rstrip(".")
        # "argument --port: 99999 is out of range" -> "--port: 99999 is out of range"
        text = _ARGUMENT_PREFIX.sub("", text)
        sys.stderr.write(f"Error: {text}. See '{prog} --help'.\n")
        sys.exit(USAGE_ERROR_EXIT)


# What ``register(subparsers)`` of each subcommand module receives: the parser's subcommands.
Subcommands: TypeAlias = "argparse._SubParsersAction[argparse.ArgumentParser]"


def add_command(subparsers: Subcommands, name: str, **options: Any) -> argparse.ArgumentParser:
    """A ``feelmysign`` subcommand whose --help prints its description (most often its
    module's docstring) as written: paragraphs, lists and examples kept, not re-wrapped."""
    return subparsers.add_parser(
        name, formatter_class=argparse.RawDescriptionHelpFormatter, **options
    )
