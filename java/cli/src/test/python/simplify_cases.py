"""Cases for comparing ``feelmysign-java simplify`` with the reference ``feelmysign simplify``.

``python simplify_cases.py OUTDIR`` writes recordings to OUTDIR/recordings/ (LASA
demonstrations, the gesture logs of research/gestures, seeded random drawings and some
broken files) and OUTDIR/cases.json: for each case the arguments of ``simplify`` and what
the reference printed (stdout, stderr) and its exit code, from the reference's own command
line run in this process. The Java test runs the same arguments and compares.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import random
import sys
from pathlib import Path
from typing import Any

from feelmysign.cli import build_parser, main
from feelmysign.research.gestures import load_gesture_log
from feelmysign.research.lasa import load_lasa
from feelmysign.simplify.recording import Recording

REPO = Path(__file__).resolve().parents[5]
SEED = 20261126
JAVA_PROG = "feelmysign-java simplify"


def recording_json(recording: Recording) -> dict[str, Any]:
    document: dict[str, Any] = {
        "canvas": {"width_px": recording.width_px, "height_px": recording.height_px},
        "paths": [
            [{"t_ms": s.t_ms, "x": s.x, "y": s.y, "pressure": s.pressure} for s in path]
            for path in recording.paths
        ],
    }
    return document


def random_flags(rng: random.Random) -> list[str]:
    """A seeded mix of both algorithms' flags, now and then one out of range."""
    flags: list[str] = []
    kind = rng.choice(["window", "window", "angle", "paper", "recorded"])
    if kind == "paper":
        flags.append("--paper")
    elif kind != "recorded":
        flags += ["--algorithm", kind]

    def maybe(flag: str, value: str) -> None:
        if rng.random() < 0.4:
            flags.extend([flag, value])

    if kind == "window":
        maybe("--max-error", str(round(rng.uniform(0.001, 1.5), rng.choice([1, 3, 6]))))
        maybe("--max-window", str(rng.choice([1, 2, 3, 8, 40, 256, 10000])))
        maybe("--max-stroke-ms", str(rng.choice([0, 50, 100.5, 300, 1000, 60000])))
        # The least-squares core (simplify/fit.py), half the time, with its lookahead and floor.
        if rng.random() < 0.5:
            flags.append("--least-squares")
            maybe("--lookahead-ms", str(rng.choice([0, 10, 30, 100.5, 1000])))
            maybe("--floor-ms", str(rng.choice([0, 20, 73.701, 150])))
        elif rng.random() < 0.5:  # the chord core, with its bend rule
            flags.append("--no-least-squares")
            maybe("--max-bend", str(rng.choice([0, 0.05, 0.2, 1])))
            maybe("--bend-floor", str(rng.choice([0, 0.1, 0.5])))
    elif kind in ("angle", "paper"):
        maybe("--check-frames", str(rng.randint(2, 30)))
        maybe("--max-angle-deg", str(rng.choice([1, 5, 12.5, 20, 45, 90, 179])))
        maybe("--frame-max", str(rng.choice([0, 1, 10, 60, 600])))
        maybe("--fps", str(rng.choice([1, 24, 30, 60, 120, 240.5, 1000])))
        if rng.random() < 0.3:
            flags.append("--no-recover")
    maybe("--min-duration-ms", str(rng.choice([0, 6.1, 50, 200])))
    maybe("--min-length", str(rng.choice([0, 0.05, 0.1, 0.5])))
    maybe("--rows", str(rng.choice([1, 2, 3, 4, 8, 64])))
    maybe("--columns", str(rng.choice([1, 2, 4, 6, 64])))
    if rng.random() < 0.25:
        flags.append("--stretch")
    if rng.random() < 0.05:  # out of range: the same sentence from both
        flags += rng.choice(
            [
                ["--min-length", "500"],
                ["--rows", "0"],
                ["--min-duration-ms", "-1"],
                ["--min-length", "nan"],
                ["--columns", "65"],
            ]
        )
    return flags


def random_drawing(rng: random.Random) -> dict[str, Any]:
    """Seeded random paths: walks, turns, pauses, equal times, several paths, on a random canvas."""
    width = rng.choice([320.0, 800.0, 1200.0, 1920.0, rng.uniform(50, 3000)])
    height = rng.choice([240.0, 600.0, 800.0, 1080.0, rng.uniform(50, 3000)])
    paths = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        x, y = rng.uniform(0, width), rng.uniform(0, height)
        t = rng.uniform(0, 5000)
        heading = rng.uniform(0, 6.283)
        samples = []
        for _ in range(rng.randint(1, 400)):
            samples.append({"t_ms": t, "x": x, "y": y, "pressure": round(rng.random(), 3)})
            t += rng.choice([0.0, 1.0, 4.0, 8.333, 16.667, rng.uniform(0, 40), 250.0])
            if rng.random() < 0.1:
                heading += rng.uniform(-3, 3)
            step = rng.choice([0.0, 0.5, 2.0, rng.uniform(0, 30)])
            # Off the canvas now and then: the mapping clamps onto the grid's edge.
            x += step * math.cos(heading)
            y += step * math.sin(heading)
        paths.append(samples)
    document: dict[str, Any] = {"canvas": {"width_px": width, "height_px": height}, "paths": paths}
    if rng.random() < 0.3:
        document["sleeve"] = {"rows": rng.randint(1, 8), "columns": rng.randint(1, 8)}
    if rng.random() < 0.3:
        algorithm = rng.choice(["angle", "window"])
        params: dict[str, Any] = (
            {"check_frames": rng.choice([3, 4.0]), "max_angle_deg": rng.choice([30, 25.5])}
            if algorithm == "angle"
            else {"max_error": rng.choice([0.1, 1]), "max_window": rng.choice([16, 64.0])}
        )
        params["colour"] = "ignored"
        document["simplifier"] = {"algorithm": algorithm, "params": params}
    return document


BROKEN = {
    "not-json.json": "{paths: []}",
    "nan.json": '{"canvas": {"width_px": NaN, "height_px": 1}, "paths": []}',
    "array.json": "[1, 2]",
    "no-canvas.json": '{"paths": []}',
    "zero-width.json": '{"canvas": {"width_px": 0, "height_px": 10}, "paths": []}',
    "empty-path.json": '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [[]]}',
    "bad-sample.json": (
        '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [[{"t_ms": 0, "x": "1", "y": 2}]]}'
    ),
    "back-in-time.json": (
        '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [[{"t_ms": 5, "x": 1, "y": 2},'
        ' {"t_ms": 4.5, "x": 1, "y": 2}]]}'
    ),
    "pressure.json": (
        '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [[{"t_ms": 0, "x": 1, "y": 2,'
        ' "pressure": 2}]]}'
    ),
    "rows-zero.json": (
        '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [], "sleeve": {"rows": 0}}'
    ),
    "unknown-algorithm.json": (
        '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [],'
        ' "simplifier": {"algorithm": "spline"}}'
    ),
    "recorded-out-of-range.json": (
        '{"canvas": {"width_px": 10, "height_px": 10}, "paths": [],'
        ' "simplifier": {"algorithm": "window", "params": {"max_error": 0}}}'
    ),
    "trailing.json": '{"canvas": {"width_px": 10, "height_px": 10}, "paths": []} x',
}

USAGE_ERRORS = [
    ["--fps", "30"],  # an angle flag on the default (window) algorithm
    ["--algorithm", "window", "--check-frames", "3"],
    ["--paper", "--algorithm", "window"],
    ["--algorithm", "spline"],
    ["--rows", "2.5"],
    ["--max-error", "abc"],
    ["--bogus"],
    ["--no", "--json"],
    ["--recover"],
    ["--algorithm", "window", "--no-recover"],
    ["--stretch=yes"],
    ["--max-e=abc"],
    ["--max-window", "2.5"],
    # An option of the window core not run (the least-squares core is the default).
    ["--max-bend", "0.2"],
    ["--least-squares", "--bend-floor", "0.2"],
    ["--algorithm", "window", "--no-least-squares", "--lookahead-ms", "80"],
]


def run(arguments: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(["simplify", *arguments])
        except SystemExit as stop:  # argparse's usage errors
            code = stop.code if isinstance(stop.code, int) else 1
    return code, out.getvalue(), err.getvalue()


def help_as(prog: str) -> str:
    """The reference's ``simplify --help`` under the Java port's name: argparse wraps the usage
    after the program's name, so the two are compared under the same one."""
    parser = build_parser("simplify")
    subcommands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    simplify = subcommands.choices["simplify"]
    simplify.prog = prog
    return simplify.format_help()


def main_(outdir: Path) -> None:
    rng = random.Random(SEED)
    folder = outdir / "recordings"
    folder.mkdir(parents=True, exist_ok=True)
    recordings: list[tuple[str, Path]] = []

    def save(name: str, document: dict[str, Any] | str) -> Path:
        path = folder / name
        text = document if isinstance(document, str) else json.dumps(document)
        path.write_text(text, encoding="utf-8")
        return path

    for demo in load_lasa():
        if demo.demo not in (1, 4, 7):  # three of each shape's seven: the run stays short
            continue
        name = f"lasa-{demo.shape}-{demo.demo}.json"
        recordings.append((name, save(name, recording_json(demo.recording))))
    gestures = sorted((REPO / "research" / "gestures").rglob("*.xml"))
    for path in gestures[::6]:
        gesture = load_gesture_log(path)
        name = "gesture-" + "-".join(path.relative_to(REPO / "research" / "gestures").parts)
        name = name.removesuffix(".xml") + ".json"
        recordings.append((name, save(name, recording_json(gesture.recording))))
    for index in range(120):
        name = f"random-{index:03d}.json"
        recordings.append((name, save(name, random_drawing(rng))))

    cases: list[dict[str, Any]] = []

    def case(name: str, arguments: list[str]) -> None:
        code, stdout, stderr = run(arguments)
        cases.append(
            {"name": name, "args": arguments, "code": code, "stdout": stdout, "stderr": stderr}
        )

    for index, (name, path) in enumerate(recordings):
        # Each recording once: the defaults, the paper's settings or seeded flags, in turn;
        # the random drawings always with seeded flags.
        turn = 2 if name.startswith("random") else index % 3
        flags = [[], ["--paper"], random_flags(rng)][turn]
        case(name, [str(path), *flags, "--json"])
    # The least-squares core on drawn shapes too (LASA, people's gestures), at its defaults.
    for name, path in recordings[::12]:
        case(name + " least squares", [str(path), "--least-squares", "--json"])
    # A recording made with the chord core: its bend rule is taken, the lookahead refused
    # unless --least-squares is given too (the check is on the settings in effect).
    chord = json.loads(recordings[0][1].read_text())
    chord["simplifier"] = {"algorithm": "window", "params": {"least_squares": False}}
    chord_path = str(save("chord-core.json", chord))
    bend = ["--max-bend", "0.1", "--bend-floor", "0.05"]
    case("chord core, bend rule", [chord_path, *bend, "--json"])
    case("chord core, lookahead", [chord_path, "--lookahead-ms", "80", "--json"])
    case("chord core, least squares", [chord_path, "--least-squares", "--lookahead-ms", "80"])
    first = str(recordings[0][1])
    case("text output", [first])
    case("text output, angle", [first, "--paper", "--stretch"])
    for name, text in BROKEN.items():
        case(name, [str(save(name, text)), "--json"])
    # Not UTF-8 (a Latin-1 "é" after a valid start, then a lone continuation byte): the
    # sentence names the first bad byte's offset.
    binary = folder / "latin1.json"
    binary.write_bytes(b'{"canvas": {"width_px": 100, "height_px": 100}, "note": "caf\xe9"}')
    case("not UTF-8", [str(binary), "--json"])
    continuation = folder / "continuation.json"
    continuation.write_bytes(b"\x80{}")
    case("not UTF-8 at the start", [str(continuation), "--json"])
    case("missing file", [str(folder / "absent.json"), "--json"])
    case("a folder", [str(folder), "--json"])
    for arguments in USAGE_ERRORS:
        case(" ".join(arguments), [first, *arguments, "--json"])
    java_help = help_as(JAVA_PROG)
    for arguments in (["--help"], ["-h"], ["--he"], [first, "--json", "--help"]):
        cases.append(
            {
                "name": " ".join(arguments),
                "args": arguments,
                "code": 0,
                "stdout": java_help,
                "stderr": "",
            }
        )
    (outdir / "cases.json").write_text(json.dumps(cases), encoding="utf-8")
    print(f"{len(cases)} cases, {len(recordings)} recordings in {outdir}")


if __name__ == "__main__":
    main_(Path(sys.argv[1]))
