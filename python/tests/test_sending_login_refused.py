"""A StrokeSender hears a reconnection's refused login through the client's on_connect,
which it wraps once per client: a sender per trial (the study) must not nest wrappers."""

from __future__ import annotations

from typing import Any

from feelmysign.connection import new_client, parse_broker_url
from feelmysign.sending import StrokeSender


def test_each_sender_on_a_client_wraps_its_first_on_connect_once() -> None:
    settings = parse_broker_url("mqtt://127.0.0.1:1", username="sender", password="x")
    client = new_client(settings)
    heard: list[Any] = []

    def subscribe_again(*args: Any) -> None:
        heard.append(args)

    client.on_connect = subscribe_again
    for _ in range(3):
        StrokeSender(client, settings, timeout_s=1.0)
    wrapper: Any = client.on_connect
    assert wrapper is not subscribe_again
    assert wrapper.wrapped is subscribe_again  # not a wrapper of a wrapper
