"""Strokes for ``feelmysign plan``: from arguments, or piped in from another command.

    feelmysign plan 0,0,2,0,1000 '{"v":1,"start":[0,0],"end":[3,2],"duration_ms":800}'
    feelmysign simplify drawing.json --json | feelmysign plan -
    feelmysign replay drawing.json --json | feelmysign plan -
    printf '0,0,2,0,1000\\n2,0,3,2,800\\n' | feelmysign plan -

Standard input may hold one stroke message per line (legacy text or JSON v1),
or the ``--json`` document of ``simplify`` or ``replay`` (its ``strokes``, the
ones a sender sends; the dropped ones are left out), on one line or spread over
many. Every stroke passes the sleeve's own validation (feelmysign.protocol).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

from feelmysign.cli.options.values import read_stdin
from feelmysign.errors import StrokeError
from feelmysign.layout import Layout
from feelmysign.protocol import Accepted, parse
from feelmysign.stroke import Stroke


def strokes_from(arguments: list[str], layout: Layout) -> Iterator[Stroke]:
    """Each argument's stroke in order; '-' gives the strokes on standard input there."""
    for position, argument in enumerate(arguments, start=1):
        if argument == "-":
            yield from _stdin_strokes(layout)
        else:
            yield _checked(argument, f"stroke {position} {argument!r}", layout)


def _stdin_strokes(layout: Layout) -> Iterator[Stroke]:
    text = read_stdin(what="strokes").decode("utf-8", errors="replace")
    document = _document(text)
    if document is not None:
        yield from _document_strokes(document, layout)
        return
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line:
            continue
        where = f"line {number} of standard input"
        inner = _document(line)
        if inner is not None:
            yield from _document_strokes(inner, layout, where=where)
        else:
            yield _checked(line, f"{where} {line[:80]!r}", layout)


def _document(text: str) -> dict[str, Any] | None:
    """The ``--json`` document of simplify or replay, if that is what ``text`` is."""
    if not text.lstrip().startswith("{"):
        return None
    try:
        value = json.loads(text)
    except (ValueError, RecursionError):
        return None
    if isinstance(value, dict) and isinstance(value.get("strokes"), list):
        return value
    return None


def _document_strokes(
    document: dict[str, Any], layout: Layout, *, where: str = "standard input"
) -> Iterator[Stroke]:
    params = document.get("params") if isinstance(document.get("params"), dict) else {}
    grid = (params or {}).get("rows"), (params or {}).get("columns")
    for index, entry in enumerate(document["strokes"]):
        if not isinstance(entry, dict):
            raise StrokeError(
                "malformed",
                f"{where}: strokes[{index}] is not an object with start, end and "
                "duration_ms; pipe in the --json output of 'simplify' or 'replay'.",
            )
        message = {
            "v": 1,
            "start": entry.get("start"),
            "end": entry.get("end"),
            "duration_ms": entry.get("duration_ms"),
        }
        hint = ""
        if all(isinstance(n, int) for n in grid) and grid != (layout.rows, layout.columns):
            hint = f" The strokes were made for a {grid[0]} x {grid[1]} grid: add " + (
                f"--rows {grid[0]} --columns {grid[1]}."
            )
        yield _checked(json.dumps(message), f"{where}: strokes[{index}]", layout, hint=hint)


def _checked(text: str, where: str, layout: Layout, *, hint: str = "") -> Stroke:
    result = parse(text, layout)
    if not isinstance(result, Accepted):
        raise StrokeError(result.reason, f"{where}: {result.message}{hint}")
    return result.stroke
