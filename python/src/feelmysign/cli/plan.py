"""``feelmysign plan``: what the sleeve would do with a stroke: a table and a picture, or JSON."""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

from feelmysign.cli._picture import LEGEND, capped_note, grid_picture
from feelmysign.cli.options.layout import add_layout_options, layout_from_args
from feelmysign.cli.options.parser import Subcommands
from feelmysign.cli.options.strokes import strokes_from
from feelmysign.cli.options.values import number
from feelmysign.layout import MAX_MIN_BURST_MS, MIN_BURST_MS, Layout
from feelmysign.planner import MERGE_DISTANCE, plan
from feelmysign.schedule import Schedule, schedule_to_json
from feelmysign.stroke import Stroke

MAX_MERGE_DISTANCE = 0.5  # beyond half a cell, merging would move crossings off their lines


def register(subparsers: Subcommands) -> None:
    parser = subparsers.add_parser(
        "plan",
        help="show the actuator commands the sleeve would play for strokes",
        description=(
            "Plan strokes with Tactile Brush and show the actuator commands. STROKE is the "
            "legacy text startX,startY,endX,endY,duration (grid units, ms), e.g. 0,0,2,0,1000, "
            "or a JSON v1 message. '-' reads strokes from standard input: one message per "
            "line, or the --json output of 'simplify' or 'replay' "
            "(feelmysign replay drawing.json --json | feelmysign plan -)."
        ),
    )
    parser.add_argument(
        "strokes", nargs="+", metavar="STROKE", help="a stroke, or - for standard input"
    )
    add_layout_options(parser)
    parser.add_argument(
        "--intensity",
        type=number(0, 1),
        metavar="A",
        help="stroke intensity in [0, 1] (default: the layout's default intensity)",
    )
    parser.add_argument(
        "--min-command-ms",
        type=number(0, MAX_MIN_BURST_MS, unit="ms"),
        metavar="D",
        help="shortest burst an actuator may play, in ms (default: the layout's min_burst_ms, "
        "else by actuator_type: "
        + ", ".join(f"{kind} {ms:g}" for kind, ms in MIN_BURST_MS.items())
        + ")",
    )
    parser.add_argument(
        "--merge-distance",
        type=number(0, MAX_MERGE_DISTANCE, unit="grid units"),
        default=MERGE_DISTANCE,
        metavar="G",
        help=f"merge virtual actuators closer than this, grid units (default: {MERGE_DISTANCE:g})",
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="reject a stroke too fast to render even as two end phantoms instead of "
        "slowing it (default: slow it)",
    )
    parser.add_argument("--json", action="store_true", help="one JSON object per stroke per line")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    layout = layout_from_args(args)
    for given in strokes_from(args.strokes, layout):
        stroke = Stroke(given.start, given.end, given.duration_ms, given.intensity)
        if args.intensity is not None:
            stroke = replace(stroke, intensity=args.intensity)
        schedule = plan(
            stroke,
            layout,
            min_command_ms=args.min_command_ms,
            merge_distance=args.merge_distance,
            strict=args.strict,
        )
        if args.json:
            print(json.dumps(schedule_to_json(schedule)), flush=True)
        else:
            print(describe(schedule, layout), flush=True)
    return 0


def describe(schedule: Schedule, layout: Layout) -> str:
    """A readable table of the commands and a picture of the grid."""
    stroke = schedule.stroke
    length_cm = stroke.length * layout.spacing_cm
    speed = length_cm / schedule.duration_ms * 1000.0
    intensity = layout.default_intensity if stroke.intensity is None else stroke.intensity
    lines = [
        f"Stroke ({_p(stroke.start)}) -> ({_p(stroke.end)}): {length_cm:.2f} cm in "
        f"{schedule.duration_ms:.3f} ms ({speed:.1f} cm/s), intensity {intensity:g}"
        f"{capped_note(intensity, layout)}, on a {layout.rows} x {layout.columns} grid, "
        f"{layout.spacing_cm:g} cm apart",
    ]
    if schedule.adjusted is not None:
        lines.append(
            f"Adjusted: too fast to render at {schedule.adjusted.requested_duration_ms:g} ms, "
            f"even as two end phantoms; slowed to {schedule.adjusted.duration_ms:.3f} ms "
            "(--strict would reject it)"
        )
    if schedule.thinned:
        kept = len(schedule.bursts)
        lines.append(
            f"Thinned: {schedule.thinned} of {kept + schedule.thinned} virtual actuators left "
            f"out (too close in time to be felt apart) so that the stroke plays in "
            f"{schedule.duration_ms:.3f} ms"
        )
    lines.append("")
    lines.append(
        f"{'#':>3} {'row y':>5} {'column x':>8} {'start ms':>10} {'duration ms':>12} "
        f"{'end ms':>10} {'intensity':>9}"
    )
    for i, c in enumerate(schedule.commands, start=1):
        # As the motor is driven: the player caps every output at the layout's max_intensity.
        driven = min(c.intensity, layout.max_intensity)
        lines.append(
            f"{i:>3} {c.row:>5} {c.column:>8} {c.start_ms:>10.3f} {c.duration_ms:>12.3f} "
            f"{c.end_ms:>10.3f} {driven:>9.3f}"
        )
    lines.append("")
    lines.append(grid_picture(schedule, layout))
    lines.append(LEGEND)
    return "\n".join(lines) + "\n"


def _p(point: tuple[float, float]) -> str:
    return f"{point[0]:g}, {point[1]:g}"
