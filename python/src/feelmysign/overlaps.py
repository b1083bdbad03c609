"""Overlapping commands on one actuator, merged into one piecewise-constant intensity.

Tactile Brush drives an actuator from several virtual actuators at once (a
diagonal renders row 1, column 1 from two phantoms), and a burst may run on
under the next stroke. An actuator plays one intensity at a time, so the
commands on it are merged: energies (intensity squared) add, capped at 1, and a
piece shorter than the minimum burst left by an overlap joins its neighbour
with the energy-weighted intensity.
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Iterable

from feelmysign.schedule import Command

Span = tuple[float, float, float]  # start_ms, end_ms, intensity of one actuator's command
Piece = tuple[float, float, float]  # start_ms, end_ms, intensity after merging
Actuator = tuple[int, int]  # row, column

# Spans are gathered per actuator under one int, ``row << ROW_SHIFT | column``: cheaper to
# hash and compare than a (row, column) tuple, and sorted the same (a grid side is at
# most 64, layout.MAX_GRID_SIDE).
ROW_SHIFT = 16
ROW_STEP = 1 << ROW_SHIFT  # the key of the actuator one row further, less this one's
COLUMN_MASK = ROW_STEP - 1


def actuator_key(row: int, column: int) -> int:
    """The key ``commands_from_spans`` gathers one actuator's spans under."""
    return row << ROW_SHIFT | column


def merge_commands(commands: Iterable[Command], *, min_command_ms: float) -> tuple[Command, ...]:
    """One actuator, one intensity at a time.

    Overlapping commands on an actuator add their energies (intensity squared),
    capped at 1. A piece shorter than ``min_command_ms`` left by the overlap
    joins its neighbour with the energy-weighted intensity, so no command is
    shorter than the minimum unless the whole on-period is.
    """
    by_actuator: dict[int, list[Span]] = {}
    for command in commands:
        if command.intensity > 0 and command.duration_ms > 0:
            span = (command.start_ms, command.end_ms, command.intensity)
            key = actuator_key(command.row, command.column)
            by_actuator.setdefault(key, []).append(span)
    return commands_from_spans(by_actuator, min_command_ms)


def commands_from_spans(
    by_actuator: dict[int, list[Span]], min_command_ms: float
) -> tuple[Command, ...]:
    """Each actuator's spans (under its ``actuator_key``) merged, as commands sorted by
    start, then row, then column."""
    commands: list[Command] = []
    append = commands.append
    sqrt = math.sqrt
    # Command(row, column, start, end - start, intensity), without the named tuple's
    # __new__ (a Python function): the same tuple, made in C.
    new = tuple.__new__
    # Actuator by actuator in row, then column order (see the sort below): the keys' order.
    for key in sorted(by_actuator):
        spans = by_actuator[key]
        row, column = key >> ROW_SHIFT, key & COLUMN_MASK
        count = len(spans)
        if count == 1:  # most actuators of a stroke render one burst: _energy_pieces inline
            start, end, intensity = spans[0]
            energy = intensity**2
            if not energy <= 0 and start < end:
                intensity = sqrt(energy)  # min(1.0, ...) without the builtin call, as below
                append(
                    new(
                        Command,
                        (row, column, start, end - start, intensity if intensity < 1.0 else 1.0),
                    )
                )
            continue
        if count == 2:
            actuator_pieces = _two_pieces(spans)
        else:
            actuator_pieces = _paired_pieces(spans) or _chained_pieces(spans)
        if actuator_pieces is None:
            actuator_pieces = _energy_pieces(spans)
        # _join_short's own first test, here: most actuators have no short piece.
        for start, end, _ in actuator_pieces:
            if end - start < min_command_ms:
                actuator_pieces = _join_short(actuator_pieces, min_command_ms)
                break
        for start, end, intensity in actuator_pieces:
            append(new(Command, (row, column, start, end - start, intensity)))
    # Sorted by start, then row, then column: made in row and column order, each actuator's
    # in time order, so a stable sort by start alone orders them so (one actuator's pieces
    # never share a start). Its keys are floats, which the sort compares fastest.
    commands.sort(key=_START)
    return tuple(commands)


_START = operator.itemgetter(2)  # of a Command: a sort key made in C


def _two_pieces(spans: list[Span]) -> list[Piece] | None:
    """``_energy_pieces`` of two spans, the second starting inside or after the first.

    That is how a stroke's bursts reach an actuator (in stroke order, onsets
    rising); the few cases there are, written out, cost a fraction of the
    general sweep. None for any other pair: the sweep handles it. The same
    floats: a sum of one energy is that energy, of two their float sum.
    """
    (s1, t1, i1), (s2, t2, i2) = spans
    e1, e2 = i1**2, i2**2
    if not (s1 < s2 and s1 < t1 and s2 < t2 and e1 > 0 and e2 > 0):
        return None
    first, second = math.sqrt(e1), math.sqrt(e2)
    first = first if first < 1.0 else 1.0
    second = second if second < 1.0 else 1.0
    if t1 < s2:  # apart: the gap between them has no energy
        return [(s1, t1, first), (s2, t2, second)]
    if t1 == s2:  # touching: one piece if their intensities are close
        if math.isclose(first, second):
            return [(s1, t2, first)]
        return [(s1, t1, first), (s2, t2, second)]
    both = math.sqrt(e1 + e2)
    both = both if both < 1.0 else 1.0
    # Overlapping: the first alone, both, then whichever runs on (if either
    # does); each piece touches the one before, so a close intensity extends it.
    overlap_end = t1 if t1 < t2 else t2
    if math.isclose(first, both):
        pieces = [(s1, overlap_end, first)]
    else:
        pieces = [(s1, s2, first), (s2, overlap_end, both)]
    if t1 == t2:
        return pieces
    last, end = (second, t2) if t1 < t2 else (first, t1)
    before = pieces[-1]
    if math.isclose(before[2], last):
        pieces[-1] = (before[0], end, before[2])
    else:
        pieces.append((overlap_end, end, last))
    return pieces


def _paired_pieces(spans: list[Span]) -> list[Piece] | None:
    """``_energy_pieces`` of spans on at most two at a time, by one walk along them.

    That is how most actuators driven by three bursts or more of a stroke get
    them: each burst overlaps the next, and is over before the one after next
    starts. So each interval is one span alone or two (summed in the spans'
    order, as the sweep sums them: ``sum`` of one or two floats is that float,
    or their float sum), and the walk finds each from the spans' order, without
    sorting their bounds. None (for the sweeps) unless each span starts after
    the one before, ends after it starts, and at or before the one after next
    starts, and has an energy above 0.
    """
    energies: list[float] = []
    before_start = before_end = last_end = -math.inf  # of the span before, of the one before it
    for start, end, intensity in spans:
        energy = intensity**2
        if not (before_start < start < end and before_end <= start and energy > 0):
            return None
        energies.append(energy)
        before_start, before_end, last_end = start, last_end, end
    # The intervals, each (start, end, energy): one span on alone, or two.
    intervals: list[Piece] = []
    add = intervals.append
    count = len(spans)
    now, alone_end, _ = spans[0]
    alone_energy = energies[0]
    j = 1  # the next span to start
    while j < count:
        next_start, next_end, _ = spans[j]
        next_energy = energies[j]
        if alone_end <= next_start:  # over before the next starts (or as it starts)
            add((now, alone_end, alone_energy))
            now, alone_end, alone_energy = next_start, next_end, next_energy
            j += 1
            continue
        if now < next_start:
            add((now, next_start, alone_energy))
        both = alone_energy + next_energy
        if next_end < alone_end:  # the next one ends first: alone again after it
            add((next_start, next_end, both))
            now = next_end
            j += 1
        elif alone_end < next_end:  # the next one goes on alone
            add((next_start, alone_end, both))
            now, alone_end, alone_energy = alone_end, next_end, next_energy
            j += 1
        else:  # both end together: the one after starts at or after that
            add((next_start, next_end, both))
            if j + 1 == count:
                break
            now, alone_end, _ = spans[j + 1]
            alone_energy = energies[j + 1]
            j += 2
    else:
        add((now, alone_end, alone_energy))
    # As the sweeps merge: a piece touching the one before with a close intensity extends it.
    pieces: list[Piece] = []
    sqrt, isclose = math.sqrt, math.isclose
    for start, end, energy in intervals:
        intensity = sqrt(energy)
        intensity = intensity if intensity < 1.0 else 1.0
        if pieces and pieces[-1][1] == start and isclose(pieces[-1][2], intensity):
            pieces[-1] = (pieces[-1][0], end, pieces[-1][2])
        else:
            pieces.append((start, end, intensity))
    return pieces


def _chained_pieces(spans: list[Span]) -> list[Piece] | None:
    """``_energy_pieces`` of spans each starting after the one before, by one sweep.

    That is how a stroke's bursts reach an actuator. At each bound the spans
    ending there leave and those starting there join the ones on, kept in the
    spans' order, so the energies summed on each piece are the very list the
    general sweep sums: the same floats, without a search per piece. None for
    spans in any other order, or empty ones: the general sweep handles them.
    """
    before = -math.inf
    for start, end, _ in spans:
        if not before < start < end:
            return None
        before = start
    bounds = sorted({t for start, end, _ in spans for t in (start, end)})
    ends: list[float] = []  # of the spans on, in the spans' order
    energies: list[float] = []  # their energies, in the same order
    pieces: list[Piece] = []
    waiting = iter(spans)
    next_start, next_end, next_intensity = next(waiting)
    start = bounds[0]
    for end in itertools.islice(bounds, 1, None):
        while start in ends:  # the spans ending here leave; the rest keep their order
            i = ends.index(start)
            del ends[i], energies[i]
        if next_start == start:  # starts differ: at most one span joins at a bound
            ends.append(next_end)
            energies.append(next_intensity**2)
            next_start, next_end, next_intensity = next(waiting, (math.inf, math.inf, 0.0))
        _add_piece(pieces, start, end, sum(energies))
        start = end
    return pieces


def _energy_pieces(spans: list[Span]) -> list[Piece]:
    """Piecewise-constant intensity of one actuator: energies summed, capped at 1."""
    bounds = sorted({t for start, end, _ in spans for t in (start, end)})
    energies = [(start, end, intensity**2) for start, end, intensity in spans]
    pieces: list[Piece] = []
    start = bounds[0]
    for end in itertools.islice(bounds, 1, None):
        # The energies on [start, end), summed in the spans' order. A span covers
        # it when it starts at or before its start and ends after it (every span
        # starts and ends on a bound).
        _add_piece(pieces, start, end, sum([e for s, t, e in energies if s <= start < t]))
        start = end
    return pieces


def _add_piece(pieces: list[Piece], start: float, end: float, energy: float) -> None:
    """Add [start, end) at the intensity of ``energy`` (capped at 1) after ``pieces``, by
    extending the last piece when it ends at ``start`` with a close intensity. No energy
    adds nothing: the actuator is off there."""
    if not energy <= 0:
        intensity = math.sqrt(energy)
        intensity = intensity if intensity < 1.0 else 1.0
        if pieces and pieces[-1][1] == start and math.isclose(pieces[-1][2], intensity):
            pieces[-1] = (pieces[-1][0], end, pieces[-1][2])
        else:
            pieces.append((start, end, intensity))


def _join_short(pieces: list[Piece], min_command_ms: float) -> list[Piece]:
    """Join pieces shorter than the minimum to an adjacent piece of the same on-period.

    ``pieces`` is the caller's own list, joined in place (every caller made it for this).
    """
    while True:
        # The shortest short piece with a neighbour (the first of equals), and that
        # neighbour, the piece touching it (the previous one preferred): one pass, no list
        # of candidates, no call per piece.
        shortest, neighbour, shortest_ms = -1, -1, math.inf
        joinable = 0  # short pieces with a neighbour
        last = len(pieces) - 1
        before_end = math.nan  # of the piece before (none before the first: never equal)
        for i, (start, end, _) in enumerate(pieces):
            length_ms = end - start
            if length_ms < min_command_ms:
                if before_end == start:
                    joinable += 1
                    if length_ms < shortest_ms:
                        shortest, neighbour, shortest_ms = i, i - 1, length_ms
                elif i < last and pieces[i + 1][0] == end:
                    joinable += 1
                    if length_ms < shortest_ms:
                        shortest, neighbour, shortest_ms = i, i + 1, length_ms
            before_end = end
        if shortest < 0:
            return pieces
        a, b = (shortest, neighbour) if shortest < neighbour else (neighbour, shortest)
        pieces[a : b + 1] = [_joined(pieces[a], pieces[b])]
        if joinable == 1:
            # Its neighbour was not short, and the two joined last at least as long: no short
            # piece is left with a neighbour (joining changes no other piece's neighbours).
            return pieces


def _joined(first: Piece, second: Piece) -> Piece:
    """Two touching pieces as one, keeping the energy (intensity squared x time)."""
    d1, d2 = first[1] - first[0], second[1] - second[0]
    energy = first[2] ** 2 * d1 + second[2] ** 2 * d2
    return (first[0], second[1], min(1.0, math.sqrt(energy / (d1 + d2))))
