"""``feelmysign study run``: a session in the terminal against a real broker and sleeve."""

from __future__ import annotations

import subprocess
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from study_helpers import REPO

from feelmysign.backends.sim import SimBackend
from feelmysign.broker import Broker
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.study import StudyStore, load_design
from feelmysign.wearer import Wearer

# The browser test (web/e2e/study.e2e.ts) runs the same design on the page.
QUICK_DESIGN = REPO / "deploy" / "studies" / "quick.toml"


@contextmanager
def _running_sleeve(broker: Broker, wearer: Wearer | None = None) -> Iterator[Sleeve]:
    c = broker.credentials
    settings = c.settings("sleeve")
    backend = SimBackend(PAPER_SLEEVE)
    options = SleeveOptions(sleeve_id=c.sleeve_id, wearer=wearer)
    running = Sleeve(settings, PAPER_SLEEVE, backend, options)
    thread = threading.Thread(target=running.run, daemon=True)
    thread.start()
    assert running.connected.wait(10), "the sleeve did not connect"
    yield running
    running.stop()
    thread.join(10)
    backend.close()


@pytest.fixture
def sleeve(broker: Broker) -> Iterator[Sleeve]:
    with _running_sleeve(broker) as running:
        yield running


def _study_run(study: Path, broker: Broker, typed: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "feelmysign",
            "study",
            "run",
            str(study),
            "--credentials",
            str(broker.credentials_path),
        ],
        input=typed,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_a_whole_session_in_the_terminal_plays_every_shape(
    tmp_path: Path, broker: Broker, sleeve: Sleeve
) -> None:
    study = tmp_path / "study.sqlite"
    StudyStore.create(study, QUICK_DESIGN, load_design(QUICK_DESIGN)).close()
    # consent, comfort (1 question + adjusted), then per trial: Enter to send, the answer,
    # the confidence (2 practice trials, a library shape and a recorded drawing, then 4
    # measured ones); then the questionnaire's 2 items.
    answers = ["line", "lightning", "a box", "no idea", "zig zag", "it was a square"]
    typed = "y\ny\nn\n" + "".join(f"\n{a}\n4\n" for a in answers) + "4\n5\n"
    result = _study_run(study, broker, typed)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "floor" not in result.stdout  # a sleeve without a wearer's limits: nothing to say
    assert "coded: square" in result.stdout and "coded: zigzag" in result.stdout
    store = StudyStore(study)
    (participant,) = store.participants()
    trials = store.trials(participant["code"])
    assert [t["answer"] for t in trials] == answers
    assert [t["shape"] for t in trials[:2]] == ["line", "zigzag"]  # practice, then measured
    assert {t["shape"] for t in trials[2:]} == {"square", "zigzag"}
    played = store.query("SELECT COUNT(*) FROM events WHERE type IN ('played', 'adjusted')")
    strokes = sum(t["segments"] for t in trials)
    assert played[0][0] == strokes  # every stroke of every shape played by the sleeve
    assert [row["value"] for row in store.questionnaire(participant["code"])] == [4, 5]
    assert participant["finished_at_ms"] is not None


def test_conditions_below_the_wearers_limits_are_said_once_before_the_first_trial(
    tmp_path: Path, broker: Broker
) -> None:
    """A sleeve started with a wearer's limits advertises them; the runner names, once and
    up front, the conditions whose strokes are below them and what to do."""
    study = tmp_path / "study.sqlite"
    StudyStore.create(study, QUICK_DESIGN, load_design(QUICK_DESIGN)).close()
    # 250 ms: the quick design's squares at 30 cm/s (4 strokes of about 230 ms, 8 of about
    # 115 ms) and its zigzag drawn fast are below it; the one-stroke practice line is not.
    with _running_sleeve(broker, Wearer("P-LIMIT", min_duration_ms=250.0)):
        # Consent, comfort, then Enter to send the practice line; the input ends at its answer.
        result = _study_run(study, broker, "y\ny\nn\n\n")
    assert result.returncode == 0, result.stdout + result.stderr
    out = result.stdout
    assert out.count("P-LIMIT") == 1, out
    warning = next(line for line in out.splitlines() if "P-LIMIT" in line)
    assert "at least 250 ms" in warning
    assert "square at resolution 'coarse', 30 cm/s: 4 of 4 strokes" in warning
    assert "square at resolution 'fine', 30 cm/s: 8 of 8 strokes" in warning
    assert "practice trial 2 (zigzag at resolution 'fine')" in warning
    assert "practice trial 1" not in warning  # the line's one stroke lasts long enough
    assert "may not feel them" in warning and "fewer segments or a slower speed" in warning
    assert out.index("P-LIMIT") < out.index("Trial 1/")  # up front, before the first trial


def test_felt_nothing_is_recorded_without_asking_a_confidence(
    tmp_path: Path, broker: Broker, sleeve: Sleeve
) -> None:
    study = tmp_path / "study.sqlite"
    StudyStore.create(study, QUICK_DESIGN, load_design(QUICK_DESIGN)).close()
    # Consent, comfort; trial 1: Enter to send, an empty answer (felt nothing); trial 2:
    # Enter to send, "line", confidence 3; then the input ends.
    result = _study_run(study, broker, "y\ny\nn\n\n\n\nline\n3\n")
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.count("Confidence 1-5") == 1, result.stdout  # for trial 2 only
    store = StudyStore(study)
    (participant,) = store.participants()
    first, second = store.trials(participant["code"])[:2]
    assert (first["felt_nothing"], first["confidence"], first["answer"]) == (1, None, "")
    assert (second["felt_nothing"], second["confidence"], second["answer"]) == (0, 3, "line")
