"""``feelmysign validate`` and the shared layout options, through main() and the real command."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

import pytest

from feelmysign.cli import main
from feelmysign.cli.options.layout import LAYOUT_ENV

FEELMYSIGN = Path(sys.executable).with_name("feelmysign")  # the installed console script
PAPER_FILE = Path(__file__).resolve().parents[2] / "deploy" / "layouts" / "paper-sleeve.toml"


@pytest.fixture(autouse=True)
def no_layout_from_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(LAYOUT_ENV, raising=False)


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["validate", *argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def feed_stdin(monkeypatch: pytest.MonkeyPatch, data: bytes) -> None:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(data)))


def test_accepted_legacy(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "0,0,2,0,1000")
    assert code == 0 and err == ""
    assert out.startswith("Accepted (legacy) by 'paper-sleeve' (3 rows x 4 columns)")
    assert "from (0, 0) to (2, 0) in 1000 ms" in out and "default intensity 0.8" in out


def test_rejected_says_why(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "4,0,2,0,1000")
    assert code == 1
    assert out.startswith("Rejected (outside_grid): start (4, 0) is outside")


def test_json_verdicts(capsys: pytest.CaptureFixture[str]) -> None:
    payload = '{"v":1,"seq":2,"start":[0,0],"end":[3,2],"duration_ms":800,"intensity":0.5}'
    code, out, _ = run(capsys, payload, "--json")
    assert code == 0
    assert json.loads(out) == {
        "ok": True,
        "format": "json",
        "stroke": {"seq": 2, "start": [0, 0], "end": [3, 2], "duration_ms": 800, "intensity": 0.5},
    }
    code, out, _ = run(capsys, "0,0,2,0", "--json")
    verdict = json.loads(out)
    assert code == 1 and verdict["ok"] is False and verdict["reason"] == "wrong_field_count"
    assert "exactly 5" in verdict["message"] and "field" not in verdict


def test_format_can_be_forced(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "0,0,2,0,1000", "--format", "json", "--json")
    assert code == 1 and json.loads(out)["reason"] == "invalid_json"


def test_payload_from_stdin(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    feed_stdin(monkeypatch, b"  1,1,3,2,500\n")
    assert run(capsys, "-")[0] == 0
    feed_stdin(monkeypatch, b"\xff\xfe")
    code, out, _ = run(capsys, "-", "--json")
    assert code == 1 and json.loads(out)["reason"] == "not_text"


def test_layout_options_change_the_grid(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert run(capsys, "0,3,1,1,100")[0] == 1
    assert run(capsys, "0,3,1,1,100", "--rows", "4")[0] == 0
    small = tmp_path / "small.toml"
    small.write_text('name = "small"\nrows = 2\ncolumns = 2\nspacing_cm = 2\n')
    code, out, _ = run(capsys, "1,1,0,0,100", "--layout", str(small))
    assert code == 0 and "'small' (2 rows x 2 columns)" in out
    assert run(capsys, "2,0,0,0,100", "--layout", str(small))[0] == 1


def test_layout_from_the_environment(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    wide = tmp_path / "wide.toml"
    wide.write_text('name = "wide"\nrows = 2\ncolumns = 8\nspacing_cm = 2\n')
    monkeypatch.setenv(LAYOUT_ENV, str(wide))
    assert "'wide'" in run(capsys, "7,1,0,0,100")[1]
    # An explicit grid option wins over the environment.
    assert run(capsys, "7,1,0,0,100", "--columns", "4")[0] == 1


def test_layout_and_grid_options_exclude_each_other(capsys: pytest.CaptureFixture[str]) -> None:
    for argv in (
        ["--layout", str(PAPER_FILE), "--rows", "3"],
        ["--spacing-cm", "2", "--layout", "x"],
    ):
        with pytest.raises(SystemExit) as caught:
            run(capsys, "0,0,1,1,100", *argv)
        assert caught.value.code == 2
        assert "cannot be combined with" in capsys.readouterr().err


def test_bad_layouts_are_errors_not_tracebacks(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    with pytest.raises(SystemExit) as caught:
        run(capsys, "0,0,1,1,100", "--rows", "0")
    err = capsys.readouterr().err
    assert (
        caught.value.code == 2
        and "--rows: 0 is out of range; give a whole number from 1 to 64" in err
    )
    code, _, err = run(capsys, "0,0,1,1,100", "--layout", str(tmp_path / "missing.toml"))
    assert (
        code == 1
        and err.startswith("Error: ")
        and "missing.toml" in err
        and "file not found" in err
    )
    bad = tmp_path / "bad.toml"
    bad.write_text("rows = 3\ncolums = 4\nspacing_cm = 3\n")
    code, _, err = run(capsys, "0,0,1,1,100", "--layout", str(bad))
    assert code == 1 and 'did you mean "columns"' in err and "columns: missing" in err


def test_help_gives_units_and_defaults(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["validate", "--help"])
    out = capsys.readouterr().out
    assert (
        "in cm" in out
        and "(default: 3)" in out
        and LAYOUT_ENV in out
        and "validate -1,0,2,0,1000" in out
    )


# --- the installed command ----------------------------------------------------------------


def command(*argv: str | bytes, stdin: bytes = b"") -> subprocess.CompletedProcess[bytes]:
    env = {"PATH": "/usr/bin:/bin", "LC_ALL": "C.UTF-8"}
    return subprocess.run(
        [FEELMYSIGN, "validate", *argv],
        input=stdin,
        capture_output=True,
        env=env,
        timeout=60,
        check=False,
    )


def test_console_script_accepts_and_rejects() -> None:
    accepted = command("--layout", str(PAPER_FILE), "0,0,3,2,1000")
    assert accepted.returncode == 0 and accepted.stdout.startswith(b"Accepted (legacy)")
    rejected = command("--json", "--", "-1,0,2,0,1000")
    assert rejected.returncode == 1 and json.loads(rejected.stdout)["reason"] == "outside_grid"


def test_console_script_reads_stdin_and_raw_bytes() -> None:
    piped = command("-", "--json", stdin=b'{"v":1,"start":[0,0],"end":[1,1],"duration_ms":50}\n')
    assert piped.returncode == 0 and json.loads(piped.stdout)["format"] == "json"
    raw = command("--json", b"0,0,2,0,10\xe9")
    assert raw.returncode == 1 and json.loads(raw.stdout)["reason"] == "not_text"


@pytest.mark.parametrize("payload", ["", "{", "[[[[", "\x01", "9" * 400, "é" * 600, "-"])
def test_console_script_never_shows_a_traceback(payload: str) -> None:
    result = command("--", payload, stdin=payload.encode())
    assert result.returncode == 1 and b"Traceback" not in result.stderr
    assert result.stdout.startswith(b"Rejected (")


def test_an_intensity_above_the_layouts_cap_says_what_is_driven(
    capped_layout: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    layout = capped_layout
    stroke = '{"v": 1, "start": [0, 0], "end": [3, 0], "duration_ms": 600, "intensity": %s}'
    code, out, _ = run(capsys, "--layout", str(layout), stroke % "0.9")
    assert code == 0
    assert "at intensity 0.9 (driven at most 0.5: the layout's safety.max_intensity" in out
    code, out, _ = run(capsys, "--layout", str(layout), stroke % "0.5")
    assert code == 0 and "driven at most" not in out
