"""The one way feelmysign reads a file a person named: never a hang, never all of memory.

Layouts, credentials, recordings, study designs (and the recordings and layouts
they name) and emulated bus states are read through :func:`read_text`. It opens
without blocking (a fifo with no writer would wait for ever), checks the opened
file, not the name (no race between the check and the read), refuses anything
but a regular file, and reads at most ``max_bytes`` (``/dev/zero`` never ends).

Its refusals are ``OSError``s whose ``strerror`` says what was wrong and what
to do, so each loader's existing "cannot read the file: ..." message carries
them unchanged. ``loads_json`` turns JSON nested deeper than Python's stack
allows into a plain ``ValueError`` like any other malformed JSON.
"""

from __future__ import annotations

import errno
import os
import stat

TYPE_CHECKING = False  # typing itself costs a start-up import; mypy reads this name as True
if TYPE_CHECKING:  # a restarting sleeve reads its layout through here before any other import
    from typing import Any

KIB = 1024
MIB = 1024 * KIB
# Caps on what is read into memory: far above any real file, far below a machine's memory.
MAX_LAYOUT_BYTES = 1 * MIB  # the paper's sleeve is 2 KiB; a 64 x 64 wiring table ~400 KiB
MAX_CREDENTIALS_BYTES = 64 * KIB  # the broker writes about 400 bytes
MAX_RECORDING_BYTES = 64 * MIB  # an hour of drawing at 240 samples a second is ~60 MiB
MAX_STATE_BYTES = 1 * MIB  # the emulated bus of 64 chips is about 40 KiB
MAX_DESIGN_BYTES = 1 * MIB  # the paper's study design is 3 KiB
MAX_PEM_BYTES = 1 * MIB  # a certificate chain is a few KiB


class UnusableFile(OSError):
    """A path that names a fifo, a device, a folder or a file too large to read whole."""

    def __init__(self, path: str | os.PathLike[str], problem: str) -> None:
        super().__init__(errno.EINVAL, problem, os.fspath(path))


def read_bytes(path: str | os.PathLike[str], *, max_bytes: int) -> bytes:
    """The whole regular file at ``path``, if it holds at most ``max_bytes``; else UnusableFile.

    Other ``OSError``s (not found, permission denied) pass through as they are.
    """
    descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC)
    try:
        info = os.fstat(descriptor)
        check_regular(path, info, max_bytes=max_bytes)
        os.set_blocking(descriptor, True)
        chunks: list[bytes] = []
        remaining = max_bytes + 1  # one byte more says the file grew past the cap
        while remaining > 0:
            chunk = os.read(descriptor, min(remaining, 1 * MIB))
            if not chunk:
                break
            chunks.append(chunk)
            remaining -= len(chunk)
    finally:
        os.close(descriptor)
    data = b"".join(chunks)
    if len(data) > max_bytes:
        raise UnusableFile(path, _too_large(len(data), max_bytes, grew=True))
    return data


def read_text(path: str | os.PathLike[str], *, max_bytes: int) -> str:
    """:func:`read_bytes` decoded as UTF-8 (``UnicodeDecodeError`` if it is not)."""
    return read_bytes(path, max_bytes=max_bytes).decode("utf-8")


def check_regular(path: str | os.PathLike[str], info: os.stat_result, *, max_bytes: int) -> None:
    """UnusableFile unless ``info`` is of a regular file of at most ``max_bytes``."""
    check_kind(path, info)
    if info.st_size > max_bytes:
        raise UnusableFile(path, _too_large(info.st_size, max_bytes))


def check_kind(path: str | os.PathLike[str], info: os.stat_result) -> None:
    """UnusableFile unless ``info`` is of a regular file (of any size: a SQLite file is opened,
    not read whole)."""
    if stat.S_ISDIR(info.st_mode):
        raise UnusableFile(path, "it is a folder: give the path of a file in it")
    if not stat.S_ISREG(info.st_mode):
        raise UnusableFile(
            path,
            f"it is {file_kind(info.st_mode)}, not a regular file: save it to a file first, "
            "then give that file's path",
        )


def file_kind(mode: int) -> str:
    """What a non-regular file is, in words."""
    if stat.S_ISFIFO(mode):
        return "a fifo (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def size_text(n_bytes: int) -> str:
    """``n_bytes`` in bytes, KiB or MiB, as a person reads it."""
    if n_bytes >= MIB:
        return f"{n_bytes / MIB:.1f} MiB"
    if n_bytes >= KIB:
        return f"{n_bytes / KIB:.1f} KiB"
    return f"{n_bytes} bytes"


def _too_large(size: int, max_bytes: int, *, grew: bool = False) -> str:
    held = f"more than {size_text(max_bytes)}" if grew else size_text(size)
    cap = size_text(max_bytes)
    return f"it holds {held}; at most {cap} is read: check that this is the right file"


def loads_json(text: str | bytes, **options: Any) -> Any:
    """``json.loads``, with nesting too deep for the stack a ValueError like other bad JSON."""
    import json  # here: the early all-off reads a layout through this module, and no JSON

    try:
        return json.loads(text, **options)
    except RecursionError:
        raise ValueError("nested too deeply to read") from None
