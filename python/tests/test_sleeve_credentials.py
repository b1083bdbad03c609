"""``sleeve-credentials.json``: the sleeve's login without the sender's password."""

from __future__ import annotations

import json
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from feelmysign.broker import Broker
from feelmysign.broker.credentials import load_login
from feelmysign.errors import BrokerError


def test_the_broker_writes_a_private_sleeve_only_file(broker: Broker) -> None:
    path = broker.sleeve_credentials_path
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    text = path.read_text()
    c = broker.credentials
    assert c.sender.password not in text and "sender" not in json.loads(text)
    login = load_login(path, "sleeve")
    assert (login.url, login.sleeve_id, login.username, login.password) == (
        c.mqtt_url,
        c.sleeve_id,
        c.sleeve.username,
        c.sleeve.password,
    )


def test_a_sleeve_only_file_cannot_send(broker: Broker) -> None:
    with pytest.raises(BrokerError, match="only a sleeve's login"):
        load_login(broker.sleeve_credentials_path, "sender")
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "feelmysign",
            "send",
            "0,0,1,0,100",
            "--credentials",
            str(broker.sleeve_credentials_path),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode != 0
    assert result.stderr.startswith("Error:") and "Traceback" not in result.stderr
    assert "credentials.json" in result.stderr


@pytest.mark.parametrize(
    "content", ['{"sleeve": {"id": "s1"}}', '{"mqtt_url": "mqtt://h:1", "sleeve": []}']
)
def test_a_broken_sleeve_file_is_named(tmp_path: Path, content: str) -> None:
    path = tmp_path / "sleeve-credentials.json"
    path.write_text(content)
    with pytest.raises(BrokerError, match=r"sleeve-credentials\.json"):
        load_login(path, "sleeve")
