"""A broker that closes the sleeve's connection at each login (here: Mosquitto with
retain_available false, which drops a client publishing a retained message) is named, with
what such a broker usually refuses, once, instead of an endless 'lost the broker'."""

from __future__ import annotations

from pathlib import Path

from bare_mosquitto import BareMosquitto, sleeve_process, wait_in_log

SAID = "closed the connection within"


def test_a_broker_refusing_retained_messages_is_named(tmp_path: Path) -> None:
    log = tmp_path / "sleeve.log"
    settings = ["retain_available false", "persistence false"]
    with BareMosquitto(tmp_path, settings) as broker, sleeve_process(broker.url, log) as sleeve:
        said = wait_in_log(log, SAID, sleeve)
    assert SAID in said and "retain_available false" in said, said
    assert said.count(SAID) == 1
    # Never logged in: no broker was "lost".
    assert "closed the connection before taking the login" in said, said
    assert "lost the broker" not in said, said
