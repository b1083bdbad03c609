"""``feelmysign study run``: a session in the terminal against a real broker and sleeve."""

from __future__ import annotations

import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from feelmysign.backends.sim import SimBackend
from feelmysign.broker import Broker
from feelmysign.connection import BrokerSettings
from feelmysign.daemon import Sleeve, SleeveOptions
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.study import StudyStore, load_design

DESIGN = """
[study]
name = "terminal"
seed = 3
repetitions = 1
resolutions = ["coarse", "fine"]
[stimulus]
speed_cm_s = 30.0
[[shapes]]
name = "square"
segments = [4, 8]
synonyms = ["box"]
[[practice]]
shape = "line"
[comfort]
questions = ["Comfortable?"]
[questionnaire]
points = 5
items = ["The sleeve was comfortable."]
"""


@pytest.fixture
def sleeve(broker: Broker) -> Iterator[Sleeve]:
    c = broker.credentials
    settings = BrokerSettings(
        c.mqtt_host, c.mqtt_port, username=c.sleeve.username, password=c.sleeve.password
    )
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
    design = tmp_path / "design.toml"
    design.write_text(DESIGN)
    study = tmp_path / "study.sqlite"
    StudyStore.create(study, design, load_design(design)).close()
    # consent, comfort (1 question + adjusted), then per trial: Enter to send, the answer,
    # the confidence; then the questionnaire.
    typed = "y\ny\nn\n" + "\nline\n5\n" + "\na box\n4\n" + "\nno idea\n\n" + "4\n"
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
    assert "coded: square" in result.stdout
    store = StudyStore(study)
    (participant,) = store.participants()
    trials = store.trials(participant["code"])
    assert [t["answer"] for t in trials] == ["line", "a box", "no idea"]
    played = store.query("SELECT COUNT(*) FROM events WHERE type IN ('played', 'adjusted')")
    strokes = sum(t["segments"] for t in trials)
    assert played[0][0] == strokes  # every stroke of every shape played by the sleeve
    assert participant["finished_at_ms"] is not None
