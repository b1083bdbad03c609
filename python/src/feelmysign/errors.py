"""The few exception classes of feelmysign, each carrying its data as attributes.

Algorithms report expected trouble (a stroke too fast, a payload malformed) as
values, not exceptions; these are for what a caller cannot go on from.
"""

from __future__ import annotations

from feelmysign.plural import plural

TYPE_CHECKING = False  # typing and pathlib cost start-up imports; mypy reads this name as True
if TYPE_CHECKING:
    from pathlib import Path


class FeelMySignError(Exception):
    """Base class: every error this package raises on purpose."""


class StrokeError(FeelMySignError):
    """A stroke the sleeve cannot render: outside the grid, non-finite, too fast in strict mode.

    ``reason`` is a stable code (the same codes as the protocol's validation), the
    message a sentence a person can act on.
    """

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason
        self.message = message


class LayoutError(FeelMySignError):
    """A sleeve layout that is wrong; ``problems`` lists every problem found, not only the first."""

    def __init__(self, source: str, problems: list[str]) -> None:
        self.source = source
        self.problems = list(problems)
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(
            f"{source}: {plural(len(self.problems), 'problem')} in the sleeve layout:\n{lines}"
        )


class HardwareError(FeelMySignError):
    """Hardware that did not answer or answered wrongly (an I2C chip, a multiplexer channel)."""


class ParameterError(FeelMySignError, ValueError):
    """A parameter outside its allowed range; carries the name, the value and the range."""

    def __init__(self, name: str, value: object, allowed: str) -> None:
        self.name = name
        self.value = value
        self.allowed = allowed
        super().__init__(f"{name} = {value!r} is not allowed; it must be {allowed}")


class BrokerError(FeelMySignError):
    """The local Mosquitto could not be set up, started or kept running.

    ``reason`` is a stable code a program can branch on:

    - ``mosquitto-missing``: no ``mosquitto`` executable was found;
    - ``port-in-use``: ``port`` is taken by another program;
    - ``bad-option``: a sleeve id, port or topic that cannot be used;
    - ``credentials-file``: a ``credentials.json`` that cannot be read or is wrong;
    - ``start-failed``: Mosquitto exited or never accepted connections at start-up;
    - ``exited``: Mosquitto stopped while it should have been running;
    - ``already-running``: another feelmysign holds the state directory (``up`` or
      ``broker``); the message says which, where it is, and how to stop it.

    ``log_path`` is Mosquitto's log file when there is one to look at; ``exit_code``
    is how Mosquitto ended, for ``exited``.
    """

    def __init__(
        self,
        reason: str,
        message: str,
        *,
        port: int | None = None,
        log_path: Path | None = None,
        exit_code: int | None = None,
    ) -> None:
        super().__init__(message)
        self.reason = reason
        self.message = message
        self.port = port
        self.log_path = log_path
        self.exit_code = exit_code


class BrokerConnectionError(BrokerError):
    """A broker that cannot be reached, refuses the login, or refuses or drops a message.

    ``reason`` (as for BrokerError) is one of ``bad-url``, ``bad-option``,
    ``refused`` (nothing listens), ``unreachable`` (name, route, TLS),
    ``login-refused``, ``timeout``, ``closed`` (the connection dropped) and
    ``publish-refused``; ``url`` is the broker's URL when known.
    """

    def __init__(self, reason: str, message: str, *, url: str | None = None) -> None:
        super().__init__(reason, message)
        self.url = url


class StudyError(FeelMySignError):
    """A study that cannot go on as asked: an unknown participant, a trial already answered,
    a study file of another version. The message says what to do."""


class DesignError(StudyError):
    """A study design file that is wrong; ``problems`` lists every problem found, not only the
    first."""

    def __init__(self, source: str, problems: list[str]) -> None:
        self.source = source
        self.problems = list(problems)
        lines = "\n".join(f"  - {p}" for p in self.problems)
        counted = plural(len(self.problems), "problem")
        super().__init__(f"{source}: {counted} in the study design:\n{lines}")
