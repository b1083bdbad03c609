"""``python -m feelmysign.bench``: print every benchmark's figures, in a few minutes.

The study analysis's coverage over hundreds of simulated studies takes about 50 minutes, so it
is a run of its own: ``make bench-study`` (``python -m feelmysign.bench.study_recovery``).
"""

from __future__ import annotations

import platform

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
    for report in reports:
        for line in report():
            print(line, flush=True)
        print()
    print(
        "The study analysis's coverage over many simulated studies (about 50 minutes):"
        " make bench-study"
    )


if __name__ == "__main__":
    main()
