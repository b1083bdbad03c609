"""A faster ``__init__`` for frozen dataclasses made by the thousand on the sleeve's hot path.

The ``__init__`` a frozen dataclass generates sets each field through
``object.__setattr__``, since its own ``__setattr__`` refuses. A planned stroke
makes a dozen commands and bursts, and those calls took a quarter of planning it.
``dict_init`` gives the class an ``__init__`` with the same parameters and
defaults that sets every field with one update of the instance's ``__dict__``.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

C = TypeVar("C", bound=type)


def dict_init(cls: C) -> C:
    """Decorate a frozen dataclass (below ``@dataclass``): one dict update sets its fields.

    The replacement is compiled from source as dataclasses compiles its own, so
    that it is a plain function with named parameters: no ``*args`` to bind on
    every call. Its signature is the dataclass's, which is what type checkers see.
    """
    names, parameters, defaults = [], [], {}
    for item in dataclasses.fields(cls):
        if item.default_factory is not dataclasses.MISSING or not item.init:
            raise TypeError(f"{cls.__name__}.{item.name}: dict_init takes plain fields only")
        names.append(item.name)
        if item.default is dataclasses.MISSING:
            parameters.append(item.name)
        else:
            defaults[f"_default_{item.name}"] = item.default
            parameters.append(f"{item.name}=_default_{item.name}")
    assignments = ", ".join(f"{name}={name}" for name in names)
    source = (
        f"def __init__(self, {', '.join(parameters)}):\n    self.__dict__.update({assignments})\n"
    )
    made: dict[str, Any] = {}
    exec(source, defaults, made)  # the source is built above from the field names alone
    init = made["__init__"]
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    init.__doc__ = f"A {cls.__name__}, its fields set with one dict update (``dict_init``)."
    setattr(cls, "__init__", init)  # noqa: B010 (mypy refuses assigning __init__ on a type)
    return cls
