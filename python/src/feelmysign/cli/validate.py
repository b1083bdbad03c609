"""``feelmysign validate``: would the sleeve accept this stroke message, and if not, why?

    feelmysign validate 0,0,2,0,1000
    feelmysign validate '{"v":1,"start":[0,0],"end":[3,2],"duration_ms":800}' --json
    echo '4,0,2,0,1000' | feelmysign validate - --layout deploy/layouts/paper-sleeve.toml

Exit 0 if accepted, 1 if rejected (or the layout is wrong), 2 for a usage error.
Uses the sleeve's own validation (feelmysign.protocol.parse), so the answer is
the sleeve's.
"""

from __future__ import annotations

import argparse
import json
import os
from typing import Any

from feelmysign.cli._picture import capped_note
from feelmysign.cli.options.layout import add_layout_options, layout_from_args
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.cli.options.values import read_stdin
from feelmysign.layout import Layout
from feelmysign.protocol import Accepted, Rejected, parse, stroke_to_dict

EPILOG = """\
A payload may start with '-' (a negative coordinate): it is judged, not taken for an option:
  feelmysign validate -1,0,2,0,1000      # Rejected (outside_grid), exit 1
Formats: legacy 'startX,startY,endX,endY,duration' (grid units, ms) or JSON v1;
see docs/protocol.md for every field, range and reason code.
"""


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "validate",
        help="check a stroke message the way the sleeve would",
        description="Say whether the sleeve would accept a stroke message, and if not, why.\n"
        "Exit status 0 if accepted, 1 if rejected.",
        epilog=EPILOG,
    )
    parser.add_argument(
        "payload",
        metavar="PAYLOAD",
        help="the message, e.g. 0,0,2,0,1000 or a JSON v1 object; '-' reads it from stdin",
    )
    parser.add_argument(
        "--format",
        choices=("auto", "legacy", "json"),
        default="auto",
        help="message format (default: auto = JSON if it starts with '{' or '[', else legacy)",
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help="print the verdict as one JSON object for programs (default: a sentence)",
    )
    add_layout_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    layout = layout_from_args(args)
    result = parse(_read_payload(args.payload), layout, format=args.format)
    if args.json:
        print(json.dumps(_verdict(result)))
    else:
        print(_sentence(result, layout))
    return 0 if isinstance(result, Accepted) else 1


def _read_payload(argument: str) -> bytes:
    """The payload's bytes: from stdin for '-', else the argument as the shell passed it."""
    if argument == "-":
        return read_stdin(what="a stroke message")
    # fsencode gives back the original bytes of an argument that was not UTF-8.
    return os.fsencode(argument)


def _verdict(result: Accepted | Rejected) -> dict[str, Any]:
    if isinstance(result, Accepted):
        return {"ok": True, "format": result.format, "stroke": stroke_to_dict(result.stroke)}
    verdict: dict[str, Any] = {"ok": False, "reason": result.reason, "message": result.message}
    if result.field is not None:
        verdict["field"] = result.field
    return verdict


def _sentence(result: Accepted | Rejected, layout: Layout) -> str:
    if isinstance(result, Rejected):
        return f"Rejected ({result.reason}): {result.message}"
    stroke = result.stroke
    intensity = (
        f"intensity {stroke.intensity:g}{capped_note(stroke.intensity, layout)}"
        if stroke.intensity is not None
        else f"the sleeve's default intensity {layout.default_intensity:g}"
    )
    chain = ""
    if stroke.drawing is not None or stroke.seq is not None:
        chain = f", drawing {stroke.drawing or '-'} seq {'-' if stroke.seq is None else stroke.seq}"
    return (
        f"Accepted ({result.format}) by {layout.name!r} ({layout.rows} rows x "
        f"{layout.columns} columns): from ({stroke.start[0]:g}, {stroke.start[1]:g}) to "
        f"({stroke.end[0]:g}, {stroke.end[1]:g}) in {stroke.duration_ms:g} ms at "
        f"{intensity}{chain}."
    )
