"""``feelmysign send`` sizes its shapes for the sleeve it sends to and waits for its answer:
a real Mosquitto, a real ``feelmysign sleeve`` of 2 rows x 6 columns on the emulated bus, and
``feelmysign send`` as its own process (its exit code as a shell sees it)."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from builder_sleeve import start_sleeve, two_by_six_layout
from sleeve_watch import SleeveWatch, online

from feelmysign.bench.restart_off import feelmysign_command
from feelmysign.broker import Broker

WAIT_S = 120.0  # generous: a loaded 2-core machine

pytestmark = pytest.mark.broker


@pytest.fixture
def watched_sleeve(broker: Broker, tmp_path: Path) -> Iterator[SleeveWatch]:
    layout = two_by_six_layout(tmp_path / "maker.toml")
    with SleeveWatch(broker.credentials, "status", "events") as watcher:
        sleeve = start_sleeve(broker.credentials_path, layout, tmp_path / "bus.json")
        try:
            watcher.next(online, "the 2 x 6 sleeve online")
            yield watcher
        finally:
            sleeve.terminate()
            _, errors = sleeve.communicate(timeout=WAIT_S)
            assert "Traceback" not in errors, errors


def send(broker: Broker, *argv: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FEELMYSIGN_")}
    return subprocess.run(
        [*feelmysign_command(), "send", "--credentials", str(broker.credentials_path), *argv],
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        env=env,
        check=False,
    )


def drawing_of(result: subprocess.CompletedProcess[str]) -> str:
    return result.stdout.split('"drawing":"', 1)[1].split('"', 1)[0]


def test_a_shape_without_a_layout_fits_the_sleeve_s_grid_and_every_stroke_plays(
    broker: Broker, watched_sleeve: SleeveWatch
) -> None:
    result = send(broker, "--shape", "heart", "--segments", "8")
    assert result.returncode == 0, result.stdout + result.stderr
    # (strokes that queued on a loaded machine are said in brackets: played faster)
    assert "The sleeve played 8 of 8 strokes" in result.stdout, result.stdout
    drawing = drawing_of(result)
    events = [e for e in watched_sleeve.received("events") if e.get("drawing") == drawing]
    assert sorted(e["seq"] for e in events if e["type"] in ("played", "adjusted")) == list(
        range(8)
    ), events
    assert not [e for e in events if e["type"] == "rejected"], events


def test_strokes_the_sleeve_refuses_make_send_fail_and_name_the_reason(
    broker: Broker, watched_sleeve: SleeveWatch
) -> None:
    # Sized for the paper's 3 x 4 grid by hand: the heart's lower half lies below row 1.
    result = send(broker, "--shape", "heart", "--segments", "8", "--rows", "3", "--columns", "4")
    assert result.returncode == 1, result.stdout + result.stderr
    drawing = drawing_of(result)
    refused = [
        e
        for e in watched_sleeve.received("events")
        if e.get("drawing") == drawing and e["type"] == "rejected"
    ]
    assert refused and {e["reason"] for e in refused} == {"outside_grid"}, refused
    assert f"refused {len(refused)} (outside_grid" in result.stderr, result.stderr
    assert result.stderr.count("Error:") == 1 and "Traceback" not in result.stderr
    assert result.stdout.count("refused (outside_grid)") == len(refused), result.stdout


def test_a_second_send_right_after_a_long_one_is_not_refused_as_late(
    broker: Broker, watched_sleeve: SleeveWatch
) -> None:
    line = send(broker, "--shape", "line", "--duration-ms", "2500")
    assert line.returncode == 0, line.stdout + line.stderr
    square = send(broker, "--shape", "square", "--duration-ms", "1200")
    assert square.returncode == 0, square.stdout + square.stderr
    assert "The sleeve played 4 of 4 strokes" in square.stdout, square.stdout
    late = [e for e in watched_sleeve.received("events") if e.get("reason") == "late"]
    assert not late, late


def test_no_sleeve_to_answer_is_an_error_after_a_bounded_wait(broker: Broker) -> None:
    result = send(broker, "--shape", "square", "--duration-ms", "400", "--timeout-s", "1")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "No status from sleeve 'sleeve1'" in result.stderr, result.stderr
    assert "The sleeve played 0 of 4 strokes; no answer for stroke(s) 1, 2, 3, 4" in result.stderr
    assert "is sleeve 'sleeve1' running" in result.stderr and "Traceback" not in result.stderr
