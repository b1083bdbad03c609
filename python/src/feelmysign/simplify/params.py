"""Parameters of the simplifiers, each declared once: default, allowed range, unit, help, label.

A parameter is a field of its simplifier's parameter dataclass, declared with
``param`` (its default, range, unit, help, the paper's name for it, and where
the page's settings panel shows it, and, for a parameter only one core of its simplifier
reads, the switch and value that choose that core: ``only_when``). The parameters every
simplifier has (the
canvas, the sleeve's grid, the shortest stroke to send) are the fields of
``SharedParams``, declared here once; each simplifier declares its own beside
its code (``angle.py``, ``window.py``). ``specs_of`` reads the declarations
back as ``ParamSpec`` rows, and everything else is derived from them:

- every parameter dataclass checks its values against them (``check_all``);
- ``feelmysign simplify`` builds its options, help and ranges from them, and refuses an
  option its simplifier or core would ignore;
- ``testdata/generate.py`` writes them as the language-neutral table
  ``testdata/params/params.json`` (the clients in other languages read it), as
  each simplifier's ``testdata/<algorithm>/params.json``, and as the page's
  types and settings rows, ``web/src/simplify/params.generated.ts``.
"""

from __future__ import annotations

import math
import typing
from dataclasses import dataclass, field, fields
from typing import Any, Literal, TypeVar

from feelmysign.errors import ParameterError
from feelmysign.simplify.mapping import CanvasMapping

# Where the page's settings panel shows a parameter: "drawing" (how the page treats a
# drawing, not how it is cut), "simplifier" (how it is cut), "sleeve" (the grid); None: the
# page sets it itself (the canvas is the drawing area).
Panel = Literal["drawing", "simplifier", "sleeve"]

_KINDS: dict[type, str] = {bool: "boolean", int: "integer", float: "number"}
_DECLARATION = "feelmysign.param"

T = TypeVar("T", bool, int, float)


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: its name, type, default, allowed range and how people see it."""

    name: str
    kind: type
    default: bool | int | float
    minimum: float | None
    maximum: float | None
    help: str
    # What a person reads: the settings panel's label, and the unit after a value.
    label: str
    unit: str | None = None
    # Its name in the paper's appendix B.1 (its sleeveX and sleeveY count from 0).
    paper: str | None = None
    panel: Panel | None = "simplifier"
    # The values of the page's one "detail" control, coarse to fine, for the parameter it sets.
    detail_levels: tuple[float, ...] = ()
    # A few letters for plot legends (``feelmysign evaluate``), where the name is too long.
    short: str | None = None
    # Read only when another (boolean) parameter of the same simplifier has this value, e.g.
    # ("least_squares", True): the one core that reads it. Otherwise it changes nothing, so the
    # CLI refuses it and the page's settings panel locks it. None: always read.
    only_when: tuple[str, bool] | None = None

    def check(self, value: Any) -> None:
        if self.kind is bool:
            if not isinstance(value, bool):
                raise ParameterError(self.name, value, "true or false")
            return
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(self.name, value, f"a number in {self.range_text()}")
        if self.kind is int and not float(value).is_integer():
            raise ParameterError(self.name, value, f"a whole number in {self.range_text()}")
        if not math.isfinite(value) or not self._in_range(float(value)):
            raise ParameterError(self.name, value, f"in {self.range_text()}")

    def _in_range(self, value: float) -> bool:
        low_ok = self.minimum is None or value >= self.minimum
        high_ok = self.maximum is None or value <= self.maximum
        return low_ok and high_ok

    def range_text(self) -> str:
        return f"[{_fmt(self.minimum)}, {_fmt(self.maximum)}]"

    @property
    def type_name(self) -> str:
        """``boolean``, ``integer`` or ``number``: the type as the JSON tables name it."""
        return _KINDS[self.kind]

    def to_json(self) -> dict[str, Any]:
        """The row of one simplifier's table (``testdata/<algorithm>/params.json``)."""
        return {
            "name": self.name,
            "type": self.type_name,
            "default": self.default,
            "minimum": self.minimum,
            "maximum": self.maximum,
            "help": self.help,
        }

    def to_table(self, algorithms: list[str]) -> dict[str, Any]:
        """The row of the language-neutral table (``testdata/params/params.json``)."""
        return {
            "name": self.name,
            "algorithms": algorithms,
            "paper": self.paper,
            "type": self.type_name,
            "default": self.default,
            "minimum": self.minimum,
            "maximum": self.maximum,
            "unit": self.unit,
            "label": self.label,
            "help": self.help,
            "panel": self.panel,
            "detail_levels": list(self.detail_levels) or None,
            "short": self.short,
            "only_when": (
                None
                if self.only_when is None
                else {"name": self.only_when[0], "value": self.only_when[1]}
            ),
        }

    def applies(self, values: dict[str, Any]) -> bool:
        """Whether a simplifier with these values (by name) reads this parameter."""
        if self.only_when is None:
            return True
        name, value = self.only_when
        return bool(values[name] == value)


def _fmt(bound: float | None) -> str:
    return "unbounded" if bound is None else f"{bound:g}"


@dataclass(frozen=True)
class _Declaration:
    """What ``param`` keeps of a field; its name and type are the field's own."""

    minimum: float | None
    maximum: float | None
    help: str
    label: str
    unit: str | None
    paper: str | None
    panel: Panel | None
    detail_levels: tuple[float, ...]
    short: str | None
    only_when: tuple[str, bool] | None


def param(
    default: T,
    minimum: float | None = None,
    maximum: float | None = None,
    *,
    help: str,
    label: str,
    unit: str | None = None,
    paper: str | None = None,
    panel: Panel | None = "simplifier",
    detail_levels: tuple[float, ...] = (),
    short: str | None = None,
    only_when: tuple[str, bool] | None = None,
) -> T:
    """A parameter field with its default and its declaration (read back by ``specs_of``)."""
    declaration = _Declaration(
        minimum, maximum, help, label, unit, paper, panel, detail_levels, short, only_when
    )
    # field() is typed as the default's type, so the dataclass field keeps its own type.
    return field(default=default, metadata={_DECLARATION: declaration})


_SPECS: dict[type, dict[str, ParamSpec]] = {}


def specs_of(params_class: type) -> dict[str, ParamSpec]:
    """The parameters of a parameter dataclass, by name, in its field order."""
    if params_class not in _SPECS:
        _SPECS[params_class] = _read_specs(params_class)
    return _SPECS[params_class]


def _read_specs(params_class: type) -> dict[str, ParamSpec]:
    hints = typing.get_type_hints(params_class)
    specs: dict[str, ParamSpec] = {}
    for item in fields(params_class):
        declared: _Declaration = item.metadata[_DECLARATION]
        kind = hints[item.name]
        # Exactly the field's type: a default of 20 for a float would be written as 20, not 20.0.
        if not isinstance(item.default, (bool, int, float)) or type(item.default) is not kind:
            raise TypeError(f"{params_class.__name__}.{item.name}: the default is not a {kind}")
        specs[item.name] = ParamSpec(
            item.name,
            kind,
            item.default,
            declared.minimum,
            declared.maximum,
            declared.help,
            declared.label,
            declared.unit,
            declared.paper,
            declared.panel,
            declared.detail_levels,
            declared.short,
            declared.only_when,
        )
    for spec in specs.values():
        if spec.only_when is None:
            continue
        name, value = spec.only_when
        condition = specs.get(name)
        if condition is None or condition.kind is not bool or not isinstance(value, bool):
            raise TypeError(
                f"{params_class.__name__}.{spec.name}: only_when names {name!r}, "
                "not a boolean parameter of the same class"
            )
    return specs


def check_all(params: object) -> None:
    """Raise ParameterError for the first field of a params dataclass outside its range."""
    for spec in specs_of(type(params)).values():
        spec.check(getattr(params, spec.name))


@dataclass(frozen=True)
class SharedParams:
    """The parameters every simplifier has: which strokes it drops, the grid and the canvas.

    A simplifier's parameters are ``class XParams(SharedParams, XOwn)``: a dataclass
    lists the fields of its last base first, so its own parameters come first and these
    after them, the order of every table and vector. The defaults are the paper's
    (appendix B.1).
    """

    clear_on_press: bool = param(
        True,
        help="a new press clears the drawing",
        label="Clear on press",
        paper="clickClear",
        panel="drawing",
    )
    min_duration_ms: float = param(
        6.1,
        0,
        10_000,
        help="shortest stroke to send, in ms",
        label="Min duration",
        unit="ms",
        paper="minimumDuration",
    )
    min_length: float = param(
        0.1,
        0,
        100,
        help="shortest stroke to send, in grid units (the window's least-squares core holds "
        "only a path's first piece to it, unless strict_minimums)",
        label="Min length",
        unit="grid units",
        paper="minimumSize",
    )
    rows: int = param(
        3, 1, 64, help="actuator rows of the sleeve", label="Rows", paper="sleeveY", panel="sleeve"
    )
    columns: int = param(
        4,
        1,
        64,
        help="actuator columns of the sleeve",
        label="Columns",
        paper="sleeveX",
        panel="sleeve",
    )
    canvas_width_px: float = param(
        1920.0,
        1,
        100_000,
        help="drawing area width in pixels",
        label="Canvas width",
        unit="px",
        paper="screenX",
        panel=None,
    )
    canvas_height_px: float = param(
        1080.0,
        1,
        100_000,
        help="drawing area height in pixels",
        label="Canvas height",
        unit="px",
        paper="screenY",
        panel=None,
    )
    stretch: bool = param(
        False,
        help="stretch the canvas onto the grid (the paper's)",
        label="Stretch to the grid",
    )

    def __post_init__(self) -> None:
        check_all(self)

    @property
    def mapping(self) -> CanvasMapping:
        """The canvas-to-grid mapping of these parameters (their grid and canvas fields)."""
        return CanvasMapping(
            self.canvas_width_px, self.canvas_height_px, self.columns, self.rows, self.stretch
        )
