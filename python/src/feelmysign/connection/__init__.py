"""Connecting to a broker: settings and URL parsing, the client factory, failure messages."""

from feelmysign.connection.client import DEFAULT_TIMEOUT_S, connect_client, new_client
from feelmysign.connection.failures import connect_failure_message
from feelmysign.connection.settings import (
    DEFAULT_BROKER_URL,
    SCHEMES,
    BrokerSettings,
    parse_broker_url,
)
from feelmysign.errors import BrokerConnectionError

__all__ = [
    "DEFAULT_BROKER_URL",
    "DEFAULT_TIMEOUT_S",
    "SCHEMES",
    "BrokerConnectionError",
    "BrokerSettings",
    "connect_client",
    "connect_failure_message",
    "new_client",
    "parse_broker_url",
]
