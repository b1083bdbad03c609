"""An ASCII picture of a stroke on the grid, for people reading ``feelmysign plan``."""

from __future__ import annotations

from feelmysign.layout import Layout
from feelmysign.schedule import Schedule

CELL_COLUMNS = 8  # characters per grid unit across
CELL_ROWS = 3  # lines per grid unit down
# Command numbers 1..35 as one character each; '+' for any later first command.
NUMBER_MARKS = "123456789abcdefghijklmnopqrstuvwxyz"
LATER_MARK = "+"
LEGEND = (
    "Each actuator shows the # of its first command in the table (1-9, then a = 10 ... "
    "z = 35, + later; . = never on).\n"
    "* is the stroke, S and E its start and end where no actuator is; x = column, "
    "y = row, in grid units."
)


def grid_picture(schedule: Schedule, layout: Layout) -> str:
    """Actuators by the table number of their first command ('.' = never), the stroke as '*'.

    'S' and 'E' mark the stroke's start and end when they are not on an actuator.
    """
    width = (layout.columns - 1) * CELL_COLUMNS + 1
    height = (layout.rows - 1) * CELL_ROWS + 1
    canvas = [[" "] * width for _ in range(height)]
    stroke = schedule.stroke
    steps = max(width, height) * 4
    for k in range(steps + 1):
        f = k / steps
        x = stroke.start[0] + (stroke.end[0] - stroke.start[0]) * f
        y = stroke.start[1] + (stroke.end[1] - stroke.start[1]) * f
        canvas[round(y * CELL_ROWS)][round(x * CELL_COLUMNS)] = "*"
    for point, mark in ((stroke.start, "S"), (stroke.end, "E")):
        canvas[round(point[1] * CELL_ROWS)][round(point[0] * CELL_COLUMNS)] = mark
    first = _first_command_numbers(schedule)
    for row in range(layout.rows):
        for column in range(layout.columns):
            number = first.get((row, column))
            canvas[row * CELL_ROWS][column * CELL_COLUMNS] = _mark(number)
    header = "".join(f"x={c}".ljust(CELL_COLUMNS) for c in range(layout.columns)).rstrip()
    lines = ["      " + header]
    for i, chars in enumerate(canvas):
        label = f"y={i // CELL_ROWS}" if i % CELL_ROWS == 0 else ""
        lines.append(f"{label:<6}" + "".join(chars).rstrip())
    return "\n".join(lines)


def _mark(number: int | None) -> str:
    if number is None:
        return "."
    return NUMBER_MARKS[number - 1] if number <= len(NUMBER_MARKS) else LATER_MARK


def _first_command_numbers(schedule: Schedule) -> dict[tuple[int, int], int]:
    """Each actuator's first command, numbered as the table numbers them (from 1)."""
    first: dict[tuple[int, int], int] = {}
    for number, command in enumerate(schedule.commands, start=1):  # sorted by start time
        first.setdefault((command.row, command.column), number)
    return first


def capped_note(intensity: float, layout: Layout) -> str:
    """What the sleeve drives a stroke asked at ``intensity`` with, when its cap lowers it
    (the player drives no motor above the layout's ``safety.max_intensity``); else ""."""
    if intensity <= layout.max_intensity:
        return ""
    return (
        f" (driven at most {layout.max_intensity:g}: the layout's safety.max_intensity caps "
        "every motor)"
    )
