"""The ``feelmysign`` command: one subcommand per module in this package.

Each subcommand module defines ``register(subparsers)``, which adds its parser
and sets ``handler`` to a function ``(args) -> int``. Errors a person can act on
print one ``Error: ...`` line on stderr and exit 1; usage errors exit 2 (one
``Error:`` line too, see ``options.parser``). Anything else that escapes a command is
a bug: it still gets one ``Error:`` line, with a request to report it, and exit
70 (EX_SOFTWARE); ``FEELMYSIGN_DEBUG=1`` shows its traceback instead.
"""

from __future__ import annotations

import os
import sys

# Nothing else at module level: a sleeve restarted after a crash imports this
# package, then switches its motors off (main), before any other import.
from feelmysign.early_off import switch_off_early

TYPE_CHECKING = False  # typing itself costs a start-up import; mypy reads this name as True
if TYPE_CHECKING:
    import argparse
    from collections.abc import Sequence
    from typing import Any, TextIO

    from feelmysign.cli.options.parser import CliParser

DEBUG_ENV = "FEELMYSIGN_DEBUG"
BUG_EXIT = 70  # EX_SOFTWARE (sysexits.h): an internal error, not the user's

# Subcommand modules, in the order `feelmysign --help` lists them.
SUBCOMMANDS = (
    "up",
    "plan",
    "simplify",
    "replay",
    "evaluate",
    "study",
    "validate",
    "sleeve",
    "broker",
    "send",
    "stop",
    "scan",
    "buzz",
    "off",
)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The whole command; with ``only``, just that subcommand (its module alone is imported)."""
    import importlib

    from feelmysign import __version__
    from feelmysign.cli.options.parser import CliParser

    parser = CliParser(
        prog="feelmysign",
        description="Draw a shape and have it felt, as it is drawn, on a vibrotactile sleeve.",
    )
    parser.add_argument("--version", action="version", version=f"feelmysign {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in SUBCOMMANDS if only is None else (only,):
        try:
            module = importlib.import_module(f"feelmysign.cli.{name}")
        except ImportError as error:
            if (error.name or "feelmysign").startswith("feelmysign"):
                raise  # our own module missing is a bug, not an extra left out
            _register_missing_extra(subparsers, name, error.name or str(error))
            continue
        missing = _first_missing(getattr(module, "REQUIRES", ()))
        if missing is not None:
            _register_missing_extra(subparsers, name, missing)
            continue
        module.register(subparsers)
    return parser


def _first_missing(packages: Sequence[str]) -> str | None:
    """The first of ``packages`` that cannot be imported here, found without importing it.

    A subcommand imports its heavy packages when it runs, not when the parser is built
    (``feelmysign --help`` stays quick); its ``REQUIRES`` names them so that a command
    whose extra is not installed is still listed as such.
    """
    import importlib.util

    for package in packages:
        try:
            if importlib.util.find_spec(package) is None:
                return package
        except (ImportError, ValueError):  # ValueError: sys.modules[package] is None
            return package
    return None


def _register_missing_extra(
    subparsers: argparse._SubParsersAction[CliParser], name: str, missing: str
) -> None:
    """A command whose packages are not installed ('make up' leaves the [research] extra out):
    listed, and saying how to get them when run."""
    import argparse

    from feelmysign.errors import FeelMySignError

    parser = subparsers.add_parser(
        name,
        help=f"(not installed here: needs {missing}, from 'make test')",
        description=f"feelmysign {name} needs the research tools, which are not installed "
        "here: run 'make test', or .venv/bin/pip install -e 'python[research]'.",
    )
    parser.add_argument("rest", nargs=argparse.REMAINDER)

    def handler(_args: argparse.Namespace) -> int:
        raise FeelMySignError(
            f"feelmysign {name} needs the research tools ({missing} is missing): run "
            "'make test', which installs them, or .venv/bin/pip install -e 'python[research]'"
        )

    parser.set_defaults(handler=handler)


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
    switch_off_early(command, arguments)  # first: before any other import
    from typing import TextIO, cast

    stdout = sys.stdout
    sys.stdout = cast(TextIO, _ReaderMayLeave(stdout))
    try:
        return _run(arguments, command)
    finally:
        sys.stdout = stdout


def _run(arguments: list[str], command: str | None) -> int:
    from feelmysign.errors import FeelMySignError

    try:
        args = build_parser(command).parse_args(arguments)
        code: int = args.handler(args)
    except FeelMySignError as error:
        print(f"Error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        _silence_stdout()
        return 0
    except Exception as error:  # the last resort: a bug, told in one line, not a traceback
        if os.environ.get(DEBUG_ENV):
            raise
        print(_bug_message(error), file=sys.stderr)
        return BUG_EXIT
    return code


def _bug_message(error: Exception) -> str:
    detail = " ".join(str(error).split())[:300] or "no detail"
    return (
        f"Error: unexpected {type(error).__name__} ({detail}). This is a bug in feelmysign: "
        f"please report it with the command you ran; run it again with {DEBUG_ENV}=1 to "
        "see where it happened."
    )


class _ReaderMayLeave:
    """Standard output that outlives its reader (``feelmysign up | head -3``).

    A command that runs on (``up``, ``sleeve``, ``broker``) prints from several
    threads; a closed pipe must not end the thread that prints (the watchdog that
    restarts the broker, the MQTT thread that logs drawings). Once the reader has
    gone, what is printed goes nowhere.
    """

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            _silence_stdout()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            _silence_stdout()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def _silence_stdout() -> None:
    """The reader went away (``| head``): nothing more to say, not even at exit's flush."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


if __name__ == "__main__":
    sys.exit(main())
