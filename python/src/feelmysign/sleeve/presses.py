"""A button's presses, debounced, told apart by how long they are held: levels in, presses out.

A mechanical button bounces: for a few milliseconds after it is pressed or let go its
contact opens and closes. The first change is taken at once (the wearer's pause must
not wait for the bouncing to end), and changes in the ``DEBOUNCE_MS`` after an accepted
one are ignored; the level is looked at again when that window closes, so a change
that happened inside it is not lost.

What comes out, for :mod:`feelmysign.backends.button` to act on:

- ``"press"``: the button went down (at once, before anyone knows how long it is held);
- ``"short"``: it came up before ``LONG_PRESS_MS``;
- ``"long"``: it has been held ``LONG_PRESS_MS`` (once per press, while it is still down).
"""

from __future__ import annotations

from typing import Literal

Press = Literal["press", "short", "long"]

# Switches bounce for 1 to 10 ms (Ganssle, "A Guide to Debouncing", 2008: most settle within
# 6 ms); 30 ms leaves room for a worn one and is still far below two presses a person makes.
DEBOUNCE_MS = 30.0
# A deliberate hold, not a slow press: about what phones take for a long press (Android's
# default long-press timeout is 0.4 to 0.5 s) and more, as a stop cannot be undone.
LONG_PRESS_MS = 1000.0


class Presses:
    """Feed the button's level on each edge (``level``) and call ``tick`` by ``next_ms``."""

    def __init__(
        self,
        *,
        pressed: bool = False,
        now_ms: float = 0.0,
        debounce_ms: float = DEBOUNCE_MS,
        long_press_ms: float = LONG_PRESS_MS,
    ) -> None:
        # A button already held at start is taken as held: nothing happens until it is let go
        # and pressed again (a stuck button must not pause and resume the sleeve by itself).
        self._down = pressed
        self._raw = pressed
        self._changed_ms = now_ms - debounce_ms
        self._long_done = pressed
        self._debounce_ms = debounce_ms
        self._long_press_ms = long_press_ms

    @property
    def down(self) -> bool:
        return self._down

    def level(self, pressed: bool, now_ms: float) -> list[Press]:
        """The button reads ``pressed`` at ``now_ms``: the presses this makes."""
        self._raw = pressed
        return self.tick(now_ms)

    def tick(self, now_ms: float) -> list[Press]:
        """What the time alone makes: a change held through the bounce, or a long press."""
        out: list[Press] = []
        if self._raw != self._down and now_ms - self._changed_ms >= self._debounce_ms:
            self._down, self._changed_ms = self._raw, now_ms
            if self._down:
                self._long_done = False
                out.append("press")
            elif not self._long_done:
                out.append("short")
        if self._down and not self._long_done and now_ms - self._changed_ms >= self._long_press_ms:
            self._long_done = True
            out.append("long")
        return out

    def next_ms(self) -> float | None:
        """When ``tick`` has something to decide next (None: only an edge can change things)."""
        times = []
        if self._raw != self._down:
            times.append(self._changed_ms + self._debounce_ms)
        if self._down and not self._long_done:
            times.append(self._changed_ms + self._long_press_ms)
        return min(times) if times else None
