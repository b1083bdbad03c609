"""``feelmysign study run``: a session in the terminal against a real broker and sleeve."""

from __future__ import annotations

import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from study_helpers import REPO

from feelmysign.backends.sim import SimBackend
from feelmysign.broker import Broker
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.study import StudyStore, load_design

# The browser test (web/e2e/study.e2e.ts) runs the same design on the page.
QUICK_DESIGN = REPO / "deploy" / "studies" / "quick.toml"


@pytest.fixture
def sleeve(broker: Broker) -> Iterator[Sleeve]:
    c = broker.credentials
    settings = c.settings("sleeve")
    backend = SimBackend(PAPER_SLEEVE)
    running = Sleeve(settings, PAPER_SLEEVE, backend, SleeveOptions(sleeve_id=c.sleeve_id))
    thread = threading.Thread(target=running.run, daemon=True)
    thread.start()
    assert running.connected.wait(10), "the sleeve did not connect"
    yield running
    running.stop()
    thread.join(10)
    backend.close()


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
    result = subprocess.run(
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
    assert result.returncode == 0, result.stdout + result.stderr
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
