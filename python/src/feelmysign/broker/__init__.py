"""The local broker: Mosquitto run as a child process from a generated config.

``mosquitto``: the ``Broker`` object (start, wait, stop); ``credentials``: the
accounts and ``credentials.json`` (``Credentials.settings(role)``: how the sleeve or
the sender connects, as ``connection.BrokerSettings``); ``_config``: the files
Mosquitto reads (``StateFiles``, where they all live, and ``hash_password``, the
password file's hash, are public here); ``_process``: finding, starting and
stopping the executable (``find_mosquitto`` is public here).
"""

from feelmysign.broker._config import StateFiles, hash_password
from feelmysign.broker._process import find_mosquitto
from feelmysign.broker.credentials import Account, Credentials, load_credentials
from feelmysign.broker.mosquitto import DEFAULT_WS_PORT, Broker, default_state_dir
from feelmysign.connection.settings import DEFAULT_MQTT_PORT, DEFAULT_SLEEVE_ID
from feelmysign.errors import BrokerError

__all__ = [
    "DEFAULT_MQTT_PORT",
    "DEFAULT_SLEEVE_ID",
    "DEFAULT_WS_PORT",
    "Account",
    "Broker",
    "BrokerError",
    "Credentials",
    "StateFiles",
    "default_state_dir",
    "find_mosquitto",
    "hash_password",
    "load_credentials",
]
