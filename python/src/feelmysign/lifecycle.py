"""``with`` blocks for what the project starts and stops: one ``__enter__`` and ``__exit__``."""

from __future__ import annotations

from types import TracebackType
from typing import Self


class Closing:
    """``with x:`` closes ``x`` at the end of the block (``close()``), however it ends."""

    def close(self) -> None:
        raise NotImplementedError

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        _type: type[BaseException] | None,
        _value: BaseException | None,
        _traceback: TracebackType | None,
    ) -> None:
        self.close()


class Started(Closing):
    """``with x:`` starts ``x`` (``start()``) and stops it (``stop()``) at the end."""

    def start(self) -> object:
        raise NotImplementedError

    def stop(self) -> None:
        raise NotImplementedError

    def close(self) -> None:
        self.stop()

    def __enter__(self) -> Self:
        self.start()
        return self
