"""What a person types and the files they name, checked in one place before any work.

Every subcommand reads its numbers, ports, topics, sleeve ids, input files and
output folders through these, so one bad value gets one ``Error:`` line that
names the option, the value, the allowed range and what to do, never a
traceback from deep inside (an OverflowError from ``1e308`` seconds, a
MemoryError from ``/dev/zero``, a hang on a fifo).

The ``argparse`` types raise ``ArgumentTypeError`` (a usage error, exit 2);
the file checks raise ``InputError`` (exit 1).
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from feelmysign.errors import FeelMySignError
from feelmysign.input_files import (
    MAX_CREDENTIALS_BYTES,
    MAX_DESIGN_BYTES,
    MAX_LAYOUT_BYTES,
    MAX_RECORDING_BYTES,
    MAX_STATE_BYTES,
    MIB,
    UnusableFile,
    check_regular,
)
from feelmysign.input_files import size_text as _size

__all__ = [
    "MAX_CREDENTIALS_BYTES",
    "MAX_DESIGN_BYTES",
    "MAX_LAYOUT_BYTES",
    "MAX_RECORDING_BYTES",
    "MAX_STATE_BYTES",
]

MAX_STDIN_BYTES = 16 * MIB  # strokes or one document piped in: 200,000 strokes fit
# MQTT allows 65,535 bytes; the broker's ACL file and the sleeve's status take this much.
MAX_TOPIC_BYTES = 256
MAX_TIMEOUT_S = 3600.0  # an hour: a longer wait for a broker is a hang, not a wait
_TOPIC_FORBIDDEN = re.compile(r"[\s+#\x00]")


# Numbers as people write them in decimal, ASCII digits only: Python's float() and int() also
# take 1_0 (10), 0x10 with int(.., 0), inf, nan and other scripts' digits (٣ is 3).
_DECIMAL = re.compile(r"\s*[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?\s*")
_WHOLE = re.compile(r"\s*[+-]?[0-9]+\s*")


def decimal_float(text: str) -> float:
    """A number written in decimal (1, 0.5, .5, 2e-3); ValueError for anything else."""
    if not _DECIMAL.fullmatch(text):
        raise ValueError(f"not a decimal number: {text!r}")
    return float(text)


def decimal_int(text: str) -> int:
    """A whole number written in decimal digits; ValueError for anything else."""
    if not _WHOLE.fullmatch(text):
        raise ValueError(f"not a whole decimal number: {text!r}")
    return int(text, 10)


_Number = TypeVar("_Number", int, float)


def _decimal_option(
    parse: Callable[[str], _Number], what: str, example: str
) -> Callable[[str], _Number]:
    """An argparse type from ``parse``: a usage error naming what to write instead."""

    def option(text: str) -> _Number:
        try:
            return parse(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not {what}; write it with the digits 0-9, e.g. {example}"
            ) from None

    return option


# ``type=float`` and ``type=int`` of every option (CliParser registers them).
decimal_float_option = _decimal_option(decimal_float, "a decimal number", "0.25, 12 or 2e-3")
decimal_int_option = _decimal_option(decimal_int, "a whole decimal number", "3")


class InputError(FeelMySignError):
    """An input file, standard input or output folder that cannot be used; says what to do."""


# --- argparse types: a usage error (exit 2) naming the allowed range ---------------------------


def number(
    low: float,
    high: float,
    *,
    unit: str = "",
    above_low: bool = False,
) -> Callable[[str], float]:
    """A finite float in [low, high] (or (low, high] with ``above_low``)."""
    bound = "above" if above_low else "from"
    allowed = f"a number {bound} {low:g} {'and at most' if above_low else 'to'} {high:g}"
    allowed += f" {unit}" if unit else ""

    def parse(text: str) -> float:
        try:
            value = decimal_float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number; give {allowed}") from None
        too_low = value <= low if above_low else value < low
        if not math.isfinite(value) or too_low or value > high:
            raise argparse.ArgumentTypeError(f"{text} is out of range; give {allowed}")
        return value

    parse.__name__ = "number"
    return parse


def whole_number(low: int, high: int, *, unit: str = "") -> Callable[[str], int]:
    """An int in [low, high]."""
    allowed = f"a whole number from {low} to {high}" + (f" {unit}" if unit else "")

    def parse(text: str) -> int:
        try:
            value = decimal_int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a whole number; give {allowed}"
            ) from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text} is out of range; give {allowed}")
        return value

    parse.__name__ = "whole number"
    return parse


def port(*, allow_zero: bool = True) -> Callable[[str], int]:
    """A TCP port: 1 to 65535, and 0 (any free port) when ``allow_zero``."""
    allowed = "a port from 1 to 65535" + (", or 0 for any free port" if allow_zero else "")

    def parse(text: str) -> int:
        try:
            value = decimal_int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a port number; give {allowed}"
            ) from None
        if not (1 if not allow_zero else 0) <= value <= 65535:
            raise argparse.ArgumentTypeError(f"{text} is out of range; give {allowed}")
        return value

    parse.__name__ = "port"
    return parse


def topic(text: str) -> str:
    """An MQTT topic one can publish and subscribe to exactly: no wildcards, no '$' prefix."""
    rules = (
        f"give a topic name of 1 to {MAX_TOPIC_BYTES} bytes without spaces, '+' or '#', "
        "not starting with '$', e.g. deviceOne/line"
    )
    if not text:
        raise argparse.ArgumentTypeError(f"the topic is empty; {rules}")
    if _TOPIC_FORBIDDEN.search(text) or text.startswith("$"):
        raise argparse.ArgumentTypeError(
            f"{text!r} cannot be used as a topic ('+' and '#' are wildcards, '$' topics "
            f"belong to the broker); {rules}"
        )
    if len(text.encode("utf-8", "surrogatepass")) > MAX_TOPIC_BYTES:
        raise argparse.ArgumentTypeError(f"the topic is too long; {rules}")
    return text


def sleeve_id(text: str) -> str:
    """A sleeve id: one topic level of 1-64 letters, digits, '_' or '-'."""
    from feelmysign.broker.credentials import SLEEVE_ID_PATTERN

    if not SLEEVE_ID_PATTERN.fullmatch(text):
        shown = "an empty sleeve id" if not text else f"the sleeve id {text!r}"
        raise argparse.ArgumentTypeError(
            f"{shown} cannot be used; give 1 to 64 letters, digits, '_' or '-' "
            "(no '/', '+' or '#': they are MQTT topic separators and wildcards), e.g. sleeve1"
        )
    return text


def not_empty(what: str) -> Callable[[str], str]:
    """Any text but the empty string, which would silently mean "the default"."""

    def parse(text: str) -> str:
        if not text:
            raise argparse.ArgumentTypeError(
                f"an empty {what} was given; give one, or leave the option out"
            )
        return text

    parse.__name__ = what
    return parse


def existing_or_new_file(what: str, max_bytes: int) -> Callable[[str], str]:
    """A file read if it exists (and created if not): refused if it is a fifo, device or huge."""

    def parse(text: str) -> str:
        not_empty(what)(text)
        if os.path.isdir(text):
            return text  # the loader says what it expects there, in its own words
        try:
            check_input_file(text, what=what, max_bytes=max_bytes)
        except InputError as error:
            raise argparse.ArgumentTypeError(str(error).rstrip(".")) from None
        return text

    parse.__name__ = what
    return parse


# --- files --------------------------------------------------------------------------------------


def check_input_file(path: str | os.PathLike[str], *, what: str, max_bytes: int) -> None:
    """Refuse what cannot be read whole and at once: a fifo, a device, a folder, a huge file.

    ``os.stat`` never blocks (opening a fifo would wait for a writer). A path that
    does not exist passes: the loader then says so in its own words. The loaders
    read through ``feelmysign.input_files``, which checks the opened file again.
    """
    try:
        info = os.stat(path)
    except OSError:
        return
    try:
        check_regular(path, info, max_bytes=max_bytes)
    except UnusableFile as error:
        problem = str(error.strerror).removeprefix("it ")
        raise InputError(f"The {what} {str(path)!r} {problem}.") from None


def read_stdin(*, what: str, max_bytes: int = MAX_STDIN_BYTES) -> bytes:
    """All of standard input, refusing more than ``max_bytes`` (``< /dev/zero`` never ends)."""
    stream = getattr(sys.stdin, "buffer", None)  # a text stream stands in for stdin in tests
    data = (
        stream.read(max_bytes + 1)
        if stream is not None
        else sys.stdin.read(max_bytes + 1).encode("utf-8", "surrogateescape")
    )
    if len(data) > max_bytes:
        raise InputError(
            f"Standard input holds more than {_size(max_bytes)} of {what}; at most that is "
            "read: pipe in the strokes of one drawing at a time."
        )
    return data


def stdin_lines(*, what: str) -> list[str]:
    """Every line of standard input, stripped, blank ones too (UTF-8; capped as ``read_stdin``)."""
    text = read_stdin(what=what).decode("utf-8", errors="replace")
    return [line.strip() for line in text.splitlines()]


def output_folder(given: str | os.PathLike[str], *, option: str) -> Path:
    """The folder ``given``, created with its parents; InputError saying why it cannot be."""
    folder = Path(given)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise InputError(
            f"{option} {str(given)!r} is a file, not a folder: give a new or existing folder."
        ) from None
    except OSError as error:
        raise InputError(
            f"{option} {str(given)!r} cannot be created ({error.strerror or error}): give a "
            "folder you may write to, e.g. under your home folder or /tmp."
        ) from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(
            f"{option} {str(given)!r} is not writable by this user: give a folder you may write to."
        )
    return folder


def output_file(given: str | os.PathLike[str], *, option: str) -> Path:
    """A file that can be created or replaced: its folder exists and is writable."""
    path = Path(given)
    folder = path.parent
    if path.is_dir():
        raise InputError(f"{option} {str(given)!r} is a folder: give a file name, e.g. felt.jsonl.")
    if folder.exists() and not folder.is_dir():
        raise InputError(
            f"{option} {str(given)!r}: {str(folder)!r} is a file, not a folder; give a file in "
            "an existing folder."
        )
    if not folder.is_dir():
        raise InputError(
            f"{option} {str(given)!r}: the folder {str(folder)!r} does not exist; create it first "
            "or give a file in an existing folder."
        )
    if not os.access(folder, os.W_OK | os.X_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise InputError(
            f"{option} {str(given)!r} is not writable by this user: give a file in a folder you "
            "may write to."
        )
    return path
