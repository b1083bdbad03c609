"""``python -m feelmysign.bench [GROUP ...]``: print every benchmark's figures, in a few minutes.

With group names, only those groups (in the usual order); ``--without GROUP`` leaves one out.
``make bench`` runs the felt-drawing group (``simplifier_timing``: simulated times, nothing
timed) while the page and the Java jar are built, then the timed groups one after another.

The study analysis's coverage over hundreds of simulated studies takes about 50 minutes, so it
is a run of its own: ``make bench-study`` (``python -m feelmysign.bench.study_recovery``).
"""

from __future__ import annotations

import argparse
import platform
import time
from collections.abc import Callable, Sequence

from feelmysign.bench import (
    algorithms,
    lasa_points,
    persistence,
    planner_lasa,
    relay,
    restart_off,
    simplifier_timing,
    sleeve,
)

GROUPS: dict[str, Callable[[], list[str]]] = {
    "algorithms": algorithms.report,
    "planner_lasa": planner_lasa.report,
    "simplifier_timing": simplifier_timing.report,
    "lasa_points": lasa_points.report,
    "sleeve": sleeve.report,
    "relay": relay.report,
    "restart_off": restart_off.report,
    "persistence": persistence.report,
}


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m feelmysign.bench", description="Print the benchmarks' figures."
    )
    parser.add_argument(
        "groups", nargs="*", metavar="GROUP", help=f"only these groups, of: {', '.join(GROUPS)}"
    )
    parser.add_argument(
        "--without", action="append", default=[], metavar="GROUP", help="leave GROUP out"
    )
    args = parser.parse_args(argv)
    unknown = [name for name in [*args.groups, *args.without] if name not in GROUPS]
    if unknown:
        parser.error(f"no benchmark group {', '.join(unknown)}; the groups are {', '.join(GROUPS)}")
    chosen = [
        name
        for name in GROUPS
        if (not args.groups or name in args.groups) and name not in args.without
    ]
    print(
        f"feelmysign benchmarks on {platform.python_implementation()} {platform.python_version()}, "
        f"{platform.machine()}: {', '.join(chosen)}"
    )
    print(
        "Each throughput is the best of 5 runs unless its group says otherwise; ratios compare with"
        " the baseline of its group, measured in the same run.\n"
    )
    # Each group's wall time, and the total: the whole of make bench is meant to take minutes.
    total_start = time.perf_counter()
    for name in chosen:
        start = time.perf_counter()
        for line in GROUPS[name]():
            print(line, flush=True)
        print(f"  ({time.perf_counter() - start:.1f} s)\n", flush=True)
    print(f"These groups: {time.perf_counter() - total_start:.1f} s")
    print(
        "The study analysis's coverage over many simulated studies (about 50 minutes):"
        " make bench-study"
    )


if __name__ == "__main__":
    main()
