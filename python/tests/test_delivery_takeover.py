"""A sender's login cannot take over the sleeve's session: the sleeve's client id is one only
a holder of the sleeve's password can name."""

from __future__ import annotations

import threading
import time
from pathlib import Path

from conftest import StartBroker
from delivery import by_seq, delivery, played, stroke, wait_for
from sleeve_watch import settings

from feelmysign.connection import new_client
from feelmysign.daemon import sleeve_client_id

STROKES = 20
DURATION_MS = 100.0
ATTEMPTS = 5


def test_sender_logins_with_the_sleeves_client_id_do_not_disconnect_it(
    start_broker: StartBroker, tmp_path: Path
) -> None:
    with delivery(start_broker, tmp_path, sleeve_login=True) as (broker, watcher, sleeve, sender):
        c = broker.credentials
        # What an attacker with the sender's login would try: the sleeve's former client id,
        # and the scheme's id computed with the password it has.
        guesses = [
            f"feelmysign-sleeve-{c.sleeve_id}",
            sleeve_client_id(c.sleeve_id, c.sender.password),
        ]
        taken: list[str] = []

        def take_over() -> None:
            for attempt in range(ATTEMPTS):
                client_id = guesses[attempt % 2]
                intruder = new_client(settings(c, "sender"), client_id=client_id)
                accepted = threading.Event()
                intruder.on_connect = lambda *args, accepted=accepted: accepted.set()
                intruder.connect(c.mqtt_host, c.mqtt_port)
                intruder.loop_start()
                if accepted.wait(10):  # the broker let it in under that id
                    taken.append(client_id)
                time.sleep(0.2)  # it stays a while, as a takeover would
                intruder.loop_stop()
                intruder.disconnect()

        log_start = broker.log_path.stat().st_size
        intruders = threading.Thread(target=take_over)
        intruders.start()
        for seq in range(STROKES):
            sender.publish(
                seq, stroke(sender.drawing, seq, DURATION_MS, sent_at_ms=time.time() * 1000)
            )
            time.sleep(DURATION_MS / 1000)  # drawing time: the pace is the point
        intruders.join(30)
        assert len(taken) == ATTEMPTS
        wait_for(
            lambda: set(range(STROKES)) <= set(by_seq(played(watcher.snapshot()), sender.drawing)),
            "every stroke to play",
        )
        log = broker.log_path.read_bytes()[log_start:].decode(errors="replace")
        assert "closing old connection" not in log, log
        assert "lost the broker" not in sleeve.log.read_text()


def test_the_client_id_depends_on_the_sleeves_password() -> None:
    first, second = sleeve_client_id("sleeve1", "p" * 32), sleeve_client_id("sleeve1", "q" * 32)
    assert first != second and first.startswith("feelmysign-sleeve-sleeve1-")
    assert len(first) == len("feelmysign-sleeve-sleeve1-") + 32
    assert sleeve_client_id("sleeve1", None) == "feelmysign-sleeve-sleeve1"
