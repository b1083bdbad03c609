"""The exception of the local broker (meant to move to ``feelmysign.errors``)."""

from __future__ import annotations

from pathlib import Path

from feelmysign.errors import FeelMySignError


class BrokerError(FeelMySignError):
    """The local Mosquitto could not be set up, started or kept running.

    ``reason`` is a stable code a program can branch on:

    - ``mosquitto-missing``: no ``mosquitto`` executable was found;
    - ``port-in-use``: ``port`` is taken by another program;
    - ``bad-option``: a sleeve id, port or topic that cannot be used;
    - ``credentials-file``: a ``credentials.json`` that cannot be read or is wrong;
    - ``start-failed``: Mosquitto exited or never accepted connections at start-up;
    - ``exited``: Mosquitto stopped while it should have been running.

    ``log_path`` is Mosquitto's log file when there is one to look at.
    """

    def __init__(
        self,
        reason: str,
        message: str,
        *,
        port: int | None = None,
        log_path: Path | None = None,
    ) -> None:
        super().__init__(message)
        self.reason = reason
        self.message = message
        self.port = port
        self.log_path = log_path
