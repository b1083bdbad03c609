"""Bad input to the real ``feelmysign`` console script: one ``Error:`` line, never a traceback.

Each case runs the installed console script in a subprocess with a timeout (a
fifo or ``/dev/zero`` must be refused, not read until memory runs out) and
checks: a non-zero exit, no traceback, exactly one line starting ``Error:``
on stderr, and that this line names what was wrong.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from feelmysign.cli import BUG_EXIT, main

FEELMYSIGN = str(Path(sys.executable).parent / "feelmysign")
TIMEOUT_S = 60.0  # far above a start-up on a loaded machine; a hang ends the test, not CI
RECORDING = {
    "canvas": {"width_px": 400, "height_px": 300},
    "paths": [[{"t_ms": 0, "x": 10, "y": 10}, {"t_ms": 500, "x": 300, "y": 200}]],
}


def run(
    argv: list[str], tmp_path: Path, *, stdin: str = os.devnull
) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    env["XDG_STATE_HOME"] = str(tmp_path / "state")  # no local broker's credentials file
    with open(stdin, "rb") as source:
        return subprocess.run(
            [FEELMYSIGN, *argv],
            stdin=source,
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
            cwd=tmp_path,
            env=env,
            check=False,
        )


def assert_one_error(done: subprocess.CompletedProcess[str], *says: str) -> str:
    assert done.returncode not in (0, BUG_EXIT), (done.returncode, done.stderr)
    assert "Traceback" not in done.stderr, done.stderr
    errors = [line for line in done.stderr.splitlines() if line.startswith("Error:")]
    assert len(errors) == 1, done.stderr
    assert done.stderr.startswith("Error:"), done.stderr
    for words in says:
        assert words in done.stderr, done.stderr
    return errors[0]


@pytest.fixture
def files(tmp_path: Path) -> dict[str, str]:
    """Bad input files, and one good recording, by name."""
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n", encoding="utf-8")
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    huge = tmp_path / "huge.toml"
    with open(huge, "wb") as handle:
        handle.truncate(2 * 1024 * 1024)  # sparse: 2 MiB of nothing, above the 1 MiB cap
    good = tmp_path / "good.json"
    good.write_text(json.dumps(RECORDING), encoding="utf-8")
    rows_a = tmp_path / "rows-a.json"
    rows_a.write_text(json.dumps({**RECORDING, "sleeve": {"rows": "a"}}), encoding="utf-8")
    a_file = tmp_path / "a-file"
    a_file.write_text("not a folder\n", encoding="utf-8")
    no_canvas = tmp_path / "no-canvas.json"
    no_canvas.write_text(json.dumps({**RECORDING, "canvas": None}), encoding="utf-8")
    deep_json = tmp_path / "deep.json"
    deep_json.write_text("[" * 5000 + "]" * 5000, encoding="utf-8")
    deep_design = tmp_path / "deep-design.toml"
    deep_design.write_text("[study]\nname = " + "{a=" * 5000 + "}" * 5000 + "\n", "utf-8")
    names = {"deep": deep, "fifo": fifo, "huge": huge, "good": good, "rows_a": rows_a}
    names |= {"deep_json": deep_json, "deep_design": deep_design, "no_canvas": no_canvas}
    names |= {"fifo_design": _design_naming(tmp_path / "fifo-study", fifo)}
    paper = Path(__file__).resolve().parents[2] / "deploy" / "layouts" / "paper-sleeve.toml"
    body = base64.urlsafe_b64encode(b"[" * 5000 + b"]" * 5000).decode().rstrip("=")
    extra = {"under_file": f"{a_file}/x", "paper": str(paper), "deep_token": f"fms1.{body}"}
    return {name: str(path) for name, path in names.items()} | extra


def _design_naming(folder: Path, fifo: Path) -> Path:
    """The quick study design, its layout and its recording both the fifo ``fifo``."""
    quick = Path(__file__).resolve().parents[2] / "deploy" / "studies" / "quick.toml"
    (folder / "recordings").mkdir(parents=True)
    os.symlink(fifo, folder / "recordings" / "zigzag.json")
    os.symlink(fifo, folder / "layout.toml")
    design = folder / "design.toml"
    text = quick.read_text(encoding="utf-8")
    design.write_text(text.replace("[stimulus]\n", '[stimulus]\nlayout = "layout.toml"\n'))
    return design


BAD_FILES = [
    (["plan", "0,0,1,0,500", "--layout", "{deep}"], ["nested too deeply"]),
    (["plan", "0,0,1,0,500", "--layout", "/dev/zero"], ["'/dev/zero' is a device"]),
    (["plan", "0,0,1,0,500", "--layout", "{fifo}"], ["fifo", "not a regular file"]),
    (["validate", "0,0,1,0,500", "--layout", "{huge}"], ["2.0 MiB", "at most 1.0 MiB"]),
    (["send", "--shape", "circle", "--credentials", "/dev/zero"], ["credentials file", "device"]),
    (["send", "--shape", "circle", "--credentials", "{fifo}"], ["credentials file", "fifo"]),
    (["simplify", "/dev/zero"], ["recording '/dev/zero' is a device"]),
    (["replay", "{fifo}"], ["recording", "fifo"]),
    (["evaluate", "/dev/zero"], ["recording '/dev/zero' is a device"]),
    (["simplify", "{rows_a}"], ["sleeve.rows must be a whole number from 1 to 64", "'a'"]),
    (["evaluate", "{good}", "--out", "/proc/x"], ["--out '/proc/x' cannot be created"]),
    (["evaluate", "{good}", "--out", "{under_file}"], ["--out", "cannot be created"]),
    (["sleeve", "--record", "{under_file}"], ["--record", "is a file, not a folder"]),
    (["up", "--record", "/nonexistent/felt.jsonl"], ["--record", "does not exist"]),
    (["send", "0,0,1,0,500", "--broker", "mqtt://[::1"], ["mqtt://[::1", "cannot be read"]),
    # Nested deeper than Python's stack: refused as malformed, not a RecursionError.
    (["scan", "--layout", "{paper}", "--emulate-state", "{deep_json}"], ["nested too deeply"]),
    (["off", "--layout", "{paper}", "--emulate-state", "{deep_json}"], ["nested too deeply"]),
    (
        ["sleeve", "--backend", "drv2605", "--layout", "{paper}", "--emulate-state", "{deep_json}"],
        ["emulated I2C bus state", "nested too deeply"],
    ),
    (["sleeve", "--join", "{deep_token}"], ["join token is not usable"]),
    (["study", "check", "{deep_design}"], ["study design", "nested too deeply"]),
    (["simplify", "{deep_json}"], ["not valid JSON", "nested too deeply"]),
    (["send", "--shape", "circle", "--credentials", "{deep_json}"], ["credentials file"]),
    # Study designs, and the layouts and recordings a design names, are read as safely.
    (["study", "check", "{fifo}"], ["study design", "fifo (named pipe)"]),
    (["study", "new", "/dev/zero", "--out", "s.sqlite"], ["study design", "a device"]),
    (["study", "check", "{fifo_design}"], ["stimulus.layout", "recording", "fifo (named pipe)"]),
    # A study file is a SQLite file: a fifo, a device or a folder is said to be one.
    (["study", "status", "{fifo}"], ["study file", "is a fifo (named pipe)", "study new"]),
    (["study", "status", "/dev/null"], ["study file '/dev/null' is a device", "study new"]),
    (["study", "status", "."], ["study file '.' is a folder", "study new"]),
    (
        ["study", "threshold", "{fifo}", "--participant", "P-2345X", "--dimension", "length"],
        ["study file", "is a fifo (named pipe)", "study new"],
    ),
    (
        ["study", "threshold", "/dev/zero", "--participant", "P", "--dimension", "duration"],
        ["study file '/dev/zero' is a device", "study new"],
    ),
    (
        [
            "up",
            "--lan",
            "--port",
            "0",
            "--http-port",
            "0",
            "--tls-cert",
            "{fifo}",
            "--tls-key",
            "x",
        ],
        ["--tls-cert", "fifo (named pipe)"],
    ),
]


@pytest.mark.parametrize(("argv", "says"), BAD_FILES, ids=lambda v: " ".join(v)[:50])
def test_bad_files_are_refused_in_one_line(
    argv: list[str], says: list[str], files: dict[str, str], tmp_path: Path
) -> None:
    done = run([arg.format(**files) for arg in argv], tmp_path)
    assert_one_error(done, *says)


BAD_VALUES = [
    (["send", "--shape", "circle", "--duration-ms", "1e308"], ["--duration-ms", "600000 ms"]),
    (["send", "0,0,1,0,500", "--timeout-s", "1e308"], ["--timeout-s", "at most 3600 s"]),
    (["send", "0,0,1,0,500", "--timeout-s", "nan"], ["--timeout-s", "above 0"]),
    (["replay", "{good}", "--send", "--timeout-s", "1e308"], ["--timeout-s"]),
    (["stop", "--timeout-s", "1e308"], ["--timeout-s", "at most 3600 s"]),
    (["scan", "--emulate-state", "/dev/zero"], ["--emulate-state", "'/dev/zero' is a device"]),
    (["buzz", "0", "0", "--emulate-state", "{fifo}"], ["--emulate-state", "fifo"]),
    # The early all-off reads the layout and state file before the command line is parsed.
    (
        ["sleeve", "--backend", "drv2605", "--layout", "{paper}", "--emulate-state", "{fifo}"],
        ["--emulate-state", "fifo"],
    ),
    (["scan", "--layout", ""], ["--layout", "an empty layout file"]),
    (["evaluate", "{good}", "--out", ""], ["--out", "an empty output folder"]),
    (["send", "0,0,1,0,500", "--legacy", "--legacy-topic", "#"], ["--legacy-topic", "wildcards"]),
    (["sleeve", "--legacy-topic", "#"], ["--legacy-topic", "'#' cannot be used"]),
    (["sleeve", "--join", ""], ["--join", "an empty join token"]),
    (["sleeve", "--legacy-topic", "a/+/b"], ["--legacy-topic"]),
    (["sleeve", "--legacy-topic", "$SYS/x"], ["--legacy-topic"]),
    (["send", "0,0,1,0,500", "--broker", ""], ["--broker", "empty"]),
    (["send", "0,0,1,0,500", "--id", ""], ["--id", "empty sleeve id", "1 to 64"]),
    (["send", "0,0,1,0,500", "--id", "a/b"], ["--id", "'a/b'"]),
    (["up", "--http-port", "99999"], ["--http-port", "1 to 65535"]),
    (["up", "--port", "-5"], ["--port", "1 to 65535"]),
    (["up", "--sleeve-id", "#"], ["--sleeve-id"]),
    (["plan", "0,0,1,0,500", "--rows", "1e9"], ["--rows", "1 to 64"]),
    (["plan", "0,0,1,0,500", "--spacing-cm", "inf"], ["--spacing-cm", "at most 20 cm"]),
    (["sleeve", "--rate-per-s", "1e308"], ["--rate-per-s", "10000"]),
    # Decimal digits only: Python alone would read 1_0 as 10 and \u0663 (Arabic-Indic) as 3.
    (["simplify", "{good}", "--max-error", "1_0"], ["--max-error", "'1_0' is not a decimal"]),
    (["simplify", "{good}", "--max-error", "0x10"], ["--max-error", "digits 0-9"]),
    (["simplify", "{good}", "--max-error", "inf"], ["--max-error", "not a decimal number"]),
    (["plan", "0,0,1,0,500", "--rows", "1_0"], ["--rows", "1 to 64"]),
    (["plan", "0,0,1,0,500", "--spacing-cm", "\u0663"], ["--spacing-cm", "at most 20 cm"]),
    (["up", "--http-port", "80_80"], ["--http-port", "1 to 65535"]),
    (["buzz", "0", "1_0"], ["COLUMN", "'1_0' is not a whole decimal number"]),
]


@pytest.mark.parametrize(("argv", "says"), BAD_VALUES, ids=lambda v: " ".join(v)[:50])
def test_bad_values_are_refused_in_one_line(
    argv: list[str], says: list[str], files: dict[str, str], tmp_path: Path
) -> None:
    done = run([arg.format(**files) for arg in argv], tmp_path)
    assert_one_error(done, *says)
    assert done.returncode == 2  # a usage error: found while reading the command line


@pytest.mark.parametrize("command", [["validate", "-"], ["plan", "-"], ["send", "-"]])
def test_endless_standard_input_is_refused(command: list[str], tmp_path: Path) -> None:
    done = run(command, tmp_path, stdin="/dev/zero")
    assert_one_error(done, "Standard input holds more than 16.0 MiB")


def test_a_layout_from_the_environment_is_checked_too(tmp_path: Path) -> None:
    env = {**os.environ, "FEELMYSIGN_LAYOUT": "/dev/zero"}
    done = subprocess.run(
        [FEELMYSIGN, "plan", "0,0,1,0,500"],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env=env,
        check=False,
    )
    assert_one_error(done, "layout file '/dev/zero' is a device")


def test_a_stroke_of_no_duration_is_told_the_range_a_sleeve_allows(tmp_path: Path) -> None:
    """Judged before connecting, when the sleeve's longest stroke is not known yet: the range
    names it as the sleeve's (not the 600000 ms any sleeve is checked against) and what to
    type."""
    done = run(["send", "--broker", "mqtt://127.0.0.1:1", "0,0,2,0,0"], tmp_path)
    line = assert_one_error(done, "(duration_not_positive)", "Nothing was sent.")
    assert "600000" not in line
    assert "more than 0 ms and at most the sleeve's longest stroke" in line
    assert "10000 ms on the paper's sleeve" in line and "e.g. 0,0,2,0,500" in line
    assert done.returncode == 1


def test_a_negative_stroke_is_judged_not_taken_for_an_option(tmp_path: Path) -> None:
    done = run(["validate", "-1,0,1,0,500", "--json"], tmp_path)
    assert done.returncode == 1, done.stderr
    assert json.loads(done.stdout)["reason"] == "outside_grid"
    planned = run(["plan", "-0.5,0,2,0,1000"], tmp_path)
    assert planned.returncode == 1 and "outside" in planned.stderr


def test_an_unknown_option_is_one_error_line_with_exit_2(tmp_path: Path) -> None:
    done = run(["plan", "0,0,1,0,500", "--no-such-option"], tmp_path)
    # The help that lists the options of the command given, not the program's list of commands.
    assert_one_error(done, "unrecognized arguments: --no-such-option", "'feelmysign plan --help'")
    assert done.returncode == 2


def test_a_recording_without_its_canvas_says_what_it_has_in_json_words(
    files: dict[str, str], tmp_path: Path
) -> None:
    done = run(["replay", files["no_canvas"]], tmp_path)
    assert_one_error(done, "'canvas' must be an object but is null", "Save button")


def test_an_unexpected_exception_is_one_error_line_asking_for_a_report(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(args: argparse.Namespace) -> int:
        raise RuntimeError("something inside\nwent wrong")

    from feelmysign.cli import validate

    monkeypatch.setattr(validate, "run", broken)
    monkeypatch.delenv("FEELMYSIGN_DEBUG", raising=False)
    assert main(["validate", "0,0,1,0,500"]) == BUG_EXIT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("Error: unexpected RuntimeError")
    assert "something inside went wrong" in err and "report" in err
    monkeypatch.setenv("FEELMYSIGN_DEBUG", "1")
    with pytest.raises(RuntimeError):
        main(["validate", "0,0,1,0,500"])
