"""``feelmysign send --wait`` when the sleeve's process dies in the middle of a stroke: the
broker publishes the sleeve's will (status offline) at once, and ``send`` does not count the
stroke played whole (before, 'The sleeve played 1 of 1 strokes', exit 0)."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

from conftest import StartBroker
from delivery import SleeveProcess
from sleeve_watch import SleeveWatch, online
from test_outcome_catch_up import REF, message, outcome_of, played

WAIT_S = 60.0
STROKE_MS = 6000


def test_send_does_not_count_played_a_stroke_the_sleeve_died_in(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    broker = start_broker(state_dir=tmp_path / "state")
    with (
        SleeveWatch(broker.credentials, "status", "events") as watcher,
        SleeveProcess(broker.credentials_path, tmp_path / "sleeve.jsonl") as sleeve,
    ):
        watcher.next(online, "the sleeve online")
        command = [sys.executable, "-m", "feelmysign", "send", "--credentials"]
        command += [str(broker.credentials_path), "--wait", f"0,1,3,1,{STROKE_MS}"]
        send = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        watcher.next(lambda n, b: b.get("type") == "played", "the stroke played")
        time.sleep(1.0)
        sleeve.kill()
        out, err = send.communicate(timeout=WAIT_S)
    assert send.returncode == 1, out + err
    assert "The sleeve played 1 of 1" not in out + err, out + err
    assert "played 0 of 1 strokes" in err, err
    assert "went offline while it played stroke(s) 1: how much of them was felt" in err, err
    assert "Traceback" not in err


def test_only_a_stroke_still_on_the_skin_when_the_sleeve_went_offline_is_not_counted() -> None:
    """A stroke whose time on the skin was over is played; one still playing is not known;
    an answer about it that comes after all (the restarted sleeve's ``crashed``) stands."""
    outcome = outcome_of(3, played(0, duration_ms=1.0), played(1, duration_ms=60_000.0))
    time.sleep(0.01)  # stroke 0's millisecond is over
    outcome.went_offline()
    summary = outcome.summary()
    assert (summary.played, summary.offline, summary.unheard) == (1, [1], [2])
    assert not summary.all_played
    assert "went offline while it played stroke(s) 2" in summary.text()
    crashed = {"type": "safety", "reason": "crashed", "row": 0, "column": 0, "seq": 1, **REF}
    outcome.on_message(None, None, message(crashed))  # type: ignore[arg-type]
    after = outcome.summary()
    assert (after.offline, dict(after.cut)) == ([], {"crashed": 1}), after
