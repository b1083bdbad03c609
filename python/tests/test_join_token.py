"""Join tokens: what add-sleeve prints is what the sleeve reads; a damaged one is named."""

from __future__ import annotations

import pytest

from feelmysign.connection import BrokerConnectionError
from feelmysign.connection.join_token import JoinToken, decode_join_token

FINGERPRINT = "ab" * 32


def test_a_token_round_trips_and_gives_tls_settings() -> None:
    token = JoinToken("mqtts://192.168.1.5:8883", "arm2", "sleeve-arm2", "pw-123456", FINGERPRINT)
    text = token.encode()
    assert text.startswith("fms1.") and "\n" not in text
    assert decode_join_token(f"  {text}\n") == token
    settings = token.settings(ca_file="/tmp/ca.pem")
    assert (settings.host, settings.port, settings.tls, settings.sleeve_id) == (
        "192.168.1.5",
        8883,
        True,
        "arm2",
    )
    assert (settings.username, settings.ca_file) == ("sleeve-arm2", "/tmp/ca.pem")


@pytest.mark.parametrize("url", ["mqtt://127.0.0.1:1883", "ws://localhost:9001", "mqtt://[::1]:1"])
def test_a_token_for_a_sleeve_on_the_broker_s_machine_may_be_plain(url: str) -> None:
    token = JoinToken(url, "arm2", "sleeve-arm2", "pw-123456")
    assert decode_join_token(token.encode()) == token
    assert token.settings().tls is False


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("eyJ1cmwiOiJ4In0", "does not start with 'fms1.'"),
        ("fms1.%%%", "not base64 JSON"),
        (JoinToken("mqtts://h:1", "a", "u", "p", FINGERPRINT).encode()[:-9], "cut or mistyped"),
        (JoinToken("mqtts://h:1", "a", "u", "p", "12").encode(), "not 64 hex digits"),
        (JoinToken("mqtt://h:1883", "a", "u", "p").encode(), "a sleeve joins over TLS unless"),
        (JoinToken("ws://10.0.0.2:80", "a", "u", "p").encode(), "a sleeve joins over TLS unless"),
    ],
)
def test_a_damaged_token_says_what_is_wrong(text: str, problem: str) -> None:
    with pytest.raises(BrokerConnectionError) as caught:
        decode_join_token(text)
    assert caught.value.reason == "bad-token"
    assert problem in str(caught.value)
    assert "add-sleeve" in str(caught.value)
