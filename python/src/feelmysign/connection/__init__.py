"""Connecting to a broker: settings and URL parsing, the client factory, failure messages."""

from feelmysign.connection.client import (
    DEFAULT_TIMEOUT_S,
    RECONNECT_MAX_S,
    RECONNECT_MIN_S,
    connect_client,
    jitter_reconnects,
    new_client,
    probe_login,
)
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
    "RECONNECT_MAX_S",
    "RECONNECT_MIN_S",
    "SCHEMES",
    "BrokerConnectionError",
    "BrokerSettings",
    "connect_client",
    "connect_failure_message",
    "jitter_reconnects",
    "new_client",
    "parse_broker_url",
    "probe_login",
]
