"""Every motor off first thing, before a starting command pays for its imports.

A DRV2605L keeps driving its motor after the process that set it dies, so a
sleeve restarted after a crash must switch the motors off as its first act.
Its normal start-up does (the backend switches every chip off before it checks
any), but only after importing the MQTT client, the broker tools, the TOML
reader and argparse, which takes a few hundred milliseconds on a busy
Raspberry Pi. This pass runs before all of that, importing nothing but what
the interpreter has already loaded (``os``, ``sys``) and two small modules of
ours (``feelmysign.input_files``, ``feelmysign.backends.all_off``):

1. The command line is scanned by hand for ``--backend``, ``--layout``
   (or ``$FEELMYSIGN_LAYOUT``), ``--emulate`` and ``--emulate-state``.
2. The layout file is read as bytes. Which chips it wires comes from a memo
   of the last time this file was read (``$XDG_STATE_HOME/feelmysign/wiring/``,
   ``/var/lib/feelmysign/wiring/`` for the systemd unit): the memo holds the
   file's whole text, so it is used only when the file is byte for byte the
   same, and then it says exactly what the full start-up would switch off.
3. Otherwise (first start, or the layout was edited) the file is read with
   the full TOML reader, and every channel of every multiplexer that it or
   the previous memo names is switched off: the chips the edit moved may be
   the ones the killed sleeve left on. Then the memo is written for next time.

``buzz`` leaves alone a bus that another process holds (a running sleeve:
:mod:`feelmysign.backends.bus_lock`), as it then refuses; the sleeve and ``off``
switch off first whoever holds the bus, and only then look at its lock.

It is best effort and quiet on purpose: whatever goes wrong here (no layout,
no bus, a missing chip, no place to keep the memo) the command's own start-up
switches everything off again and then reports the problem with the usual error.
"""

from __future__ import annotations

import os
import sys

from feelmysign import __version__
from feelmysign.backends.all_off import CHANNELS, RawI2CBus, switch_off
from feelmysign.input_files import MAX_LAYOUT_BYTES, read_bytes

TYPE_CHECKING = False  # typing itself costs a start-up import; mypy reads this name as True
if TYPE_CHECKING:
    from collections.abc import Sequence

    from feelmysign.backends.all_off import WriteBus
    from feelmysign.layout import Layout

# The commands that drive motors, and their --backend default ("scan" only reads).
# "off" has no --backend: it always drives the chips.
EARLY_COMMANDS = {"sleeve": "sim", "buzz": "drv2605", "off": "drv2605"}
LAYOUT_ENV = "FEELMYSIGN_LAYOUT"  # as cli/options/layout.py reads it
DEBUG_ENV = "FEELMYSIGN_DEBUG"  # as cli/__init__.py reads it: a bug here is then printed
# The memo's first line: a memo another version of feelmysign wrote is a miss (its reader
# of the layout may have differed).
MEMO_FORMAT = f"feelmysign-wiring/1 {__version__}".encode()
MAX_MEMO_BYTES = MAX_LAYOUT_BYTES + 64 * 1024  # the layout's text plus a few lines of wiring

_VALUE_OPTIONS = ("--backend", "--layout", "--emulate-state")
_FLAG_OPTIONS = ("--emulate",)

# bus number -> multiplexer address -> channels
Targets = dict[int, dict[int, set[int]]]


def switch_off_early(command: str | None, arguments: Sequence[str]) -> list[str]:
    """If ``command`` drives the sleeve's chips, switch every one of them off now.

    Returns what could not be switched off, in words (the command's own start-up
    finds and reports the same again); never raises.
    """
    options = _scan_options(command, arguments)
    if options is None:
        return []
    layout_path, state_path = options
    try:
        return _switch_off(layout_path, state_path, skip_held=command == "buzz")
    except Exception as error:  # a bug here must not keep the start-up from its own all-off
        if os.environ.get(DEBUG_ENV):
            import traceback

            traceback.print_exc()
        return [f"early all-off failed: {type(error).__name__}: {error}"]


def _scan_options(command: str | None, arguments: Sequence[str]) -> tuple[str, str | None] | None:
    """(layout file, emulated state file or None) when ``command`` drives chips; else None.

    Read as argparse reads them (``--opt VALUE``, ``--opt=VALUE``, the last one
    wins, ``--`` ends the options); anything this does not understand is left
    to the real parser, which runs next and says what is wrong.
    """
    if command not in EARLY_COMMANDS:
        return None
    found: dict[str, str | None] = {"--backend": EARLY_COMMANDS[command]}
    tokens = list(arguments)
    index = 0
    while index < len(tokens):
        token = tokens[index]
        index += 1
        if token == "--":
            break
        name, equals, value = token.partition("=")
        if name in _FLAG_OPTIONS and not equals:
            found[name] = ""
        elif name in _VALUE_OPTIONS:
            if not equals:
                if index == len(tokens) or tokens[index].startswith("-"):
                    return None  # a usage error: the real parser reports it
                value = tokens[index]
                index += 1
            found[name] = value
    layout = found.get("--layout") or os.environ.get(LAYOUT_ENV) or None
    state = found.get("--emulate-state") or None
    if found["--backend"] != "drv2605" or layout is None:
        return None  # the simulator, or a bare grid (which wires no chip)
    if "--emulate" in found and state is None:
        return None  # a fresh emulated bus starts with every motor off
    return layout, state


def _switch_off(layout_path: str, state_path: str | None, *, skip_held: bool) -> list[str]:
    if state_path is not None and not os.path.exists(state_path):
        return []  # a fresh emulated bus starts with every motor off
    try:
        # Through feelmysign.input_files: a fifo or /dev/zero is refused without waiting.
        text = read_bytes(layout_path, max_bytes=MAX_LAYOUT_BYTES)
    except OSError as error:
        return [f"{layout_path}: {error.strerror or error}"]
    source = os.path.abspath(layout_path)
    memo_path = _memo_path(source)
    memo = _read_memo(memo_path, source)
    if memo is not None and memo[0] == text:
        return off(memo[1], state_path, skip_held=skip_held)  # exactly what this layout wires
    targets: Targets = {}
    if memo is not None:  # the layout was edited: what the old one wired may be on
        _add_every_channel(targets, memo[1])
    wiring = _parse_wiring(text, layout_path)
    if wiring is not None:
        _add_every_channel(targets, wiring)
        _write_memo(memo_path, source, text, wiring)
    return off(targets, state_path, skip_held=skip_held)


def off(targets: Targets, state_path: str | None, *, skip_held: bool = False) -> list[str]:
    """Every DRV2605L of ``targets`` off (on the emulated bus in ``state_path``, if given);
    what failed, in words. Also the sleeve's guardian's off (:mod:`feelmysign.guard`)."""
    problems: list[str] = []
    for bus_number, channels in sorted(targets.items()):
        if not channels:
            continue  # a layout without wiring: no chip on this bus to reach
        if skip_held and _held(bus_number, state_path):
            # buzz beside a running sleeve: it refuses, and must not touch the sleeve's bus
            # first (the sleeve and off switch off whatever holds the bus).
            problems.append(f"I2C bus {bus_number}: in use by another process, left alone")
            continue
        try:
            bus = _open_bus(bus_number, state_path)
        except OSError as error:
            problems.append(f"I2C bus {bus_number}: {error.strerror or error}")
            continue
        try:
            problems.extend(switch_off(bus, channels))
        finally:
            bus.close()
    return problems


def _held(bus_number: int, state_path: str | None) -> bool:
    from feelmysign.backends.bus_lock import holder_of, lock_for

    return holder_of(lock_for(bus_number, state_path).path) is not None


def _open_bus(bus_number: int, state_path: str | None) -> WriteBus:
    if state_path is None:
        return RawI2CBus(bus_number)
    # The emulated bus in a file: one bus, whatever the layout's number.
    from feelmysign.backends.emulated_state import EmulatedStateError, open_state_bus

    try:
        return open_state_bus(state_path, None)
    except EmulatedStateError as error:
        raise OSError(error.problem) from error


def _add_every_channel(targets: Targets, wiring: Targets) -> None:
    for bus_number, multiplexers in wiring.items():
        for multiplexer in multiplexers:
            targets.setdefault(bus_number, {})[multiplexer] = set(CHANNELS)


def _parse_wiring(text: bytes, source: str) -> Targets | None:
    """The chips ``text`` wires, read by the full layout reader; None for a layout it refuses."""
    from feelmysign.errors import LayoutError
    from feelmysign.layout import parse_layout

    try:
        layout = parse_layout(text.decode("utf-8"), source)
    except (LayoutError, UnicodeDecodeError):
        return None  # the command's own start-up says what is wrong with it
    return targets_of(layout)


def targets_of(layout: Layout) -> Targets:
    """The chips ``layout`` wires: its bus -> multiplexer -> channels."""
    channels: dict[int, set[int]] = {}
    for wire in layout.wiring:
        channels.setdefault(wire.multiplexer, set()).add(wire.channel)
    return {layout.i2c_bus: channels}


def wiring_lines(targets: Targets) -> list[str]:
    """``targets`` as the memo writes them, one ``mux BUS 0xADDRESS CHANNEL...`` line per
    multiplexer (also the guardian's command line: :mod:`feelmysign.guard`)."""
    lines = []
    for bus_number, multiplexers in sorted(targets.items()):
        for multiplexer, channels in sorted(multiplexers.items()):
            listed = " ".join(str(channel) for channel in sorted(channels))
            lines.append(f"mux {bus_number} 0x{multiplexer:02X} {listed}")
    return lines


def targets_from_lines(lines: Sequence[str | bytes]) -> Targets | None:
    """What :func:`wiring_lines` wrote; None for a line it did not write."""
    targets: Targets = {}
    try:
        for line in lines:
            kind, bus, multiplexer, *channels = line.split()
            if kind not in ("mux", b"mux"):
                return None
            targets.setdefault(int(bus), {})[int(multiplexer, 16)] = {int(c) for c in channels}
    except ValueError:
        return None
    return targets


# --- the memo ------------------------------------------------------------------------------
# Text, so that a person can read it:
#
#     feelmysign-wiring/1 0.1.0           (the memo's format, then feelmysign's version)
#     source /etc/feelmysign/layout.toml
#     mux 1 0x70 0 1 2 3 4 5 6 7        (bus, multiplexer, channels)
#     mux 1 0x71 0 1 2 3
#     layout 2718                       (then the layout file's 2718 bytes, as read)


def _memo_path(source: str) -> str:
    """Where the memo of the layout file ``source`` is kept: one file per layout path."""
    import zlib  # a checksum names the file; the memo holds the path, so a clash is a miss

    state_home = os.environ.get("XDG_STATE_HOME") or os.path.expanduser("~/.local/state")
    name = f"{zlib.crc32(os.fsencode(source)):08x}.txt"
    return os.path.join(state_home, "feelmysign", "wiring", name)


def _read_memo(path: str, source: str) -> tuple[bytes, Targets] | None:
    """(the layout text, the chips it wires) from the memo at ``path``; None if unusable."""
    try:
        data = read_bytes(path, max_bytes=MAX_MEMO_BYTES)
    except OSError:
        return None
    header, separator, text = data.partition(b"\nlayout ")
    size, newline, text = text.partition(b"\n")
    lines = header.split(b"\n")
    if not (separator and newline) or lines[:2] != [MEMO_FORMAT, b"source " + os.fsencode(source)]:
        return None
    try:
        if int(size) != len(text):
            return None  # cut short: a memo is replaced whole, but a disk may fill up
    except ValueError:
        return None
    targets = targets_from_lines(lines[2:])
    return None if targets is None else (text, targets)


def _write_memo(path: str, source: str, text: bytes, wiring: Targets) -> None:
    """Keep ``wiring`` for the next start with this layout; quietly not, where it cannot be."""
    if "\n" in source:
        return  # the memo is one path per line
    lines = [MEMO_FORMAT, b"source " + os.fsencode(source)]
    lines.extend(line.encode() for line in wiring_lines(wiring))
    lines.append(b"layout %d" % len(text))
    temporary = f"{path}.{os.getpid()}.tmp"
    try:
        os.makedirs(os.path.dirname(path), mode=0o700, exist_ok=True)
        with open(temporary, "wb") as memo:
            memo.write(b"\n".join(lines) + b"\n" + text)
        os.replace(temporary, path)  # whole or not at all, for a reader at any moment
    except OSError as error:
        if os.environ.get(DEBUG_ENV):
            print(f"feelmysign: no wiring memo at {path}: {error}", file=sys.stderr)
        import contextlib

        with contextlib.suppress(OSError):
            os.unlink(temporary)
