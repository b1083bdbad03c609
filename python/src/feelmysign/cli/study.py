"""``feelmysign study``: the recognition study of the paper's section 6, and SQ2.2's thresholds.

    feelmysign study check deploy/studies/paper.toml            # validate a design
    feelmysign study new deploy/studies/paper.toml --out s.sqlite
    feelmysign study simulate s.sqlite --participants 12        # a dry run, no sleeve needed
    feelmysign study simulate s.sqlite --wearer in-range        # ... thresholds inside the range
    feelmysign study run s.sqlite                               # a session in the terminal
    feelmysign up --study s.sqlite                              # ... or on the page /study
    feelmysign study review s.sqlite                            # decide unclear answers
    feelmysign study status s.sqlite
    feelmysign study analyse s.sqlite --out results/            # export + analysis + report
    feelmysign study threshold s.sqlite --participant P-XXXXX --dimension length

See docs/study.md.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import TYPE_CHECKING

from feelmysign.cli._study_threshold import add_threshold_parser
from feelmysign.cli.options.broker import add_broker_options, broker_settings_from_args
from feelmysign.cli.options.parser import Subcommands, add_command
from feelmysign.errors import StudyError
from feelmysign.plural import plural
from feelmysign.study.choices import BOOTSTRAP_SAMPLES

if TYPE_CHECKING:
    from feelmysign.study.design import Design
    from feelmysign.study.store import StudyStore

# Checked (not imported) when the parser is built: without them 'study' is listed as not installed.
REQUIRES = (
    "numpy",
    "scipy",
    "matplotlib",
    "statsmodels",
    "pandas",
    "questplus",
    "similaritymeasures",
    "simplification",
)

# The study's modules (numpy, scipy, statsmodels, matplotlib, questplus) are imported by the
# step that runs, not by 'feelmysign --help'.


def register(subparsers: Subcommands) -> None:
    parser = add_command(
        subparsers,
        "study",
        help="run the paper's recognition study (design, sessions, coding, analysis, thresholds)",
        description=__doc__,
    )
    commands = parser.add_subparsers(dest="study_command", metavar="STEP", required=True)

    check = commands.add_parser("check", help="validate a design file and show its plan")
    check.add_argument("design", type=Path, help="the design file (TOML)")
    check.set_defaults(handler=_check)

    new = commands.add_parser("new", help="create a study file from a design")
    new.add_argument("design", type=Path, help="the design file (TOML)")
    new.add_argument(
        "--out", type=Path, required=True, metavar="FILE", help="the study file to create"
    )
    new.set_defaults(handler=_new)

    status = commands.add_parser("status", help="participants, progress and answers to review")
    status.add_argument("study", type=Path, help="the study file")
    status.set_defaults(handler=_status)

    simulate = commands.add_parser(
        "simulate", help="dry run: add simulated participants and run their whole sessions"
    )
    simulate.add_argument("study", type=Path, help="the study file")
    simulate.add_argument(
        "--participants", type=int, default=12, metavar="N", help="how many (default 12)"
    )
    simulate.add_argument("--seed", type=int, default=0, help="the simulation's seed (default 0)")
    simulate.add_argument(
        "--wearer",
        choices=("template", "in-range"),
        default="template",
        help="how the simulated participants answer: 'template' (default) matches the felt "
        "path with each shape's outline, near ceiling for most shapes of the paper's design; "
        "'in-range' answers by a known curve per shape whose needed resolution lies inside "
        "the tested range (printed here and shown in the report beside the estimates)",
    )
    simulate.set_defaults(handler=_simulate)

    run = commands.add_parser("run", help="run a session in the terminal (the sleeve over MQTT)")
    run.add_argument("study", type=Path, help="the study file")
    run.add_argument(
        "--participant", metavar="CODE", help="resume this participant (default: a new one)"
    )
    add_broker_options(run, role="sender")
    run.set_defaults(handler=_run)

    review = commands.add_parser("review", help="decide the answers the synonyms could not code")
    review.add_argument("study", type=Path, help="the study file")
    review.set_defaults(handler=_review)

    for name, what in (
        ("export", "anonymised CSV + design JSON"),
        ("analyse", "export, then analysis, plots and report"),
    ):
        command = commands.add_parser(name, help=what)
        command.add_argument("study", type=Path, help="the study file")
        command.add_argument(
            "--out",
            type=Path,
            metavar="DIR",
            help="output folder (default: study-results/<study>-<date-time>)",
        )
        if name == "analyse":
            command.add_argument(
                "--bootstrap",
                type=int,
                default=BOOTSTRAP_SAMPLES,
                metavar="B",
                help=f"bootstrap samples per shape (default {BOOTSTRAP_SAMPLES})",
            )
        command.set_defaults(handler=_export if name == "export" else _analyse)

    add_threshold_parser(commands)


def _out_dir(args: argparse.Namespace) -> Path:
    if args.out is not None:
        return Path(args.out)
    return Path("study-results") / f"{args.study.stem}-{time.strftime('%Y%m%d-%H%M%S')}"


def _check(args: argparse.Namespace) -> int:
    from feelmysign.study.design_file import load_design

    design = load_design(args.design)
    print(f"{args.design}: valid. {design.name}")
    speeds = ", ".join(f"{speed:g}" for speed in design.speeds)
    by_speed = f"{len(design.speeds)} speeds ({speeds} cm/s) x " if design.speed_is_factor else ""
    print(
        f"  {plural(len(design.shapes), 'shape')} x {plural(len(design.resolutions), 'resolution')}"
        f" x {by_speed}{plural(design.repetitions, 'repetition')} = "
        f"{plural(design.main_trials, 'measured trial')} per participant, "
        f"after {plural(len(design.practice), 'practice trial')}; order: {design.randomisation}"
    )
    for shape in design.shapes:
        strokes = ", ".join(str(level.strokes) for level in shape.levels)
        print(f"  {shape.name:<10} strokes {strokes}; synonyms: {', '.join(shape.synonyms)}")
    if design.speed_is_factor:
        practice = [f"{p.shape} at {design.practice_speed_cm_s(p):g} cm/s" for p in design.practice]
        if practice:
            print(f"  practice: {', '.join(practice)}")
    print(_session_length(design, args.design))
    from feelmysign.study.slowed import slowed_trials

    for slowed in slowed_trials(design, args.design.resolve().parent):
        print(f"  warning: {slowed.message()}")
    return 0


SECONDS_PER_ANSWER = 12.0  # asking, the answer typed and recorded: an assumption, not measured


def _session_length(design: Design, path: Path) -> str:
    """How long one participant's trials take: the shapes' drawing time (exact) and an
    assumed time per answer."""
    from feelmysign.study.order import participant_order
    from feelmysign.study.stimulus import trial_strokes

    base_dir = path.resolve().parent
    drawn_ms = 0.0
    trials = participant_order(design, 0)
    for trial in trials:
        strokes = trial_strokes(
            design,
            base_dir,
            trial.shape,
            level=trial.level,
            segments=trial.segments,
            drawing="-",
            speed_cm_s=trial.speed_cm_s,
        )
        drawn_ms += sum(stroke.duration_ms for stroke in strokes)
    total_s = drawn_ms / 1000 + SECONDS_PER_ANSWER * len(trials)
    return (
        f"  session: {plural(len(trials), 'trial')}, {drawn_ms / 60000:.1f} min of drawing; "
        f"about {total_s / 60:.0f} min with {SECONDS_PER_ANSWER:g} s per answer (an assumption), "
        "before the comfort check, the questionnaire and any pause"
    )


def _new(args: argparse.Namespace) -> int:
    from feelmysign.study.design_file import load_design
    from feelmysign.study.store import StudyStore

    design = load_design(args.design)
    StudyStore.create(args.out, args.design, design).close()
    print(
        f"Created {args.out} for {design.name!r}. Next: 'feelmysign up --study {args.out}' "
        f"(page /study), or 'feelmysign study run {args.out}'."
    )
    from feelmysign.study.slowed import slowed_trials

    slowed = slowed_trials(design, Path(args.design).resolve().parent)
    if slowed:
        named = ", ".join(f"{s.shape} {s.level} at {s.speed_cm_s:g} cm/s" for s in slowed[:3])
        more = ", ..." if len(slowed) > 3 else ""
        print(
            f"Warning: the sleeve would slow strokes in {plural(len(slowed), 'case')} at the "
            f"design's speeds ({named}{more}): 'feelmysign study check {args.design}' says "
            "which speeds play them unslowed."
        )
    return 0


def _store(args: argparse.Namespace) -> StudyStore:
    """The study named on the command line (``STUDY``), opened."""
    from feelmysign.study.store import StudyStore

    return StudyStore(args.study)


def _status(args: argparse.Namespace) -> int:
    from feelmysign.study.store import DISCARDED

    store = _store(args)
    print(f"{args.study}: {store.design.name}")
    for row in store.participants():
        trials = store.trials(row["code"])
        answered = sum(1 for t in trials if t["answered_at_ms"] is not None)
        # The measured answers awaiting review, as the review, the page and the analysis count.
        unclear = len(store.awaiting_review(row["code"]))
        state = "done" if row["finished_at_ms"] else ("paused" if row["paused"] else "open")
        kind = " (simulated)" if row["simulated"] else ""
        print(
            f"  {row['code']}{kind}: {answered}/{len(trials)} answered, {unclear} unclear, {state}"
        )
        for run in store.threshold_runs(row["code"]):
            done = store.threshold_trials(run["id"])
            what = "simulated threshold run (dry run)" if run["simulated"] else "threshold run"
            unit = "grid units" if run["dimension"] == "length" else "ms"
            if run["stop_reason"] == DISCARDED:
                result = "discarded (kept in the file, left out of the results)"
            elif run["finished_at_ms"] is not None and run["threshold"] is not None:
                result = f"finished, {run['threshold']:.3g} {unit}"
            else:
                result = "unfinished (the same command resumes it)"
            count = plural(len(done), "trial")
            print(f"    {what} {run['id']} ({run['dimension']}): {count}, {result}")
    if not store.participants():
        print("  no participant yet")
    return 0


def _simulate(args: argparse.Namespace) -> int:
    if not 1 <= args.participants <= 500:
        raise StudyError(f"--participants must be 1 to 500; got {args.participants}")
    from feelmysign.study.dry_run import dry_run

    store = _store(args)
    codes = dry_run(
        store,
        args.participants,
        seed=args.seed,
        wearer=args.wearer,
        progress=lambda n, code: print(
            f"  simulated participant {n}/{args.participants}: {code}", flush=True
        ),
    )
    print(
        f"Ran {len(codes)} simulated sessions into {args.study}. "
        f"Next: 'feelmysign study analyse {args.study}'."
    )
    if args.wearer == "in-range":
        from feelmysign.study.simulated import in_range_truths

        print(
            "Known truth of the in-range wearers, to compare with the analysis's needed "
            f"resolutions: the strokes at which the average participant reaches "
            f"{store.design.criterion:.0%} correct (each participant's curve is shifted by an "
            "amount of their own):"
        )
        for truth in in_range_truths(store.design).values():
            print(
                f"  {truth.shape}: {truth.needed_strokes:.2f} strokes (tested "
                f"{truth.lowest_tested}-{truth.highest_tested}; slope "
                f"{truth.slope_per_doubling:g} per doubling, participants' SD "
                f"{truth.spread_doublings:g} doublings)"
            )
    return 0


def _run(args: argparse.Namespace) -> int:
    from feelmysign.study.terminal import run_in_terminal

    store = _store(args)
    settings = broker_settings_from_args(args, "sender")
    return run_in_terminal(store, settings, args.participant)


def _review(args: argparse.Namespace) -> int:
    from feelmysign.study.terminal import review_in_terminal

    return review_in_terminal(_store(args))


def _export(args: argparse.Namespace) -> int:
    from feelmysign.study.export import export_study

    out = _out_dir(args)
    for path in export_study(_store(args), out):
        print(path)
    return 0


def _analyse(args: argparse.Namespace) -> int:
    if not 50 <= args.bootstrap <= 100_000:
        raise StudyError(f"--bootstrap must be 50 to 100000; got {args.bootstrap}")
    from feelmysign.study.analysis import analyse_study

    out = _out_dir(args)
    analysis = analyse_study(_store(args), out, samples=args.bootstrap)
    print(
        f"{plural(analysis.participants, 'participant')}, {plural(analysis.trials, 'trial')}, "
        f"{analysis.unclear} awaiting review."
    )
    if analysis.model is not None:
        from feelmysign.study.analysis.report import shape_test_sentence

        print(shape_test_sentence(analysis.model.test))
        if analysis.model.speed_test is not None:
            from feelmysign.study.analysis.report import speed_test_sentence

            print(speed_test_sentence(analysis.model.speed_test))
    for path in analysis.files:
        print(path)
    return 0
