"""``python -m feelmysign.bench``: print every benchmark's figures, in a few minutes.

The study analysis's coverage over hundreds of simulated studies takes about 50 minutes, so it
is a run of its own: ``make bench-study`` (``python -m feelmysign.bench.study_recovery``).
"""

from __future__ import annotations

import platform
import time

from feelmysign.bench import (
    algorithms,
    lasa_points,
    persistence,
    planner_lasa,
    restart_off,
    simplifier_timing,
    sleeve,
)


def main() -> None:
    print(
        f"feelmysign benchmarks on {platform.python_implementation()} {platform.python_version()}, "
        f"{platform.machine()}"
    )
    print(
        "Each figure is the best of 5 runs; ratios compare with the baseline of its group,"
        " measured in the same run.\n"
    )
    reports = (
        algorithms.report,
        planner_lasa.report,
        simplifier_timing.report,
        lasa_points.report,
        sleeve.report,
        restart_off.report,
        persistence.report,
    )
    # Each group's wall time, and the total: the whole of make bench is meant to take minutes.
    total_start = time.perf_counter()
    for report in reports:
        start = time.perf_counter()
        for line in report():
            print(line, flush=True)
        print(f"  ({time.perf_counter() - start:.1f} s)\n", flush=True)
    print(f"All groups: {time.perf_counter() - total_start:.1f} s")
    print(
        "The study analysis's coverage over many simulated studies (about 50 minutes):"
        " make bench-study"
    )


if __name__ == "__main__":
    main()
