"""``feelmysign simplify``: run a recorded drawing through a simplifier and show the strokes."""

from __future__ import annotations

import argparse
import functools
import json
from dataclasses import asdict, fields, replace
from typing import Any

from feelmysign.cli.options.values import MAX_RECORDING_BYTES, check_input_file
from feelmysign.simplify import (
    ALGORITHMS,
    AngleParams,
    PathSegment,
    WindowParams,
    load_recording,
    simplify_paths,
)
from feelmysign.simplify.recording import Recording, RecordingError
from feelmysign.simplify.registry import (
    DEFAULT_ALGORITHM,
    ONLY_FOR,
    PAPER_ALGORITHM,
    Params,
    algorithm_of,
)

DEFAULTS = AngleParams()
WINDOW_DEFAULTS = WindowParams()


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "simplify",
        help="cut a recorded drawing into the strokes a sender would send",
        description=(
            "Run a recording (JSON: canvas size and pointer samples per path; see "
            "docs/research.md) through a simplifier, exactly as the drawing client would, "
            "and show the strokes it sends and the ones it drops."
        ),
    )
    parser.add_argument("recording", metavar="RECORDING", help="a recording JSON file")
    parser.add_argument(
        "--algorithm",
        choices=list(ALGORITHMS),
        default=None,
        help="the simplifier: angle (the paper's) or window (error-bounded, cut at features); "
        f"default: the recording's, else {DEFAULT_ALGORITHM}",
    )
    parser.add_argument(
        "--paper",
        action="store_true",
        help="the paper's settings: the angle simplifier at its appendix B.1 values "
        "(the same as --algorithm angle)",
    )
    _option(
        parser,
        "--max-error",
        float,
        "E",
        "window: farthest a drawn point may lie from its stroke, grid units",
        WINDOW_DEFAULTS.max_error,
    )
    _option(
        parser,
        "--max-window",
        int,
        "N",
        "window: longest stroke in samples after its start (bounds the work)",
        WINDOW_DEFAULTS.max_window,
    )
    _option(
        parser,
        "--max-stroke-ms",
        float,
        "MS",
        "window: longest stroke in ms of drawing, so a long line is felt before it ends; "
        "0 = no limit",
        WINDOW_DEFAULTS.max_stroke_ms,
    )
    _option(
        parser, "--check-frames", int, "N", "angle: frames between checks", DEFAULTS.check_frames
    )
    _option(
        parser,
        "--max-angle-deg",
        float,
        "A",
        "angle: largest turn that continues a line, degrees",
        DEFAULTS.max_angle_deg,
    )
    _option(
        parser,
        "--frame-max",
        int,
        "N",
        "angle: longest line in frames, 0 = no limit",
        DEFAULTS.frame_max,
    )
    _option(
        parser, "--fps", float, "F", "angle: frames per second of the drawing loop", DEFAULTS.fps
    )
    parser.add_argument(
        "--no-recover",
        dest="recover",
        action="store_false",
        default=None,
        help="angle: start a new line at the pointer after a failed check, leaving gaps "
        "(default: recover, start it at the last check)",
    )
    _option(
        parser,
        "--min-duration-ms",
        float,
        "D",
        "shortest stroke sent, ms",
        DEFAULTS.min_duration_ms,
    )
    _option(
        parser, "--min-length", float, "L", "shortest stroke sent, grid units", DEFAULTS.min_length
    )
    _option(
        parser,
        "--rows",
        int,
        "R",
        "actuator rows (default: the recording's sleeve, else",
        DEFAULTS.rows,
    )
    _option(
        parser,
        "--columns",
        int,
        "C",
        "actuator columns (default: the recording's sleeve, else",
        DEFAULTS.columns,
    )
    parser.add_argument(
        "--stretch",
        action="store_true",
        default=None,
        help="stretch the canvas onto the grid as the paper did (default: keep the aspect ratio)",
    )
    parser.add_argument("--json", action="store_true", help="print the strokes as JSON")
    parser.set_defaults(handler=functools.partial(run, parser=parser))


def _option(
    parser: argparse.ArgumentParser, flag: str, kind: type, metavar: str, text: str, default: object
) -> None:
    suffix = f" {default})" if text.endswith("else") else f" (default: {default})"
    parser.add_argument(flag, type=kind, metavar=metavar, default=None, help=text + suffix)


def params_from_args(args: argparse.Namespace, recording: Recording) -> Params:
    """The recording's own settings, then the command line's, over the algorithm's defaults."""
    algorithm = ALGORITHMS[chosen_algorithm(args, recording)]
    names = [f.name for f in fields(algorithm.params)]
    recorded = (
        recording.simplifier.get("params", {})
        if recording.simplifier.get("algorithm", DEFAULT_ALGORITHM) == algorithm.name
        and not getattr(args, "paper", False)
        else {}
    )
    base = algorithm.params(**{k: v for k, v in recorded.items() if k in names})
    overrides: dict[str, Any] = {
        "canvas_width_px": recording.width_px,
        "canvas_height_px": recording.height_px,
        "rows": recording.rows or base.rows,
        "columns": recording.columns or base.columns,
    }
    for name in names:
        value = getattr(args, name, None)
        if value is not None:
            overrides[name] = value
    params: Params = replace(base, **overrides)
    return params


def chosen_algorithm(args: argparse.Namespace, recording: Recording) -> str:
    """``--paper`` or ``--algorithm``, else the recording's sender's, else the default."""
    if getattr(args, "paper", False):
        return PAPER_ALGORITHM
    chosen = getattr(args, "algorithm", None)
    if chosen is not None:
        return str(chosen)
    recorded = recording.simplifier.get("algorithm", DEFAULT_ALGORITHM)
    if recorded not in ALGORITHMS:
        raise RecordingError(
            f"{args.recording}: simplifier.algorithm {recorded!r} is unknown; "
            f"choose one with --algorithm {'|'.join(ALGORITHMS)}"
        )
    return str(recorded)


def load(path: str) -> Recording:
    """The recording at ``path``, refused up front if it is not a regular file of sane size."""
    check_input_file(path, what="recording", max_bytes=MAX_RECORDING_BYTES)
    return load_recording(path)


def run(args: argparse.Namespace, *, parser: argparse.ArgumentParser | None = None) -> int:
    recording = load(args.recording)
    _check_usage(args, chosen_algorithm(args, recording), parser)
    params = params_from_args(args, recording)
    result = simplify_paths(params, recording.paths)
    if args.json:
        print(json.dumps(to_json(result, params)))
    else:
        print(describe(result, params, args.recording))
    return 0


def _check_usage(
    args: argparse.Namespace, algorithm: str, parser: argparse.ArgumentParser | None
) -> None:
    """Usage error (exit 2): an option of the other algorithm, which would be ignored."""
    paper = getattr(args, "paper", False)
    if paper and args.algorithm not in (None, PAPER_ALGORITHM) and parser:
        parser.error(
            f"--paper is the {PAPER_ALGORITHM} simplifier: drop --algorithm {args.algorithm}"
        )
    for name, owner in ONLY_FOR.items():
        if owner != algorithm and getattr(args, name, None) is not None and parser:
            flag = "--no-recover" if name == "recover" else "--" + name.replace("_", "-")
            parser.error(f"{flag} only applies to --algorithm {owner}")


def to_json(result: list[PathSegment], params: Params) -> dict[str, Any]:
    strokes, dropped = [], []
    for item in result:
        s = item.segment
        entry = {
            "start": list(s.start),
            "end": list(s.end),
            "start_ms": s.start_ms,
            "end_ms": s.end_ms,
            "duration_ms": s.duration_ms,
            "path": item.path,
            "emitted_at_ms": s.emitted_at_ms,
        }
        if s.dropped is None:
            strokes.append(entry)
        else:
            dropped.append({"reason": s.dropped, **entry})
    return {
        "algorithm": algorithm_of(params).name,
        "params": asdict(params),
        "strokes": strokes,
        "dropped": dropped,
    }


def describe(result: list[PathSegment], params: Params, source: str) -> str:
    sent = [r for r in result if r.segment.dropped is None]
    lines = [
        f"{source}: {len({r.path for r in result})} path(s) -> {len(sent)} stroke(s) sent, "
        f"{len(result) - len(sent)} dropped ({_settings(params)}; "
        f"{params.rows} x {params.columns} grid)",
        "",
        f"{'path':>4}  {'start':>15}  {'end':>15}  {'ms':>8}  {'emitted at':>10}  note",
    ]
    for r in result:
        s = r.segment
        note = f"dropped: {s.dropped}" if s.dropped else ""
        lines.append(
            f"{r.path:>4}  {_p(s.start):>15}  {_p(s.end):>15}  {s.duration_ms:>8.1f}  "
            f"{s.emitted_at_ms:>10.1f}  {note}"
        )
    return "\n".join(lines)


def _settings(params: Params) -> str:
    if isinstance(params, WindowParams):
        cap = f"{params.max_stroke_ms:g} ms" if params.max_stroke_ms else "no limit"
        return (
            f"window: max error {params.max_error:g} grid units, every sample, longest stroke {cap}"
        )
    return (
        f"angle: check every {params.check_frames} frames, max {params.max_angle_deg:g} deg, "
        f"{params.fps:g} fps"
    )


def _p(point: tuple[float, float]) -> str:
    return f"({point[0]:.3f}, {point[1]:.3f})"
