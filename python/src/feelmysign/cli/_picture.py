"""An ASCII picture of a stroke on the grid, for people reading ``feelmysign plan``."""

from __future__ import annotations

from feelmysign.layout import Layout
from feelmysign.schedule import Schedule

CELL_COLUMNS = 8  # characters per grid unit across
CELL_ROWS = 3  # lines per grid unit down
ORDER_MARKS = "123456789abcdefghijklmnopqrstuvwxyz"


def grid_picture(schedule: Schedule, layout: Layout) -> str:
    """Actuators by the order they first switch on (1, 2, ...; '.' = never), the stroke as '*'.

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
    order = _first_on_order(schedule)
    for row in range(layout.rows):
        for column in range(layout.columns):
            rank = order.get((row, column))
            mark = "." if rank is None else ORDER_MARKS[min(rank, len(ORDER_MARKS) - 1)]
            canvas[row * CELL_ROWS][column * CELL_COLUMNS] = mark
    header = "".join(f"x={c}".ljust(CELL_COLUMNS) for c in range(layout.columns)).rstrip()
    lines = ["      " + header]
    for i, chars in enumerate(canvas):
        label = f"y={i // CELL_ROWS}" if i % CELL_ROWS == 0 else ""
        lines.append(f"{label:<6}" + "".join(chars).rstrip())
    return "\n".join(lines)


def _first_on_order(schedule: Schedule) -> dict[tuple[int, int], int]:
    order: dict[tuple[int, int], int] = {}
    for command in schedule.commands:  # sorted by start time
        order.setdefault((command.row, command.column), len(order))
    return order
