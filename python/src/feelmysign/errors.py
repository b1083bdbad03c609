"""The few exception classes of feelmysign, each carrying its data as attributes.

Algorithms report expected trouble (a stroke too fast, a payload malformed) as
values, not exceptions; these are for what a caller cannot go on from.
"""

from __future__ import annotations


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
            f"{source}: {len(self.problems)} problem(s) in the sleeve layout:\n{lines}"
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
