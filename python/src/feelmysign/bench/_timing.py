"""Timing helpers: best-of-N repeats of a callable, per item."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, TypeVar

T = TypeVar("T")


@dataclass(frozen=True)
class Rate:
    name: str
    items: int
    seconds: float

    @property
    def per_second(self) -> float:
        return self.items / self.seconds

    @property
    def us_per_item(self) -> float:
        return self.seconds / self.items * 1e6


def best_rate(name: str, work: Callable[[], int], *, repeats: int = 5) -> Rate:
    """The fastest of ``repeats`` runs (the least disturbed by the rest of the machine)."""
    best = float("inf")
    items = 0
    for _ in range(repeats):
        start = time.perf_counter()
        items = work()
        best = min(best, time.perf_counter() - start)
    return Rate(name, items, best)


def each(work: Callable[[T], Any], items: Iterable[T]) -> int:
    """``work`` on every item, each result let go at once (as the sleeve does with a stroke's
    plan); how many. Keeping them all would make the garbage collector walk them on each pass."""
    count = 0
    for item in items:
        work(item)
        count += 1
    return count


def row(rate: Rate, baseline: Rate) -> str:
    ratio = rate.us_per_item / baseline.us_per_item
    return (
        f"  {rate.name:<44} {rate.per_second:>12,.0f}/s  {rate.us_per_item:>9.2f} us each"
        f"  {ratio:>7.1f}x baseline"
    )
