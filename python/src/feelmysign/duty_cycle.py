"""Each motor's duty cycle: its drive over a sliding window, the quantity that heats it.

A vibration motor warms with the power it draws, about the square of its
drive, and cools while it rests; a short rest between strokes is a real rest
too. So the sleeve keeps, per actuator, the energy it was driven with,
``intensity**2`` times time, in ms of full drive, over the last
``window_ms``, and a stroke may start only if, with what the strokes already
playing will still add and with the stroke's own commands, that stays within
``max_duty_cycle * window_ms`` (the budget).

The check is conservative in one way only: the energy still to come is added
to the energy of the whole past window, as if none of the past were about to
leave it. So a stroke that starts always plays to its end uncut, and no
window ever holds more than the budget. A motor used at a steady fraction of
the time is never refused while that fraction of the window plus twice the
stroke length stays under the budget (sufficient, loose for long strokes):
with the defaults (a minute, 0.5, 10 s strokes at most) up to 45% for strokes
under a second, and a property test checks any pace up to a fifth of the time
whatever the strokes' length.

Pure: times come in as arguments (the timeline's, in ms).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

Actuator = tuple[int, int]

# surely_fits keeps this much of the budget in hand (a fraction of it, and ms of full
# drive): far more than the rounding of its running totals over days, far less than felt.
SURE_MARGIN = 1e-6
SURE_MARGIN_MS = 1e-3


@dataclass(frozen=True)
class Drive:
    """``energy`` (intensity squared) from ``start_ms`` to ``end_ms`` on one actuator."""

    start_ms: float
    end_ms: float
    energy: float


@dataclass(frozen=True)
class Refusal:
    """A stroke the cap refused: the first actuator over its budget, and by how much."""

    actuator: Actuator
    duty_cycle: float  # what the window would hold, as a fraction of it at full drive
    max_duty_cycle: float
    window_ms: float


class DutyCycle:
    """Past drive per actuator (as written) and committed drive (strokes admitted, not over)."""

    def __init__(self, window_ms: float, max_duty_cycle: float) -> None:
        if not window_ms > 0 or not 0 < max_duty_cycle <= 1:
            raise ValueError(
                f"window_ms must be above 0 and max_duty_cycle in (0, 1]; "
                f"got {window_ms}, {max_duty_cycle}"
            )
        self.window_ms = window_ms
        self.max_duty_cycle = max_duty_cycle
        self.budget_ms = window_ms * max_duty_cycle
        self._past: dict[Actuator, deque[Drive]] = {}
        # Per actuator, the energy of its past drives whole (what the window can hold of them
        # at most): kept as they come and go, for ``surely_fits``.
        self._past_total: dict[Actuator, float] = {}
        self._level: dict[Actuator, tuple[float, float]] = {}  # actuator -> (since_ms, energy)
        self._committed: dict[Actuator, list[Drive]] = {}
        # Per actuator, the energy of its committed drives whole: kept as they are committed.
        self._committed_total: dict[Actuator, float] = {}

    def output(self, actuator: Actuator, t_ms: float, intensity: float) -> None:
        """The actuator's output changed to ``intensity`` at ``t_ms``."""
        since = self._level.pop(actuator, None)
        if since is not None and t_ms > since[0]:
            self._past.setdefault(actuator, deque()).append(Drive(since[0], t_ms, since[1]))
            total = self._past_total.get(actuator, 0.0)
            self._past_total[actuator] = total + since[1] * (t_ms - since[0])
        if intensity > 0:
            self._level[actuator] = (t_ms, intensity * intensity)
        self._forget(actuator, t_ms)

    def energy_ms(self, actuator: Actuator, now_ms: float) -> float:
        """ms of full drive in the window that ends at ``now_ms`` (the drive so far only)."""
        start = now_ms - self.window_ms
        total = sum(_overlap(d, start, now_ms) for d in self._past.get(actuator, ()))
        level = self._level.get(actuator)
        if level is not None:
            total += _overlap(Drive(level[0], now_ms, level[1]), start, now_ms)
        return total

    def check(self, drives: dict[Actuator, list[Drive]], now_ms: float) -> Refusal | None:
        """None if a stroke with ``drives`` (per actuator) may start at ``now_ms``."""
        for actuator, planned in sorted(drives.items()):
            to_come = sum(_ahead(d, now_ms) for d in self._committed.get(actuator, ()))
            total = (
                self.energy_ms(actuator, now_ms) + to_come + sum(_ahead(d, now_ms) for d in planned)
            )
            if total > self.budget_ms:
                return Refusal(
                    actuator, total / self.window_ms, self.max_duty_cycle, self.window_ms
                )
        return None

    def surely_fits(self, energy_ms: float, now_ms: float) -> bool:
        """True only if ``check`` would admit, at ``now_ms``, any stroke whose drive on each
        of its actuators is at most ``energy_ms``; False when it cannot tell so cheaply.

        Answers from running totals, without summing the window's drives, each bound
        above: the past drives whole, the level held since it began, the committed drives
        whole. The margin covers the rounding of the totals kept over time.
        """
        limit = self.budget_ms * (1 - SURE_MARGIN) - SURE_MARGIN_MS
        if energy_ms * (1 + SURE_MARGIN) > limit:
            return False
        # First the largest past and the largest committed total, whichever actuators hold
        # them, and every level held: above any one actuator's load. Mostly enough, and it
        # asks nothing per actuator (this runs before a stroke's first motor command).
        bound = (
            energy_ms * (1 + SURE_MARGIN)
            + max(self._past_total.values(), default=0.0)
            + max(self._committed_total.values(), default=0.0)
        )
        for since_ms, energy in self._level.values():
            bound += energy * max(0.0, now_ms - since_ms)
        if bound <= limit:
            return True
        for actuator in {*self._past_total, *self._level, *self._committed}:
            load = self._past_total.get(actuator, 0.0)
            level = self._level.get(actuator)
            if level is not None:
                load += level[1] * max(0.0, now_ms - level[0])
            for drive in self._committed.get(actuator, ()):
                load += drive.energy * (drive.end_ms - drive.start_ms)
            if load + energy_ms * (1 + SURE_MARGIN) > limit:
                return False
        return True

    def commit(self, drives: dict[Actuator, list[Drive]], now_ms: float) -> None:
        """The stroke with ``drives`` started: its drive counts until it is over."""
        for actuator, planned in drives.items():
            kept = [d for d in self._committed.get(actuator, ()) if d.end_ms > now_ms]
            committed = self._committed[actuator] = kept + list(planned)
            total = 0.0
            for drive in committed:  # summed as surely_fits sums them
                total += drive.energy * (drive.end_ms - drive.start_ms)
            self._committed_total[actuator] = total

    def clear(self) -> None:
        """Nothing committed any more (the plan was dropped); the past stays: it heated."""
        self._committed.clear()
        self._committed_total.clear()

    def _forget(self, actuator: Actuator, now_ms: float) -> None:
        past = self._past.get(actuator)
        while past and past[0].end_ms <= now_ms - self.window_ms:
            gone = past.popleft()
            self._past_total[actuator] -= gone.energy * (gone.end_ms - gone.start_ms)
        if past is not None and not past:
            self._past_total.pop(actuator, None)  # and with it any rounding kept so far


def _overlap(drive: Drive, start_ms: float, end_ms: float) -> float:
    span = min(drive.end_ms, end_ms) - max(drive.start_ms, start_ms)
    return drive.energy * span if span > 0 else 0.0


def _ahead(drive: Drive, now_ms: float) -> float:
    span = drive.end_ms - max(drive.start_ms, now_ms)
    return drive.energy * span if span > 0 else 0.0
