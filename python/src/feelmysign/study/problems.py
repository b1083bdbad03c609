"""Read values out of a parsed TOML table, collecting every problem instead of stopping at one.

Each reader returns the value, or ``None`` after recording a problem that says
where (``shapes[2].segments``), what was expected, and what was found.
"""

from __future__ import annotations

import math
from typing import Any

from feelmysign.errors import DesignError

MISSING: Any = object()


def show(value: Any) -> str:
    """``value`` as the design file spells it: ``true``, not Python's ``True``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    return repr(value)


class Problems:
    def __init__(self, source: str) -> None:
        self.source = source
        self.items: list[str] = []

    def add(self, key: str, text: str) -> None:
        self.items.append(f"{key}: {text}")

    def raise_if_any(self) -> None:
        if self.items:
            raise DesignError(self.source, self.items)

    def _absent(self, key: str, value: Any, allowed: str, required: bool) -> bool:
        if value is MISSING:
            if required:
                self.add(key, f"missing; give {allowed}")
            return True
        return False

    def integer(
        self, key: str, value: Any, low: int, high: int, *, required: bool = True
    ) -> int | None:
        allowed = f"a whole number from {low} to {high}"
        if self._absent(key, value, allowed, required):
            return None
        if not isinstance(value, int) or isinstance(value, bool) or not low <= value <= high:
            self.add(key, f"must be {allowed}; got {show(value)}")
            return None
        return value

    def number(
        self, key: str, value: Any, low: float, high: float, *, required: bool = True
    ) -> float | None:
        allowed = f"a number from {low:g} to {high:g}"
        if self._absent(key, value, allowed, required):
            return None
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not ok or not math.isfinite(value) or not low <= value <= high:
            self.add(key, f"must be {allowed}; got {show(value)}")
            return None
        return float(value)

    def text(
        self, key: str, value: Any, *, required: bool = True, max_chars: int = 200
    ) -> str | None:
        allowed = f"a text of 1 to {max_chars} characters"
        if self._absent(key, value, allowed, required):
            return None
        if not isinstance(value, str) or not value.strip() or len(value) > max_chars:
            self.add(key, f"must be {allowed}; got {show(value)}")
            return None
        return value.strip()

    def choice(self, key: str, value: Any, choices: tuple[str, ...], default: str) -> str | None:
        if value is MISSING:
            return default
        if value not in choices:
            self.add(key, f"must be one of {', '.join(map(repr, choices))}; got {show(value)}")
            return None
        return str(value)

    def table(self, key: str, value: Any, *, required: bool = False) -> dict[str, Any]:
        if self._absent(key, value, "a table", required):
            return {}
        if not isinstance(value, dict):
            self.add(key, f"must be a table ([{key}]); got {show(value)}")
            return {}
        return value

    def array(self, key: str, value: Any, *, required: bool = True) -> list[Any] | None:
        if self._absent(key, value, "a list [...]", required):
            return None
        if isinstance(value, dict) and "." not in key and "[" not in key:
            # [practice] written where [[practice]] was meant: one table, not a list of them.
            self.add(
                key,
                f"must be a list of tables; got a single [{key}] table: write [[{key}]] (two "
                "brackets) before each entry instead, one per entry",
            )
            return None
        if not isinstance(value, list):
            self.add(key, f"must be a list [...]; got {show(value)}")
            return None
        return value

    def texts(self, key: str, value: Any, *, required: bool = True) -> tuple[str, ...]:
        items = self.array(key, value, required=required)
        if items is None:
            return ()
        out = [self.text(f"{key}[{i}]", item) for i, item in enumerate(items)]
        return tuple(t for t in out if t is not None)

    def unknown(self, key: str, table: dict[str, Any], known: tuple[str, ...]) -> None:
        """A misspelt key is a problem: silently ignoring it would run another study."""
        for name in table:
            if name not in known:
                where = f"{key}.{name}" if key else name
                self.add(where, f"unknown key; the keys here are {', '.join(known)}")
