"""``feelmysign simplify``: run a recorded drawing through a simplifier and show the strokes."""

from __future__ import annotations

import argparse
import functools
import json
from dataclasses import asdict, fields, replace
from typing import Any

from feelmysign.cli.options.parser import Subcommands
from feelmysign.cli.options.values import (
    MAX_RECORDING_BYTES,
    check_input_file,
    decimal_float_option,
    decimal_int_option,
)
from feelmysign.errors import ParameterError
from feelmysign.simplify import (
    ALGORITHMS,
    PathSegment,
    load_recording,
    simplify_paths,
)
from feelmysign.simplify.params import ParamSpec
from feelmysign.simplify.recording import Recording, RecordingError
from feelmysign.simplify.registry import (
    DEFAULT_ALGORITHM,
    ONLY_FOR,
    OWNERS,
    PAPER_ALGORITHM,
    PARAMETERS,
    Params,
    algorithm_of,
)

# The parameters that change the strokes of a recording get an option: the simplifier's and
# the grid's; the canvas is the recording's, and clearing on a press is the page's.
CLI_PANELS = ("simplifier", "sleeve")
# A number option's placeholder, by its unit.
_METAVARS = {"ms": "MS", "°": "DEG", "grid units": "UNITS", "fps": "FPS", "px": "PX"}


def register(subparsers: Subcommands) -> None:
    parser = subparsers.add_parser(
        "simplify",
        help="cut a recorded drawing into the strokes a sender would send",
        description=(
            "Run a recording (JSON: canvas size and pointer samples per path; see "
            "docs/research.md) through a simplifier, exactly as the drawing client would, "
            "and show the strokes it sends and the ones it drops. An option not given takes "
            "the recording's value (its simplifier's settings, its sleeve's grid), else its "
            "default."
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
    for spec in PARAMETERS.values():
        if spec.panel in CLI_PANELS:
            _option(parser, spec)
    parser.add_argument("--json", action="store_true", help="print the strokes as JSON")
    parser.set_defaults(handler=functools.partial(run, parser=parser))


def option_flag(name: str) -> str:
    """``min_length`` -> ``--min-length``."""
    return "--" + name.replace("_", "-")


def _option(parser: argparse.ArgumentParser, spec: ParamSpec) -> None:
    """The option of one parameter, its help and range from its declaration; None when absent,
    so the recording's value or the default applies."""
    owners = OWNERS[spec.name]
    prefix = f"{owners[0]}: " if len(owners) == 1 else ""
    if spec.only_when is not None:  # read by one of its simplifier's cores only
        prefix = f"{prefix[:-2]} with {_switch_flag(*spec.only_when)}: "
    flag = option_flag(spec.name)
    if spec.kind is bool:
        default = "on" if spec.default else "off"
        parser.add_argument(
            flag,
            action=argparse.BooleanOptionalAction,
            default=None,
            help=_escape(f"{prefix}{spec.help} (default: {default})"),
        )
        return
    allowed = f"{_bound(spec.minimum)} to {_bound(spec.maximum)}"
    parser.add_argument(
        flag,
        type=_value_of(spec),
        metavar="N" if spec.kind is int else _METAVARS.get(spec.unit or "", "X"),
        default=None,
        help=_escape(f"{prefix}{spec.help} ({allowed}; default: {spec.default:g})"),
    )


def _value_of(spec: ParamSpec) -> Any:
    """The option's argparse type: a value outside the parameter's range is a usage error (exit
    2) that names the range, before any recording is read, as any other option's."""
    whole = spec.kind is int
    kind = "a whole number" if whole else "a number"
    if spec.minimum is not None and spec.maximum is not None:
        allowed = f"{kind} from {spec.minimum:g} to {spec.maximum:g}"
    elif spec.minimum is not None:
        allowed = f"{kind} of {spec.minimum:g} or more"
    elif spec.maximum is not None:
        allowed = f"{kind} of at most {spec.maximum:g}"
    else:
        allowed = kind
    if spec.unit:
        allowed += f" ({spec.unit})"

    def parse(text: str) -> float | int:
        # Written in decimal digits, as every number option (a usage error that says so).
        value: float | int = decimal_int_option(text) if whole else decimal_float_option(text)
        try:
            spec.check(value)
        except ParameterError:
            raise argparse.ArgumentTypeError(f"{text} is out of range; give {allowed}") from None
        return value

    parse.__name__ = "whole number" if whole else "number"
    return parse


def _switch_flag(name: str, value: bool) -> str:
    """The flag that sets a boolean parameter to ``value``: ``--least-squares`` or
    ``--no-least-squares``."""
    return option_flag(name if value else f"no_{name}")


def _bound(value: float | None) -> str:
    return "unbounded" if value is None else f"{value:g}"


def _escape(text: str) -> str:
    return text.replace("%", "%%")


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


def checked_params(
    args: argparse.Namespace, recording: Recording, parser: argparse.ArgumentParser | None
) -> Params:
    """``params_from_args``, after refusing (exit 2) an option the strokes would ignore: one of
    the other algorithm's, or one of the core the effective settings do not run."""
    _check_usage(args, chosen_algorithm(args, recording), parser)
    params = params_from_args(args, recording)
    _check_conditions(args, params, parser)
    return params


def run(args: argparse.Namespace, *, parser: argparse.ArgumentParser | None = None) -> int:
    recording = load(args.recording)
    params = checked_params(args, recording, parser)
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
        value = getattr(args, name, None)
        if owner != algorithm and value is not None and parser:
            flag = option_flag(name if value is not False else f"no_{name}")
            parser.error(f"{flag} only applies to --algorithm {owner}")


def _check_conditions(
    args: argparse.Namespace, params: Params, parser: argparse.ArgumentParser | None
) -> None:
    """Usage error (exit 2): an option its simplifier reads only under a setting (``only_when``)
    that is off here, the recording's settings included, so it would change nothing."""
    for name, spec in algorithm_of(params).specs.items():
        value = getattr(args, name, None)
        if spec.only_when is None or value is None or spec.applies(asdict(params)) or not parser:
            continue
        switch, needed = spec.only_when
        flag = option_flag(name if value is not False else f"no_{name}")
        wanted = _switch_flag(switch, needed)
        if getattr(args, switch, None) is not None:
            fix = f"drop it, or give {wanted} instead of {_switch_flag(switch, not needed)}"
        else:
            state = "on" if not needed else "off"
            label = PARAMETERS[switch].label.lower()
            why = (
                f"{label} is {state} by default"
                if getattr(params, switch) == PARAMETERS[switch].default
                else f"the recording's settings have {label} {state}"
            )
            fix = f"drop it, or add {wanted} ({why})"
        parser.error(f"{flag} only applies with {wanted}; {fix}")


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
        f"{len(result) - len(sent)} dropped ({algorithm_of(params).describe(params)}; "
        f"{params.rows} x {params.columns} grid)",
        "",
        f"{'path':>4}  {'start':>15}  {'end':>15}  {'ms':>8}  {'emitted at':>10}  note",
    ]
    for r in result:
        s = r.segment
        note = f"dropped: {s.dropped}" if s.dropped else ""
        if not s.dropped and s.duration_ms != s.drawn_ms:  # drawn briefer than the floor
            note = f"at the sleeve's floor (drawn in {s.drawn_ms:.1f} ms)"
        lines.append(
            f"{r.path:>4}  {_p(s.start):>15}  {_p(s.end):>15}  {s.duration_ms:>8.1f}  "
            f"{s.emitted_at_ms:>10.1f}  {note}"
        )
    return "\n".join(lines)


def _p(point: tuple[float, float]) -> str:
    return f"({point[0]:.3f}, {point[1]:.3f})"
