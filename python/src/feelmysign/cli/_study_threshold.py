"""``feelmysign study threshold``: SQ2.2's QUEST+ run for one participant, in the terminal.

With ``--simulated-observer T`` a simulated wearer with threshold T answers and
the sleeve is the offline planner: a dry run of the procedure. Its threshold is T's,
not the participant's, so ``--save`` refuses it for a real (not simulated)
participant: the sleeve would take it as that wearer's measured floor.
"""

from __future__ import annotations

import argparse
import json
import random
import sqlite3
from pathlib import Path
from typing import Any

from feelmysign.cli.options.broker import add_broker_options, broker_settings_from_args
from feelmysign.errors import StudyError
from feelmysign.study.choices import DIMENSIONS, DIRECTIONS

_KEYS = {d[0]: d for d in DIRECTIONS}  # u, d, l, r


def add_threshold_parser(commands: Any) -> None:
    parser = commands.add_parser(
        "threshold",
        help="SQ2.2: shortest stroke length or duration whose direction is felt (QUEST+)",
        description=__doc__,
    )
    parser.add_argument("study", type=Path, help="the study file")
    parser.add_argument("--participant", required=True, metavar="CODE", help="who takes part")
    parser.add_argument("--dimension", choices=DIMENSIONS, required=True, help="what varies")
    parser.add_argument(
        "--simulated-observer",
        type=float,
        metavar="T",
        help="dry run: a simulated wearer whose threshold is T (grid units or ms)",
    )
    parser.add_argument("--seed", type=int, default=0, help="the simulated wearer's seed")
    parser.add_argument(
        "--save",
        type=Path,
        metavar="FILE",
        help="also write the threshold into this wearer file (JSON; the other dimension's "
        "value, if the file has one for the same participant, is kept), for "
        "'feelmysign sleeve --wearer FILE'",
    )
    add_broker_options(parser, role="sender")
    parser.set_defaults(handler=run)


def _ask(direction: str, value: float) -> str:
    while True:
        said = input("  Which way did it move? [u]p, [d]own, [l]eft, [r]ight: ").strip().lower()
        if said[:1] in _KEYS:
            return _KEYS[said[:1]]
        print("  Type u, d, l or r.")


def _refuse_a_dry_run_for_a_real_wearer(participant: sqlite3.Row, path: Path) -> None:
    """A simulated observer's threshold is no measurement of a real participant: written into
    their wearer file, the sleeve would keep to it as their floor."""
    if not participant["simulated"]:
        raise StudyError(
            f"--save with --simulated-observer would write a simulated threshold into {path} "
            f"as {participant['code']}'s measured limit, and the sleeve would keep to it; "
            "leave out --save for a dry run (it is stored in the study file as one), or use a "
            "simulated participant ('feelmysign study simulate' adds them)"
        )


def run(args: argparse.Namespace) -> int:
    from feelmysign.apparent_motion import shortest_planned_ms
    from feelmysign.study.simulated_sleeve import offline_player
    from feelmysign.study.sleeve_link import SleeveLink
    from feelmysign.study.stimulus import stimulus_layout
    from feelmysign.study.store import StudyStore
    from feelmysign.study.threshold import SimulatedObserver, dimension_settings, value_words
    from feelmysign.study.threshold_run import run_threshold

    if args.save is not None:
        from feelmysign.wearer import wearer_to_update

        wearer_to_update(args.save, args.participant)  # a bad file is said before the run
    store = StudyStore(args.study)
    # Said first: an unknown code is the mistake to fix, not the broker the run would need.
    participant = store.participant(args.participant)
    if args.save is not None and args.simulated_observer is not None:
        _refuse_a_dry_run_for_a_real_wearer(participant, args.save)
    layout = stimulus_layout(store.design.stimulus, store.base_dir)

    def progress(n: int, value: float, sent: str, said: str) -> None:
        mark = "right" if sent == said else "wrong"
        shown = value_words(args.dimension, value)
        print(f"  trial {n}: {shown} {sent}, answered {said} ({mark})", flush=True)

    if args.simulated_observer is not None:
        if not args.simulated_observer > 0:
            raise StudyError(f"--simulated-observer must be above 0; got {args.simulated_observer}")
        observer = SimulatedObserver(args.simulated_observer)
        rng = random.Random(args.seed)
        estimate = run_threshold(
            store,
            args.participant,
            args.dimension,
            layout,
            offline_player(layout),
            lambda direction, value: observer.respond(direction, value, rng),
            progress,
            simulated=True,
        )
    else:
        with SleeveLink(broker_settings_from_args(args, "sender")) as link:
            estimate = run_threshold(
                store, args.participant, args.dimension, layout, link.play, _ask, progress
            )
    kind = (
        f"Simulated {args.dimension} threshold (a dry run, stored as one)"
        if args.simulated_observer
        else f"Threshold ({args.dimension})"
    )
    grid = dimension_settings(store.design.threshold, args.dimension)
    print(f"{kind}: {estimate.words(args.dimension, grid)}.")
    floor_ms = shortest_planned_ms(layout.shortest_burst_ms)
    if args.dimension == "duration" and estimate.threshold < floor_ms:
        print(
            f"The sleeve played every stroke briefer than its floor ({floor_ms:g} ms) at the "
            "floor: how this wearer does below it is not known, and senders keep to the floor "
            "anyway."
        )
    if args.save is not None:
        from feelmysign.wearer import save_wearer

        if estimate.censored == "above":
            raise StudyError(
                f"nothing saved to {args.save}: this run did not measure a {args.dimension} "
                "threshold (above), and the sleeve would keep to the top of the tested range "
                "as the wearer's limit; the run stays in the study file"
            )
        wearer = save_wearer(args.save, args.participant, args.dimension, estimate.threshold)
        print(
            f"Saved to {args.save}: {json.dumps(wearer.to_json())}; run the sleeve with "
            f"'feelmysign sleeve --wearer {args.save}' (or 'feelmysign up --wearer {args.save}')."
        )
    return 0
