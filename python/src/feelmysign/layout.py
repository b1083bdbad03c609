"""The sleeve's geometry, safety caps and wiring, from one validated TOML file.

A layout file (see deploy/layouts/paper-sleeve.toml and docs/protocol.md)::

    name = "paper-sleeve"
    rows = 3                      # actuators along y (row index 0..rows-1)
    columns = 4                   # actuators along x (column index 0..columns-1)
    spacing_cm = 3.0              # centre-to-centre distance between neighbours
    actuator_type = "ERM"         # ERM or LRA
    min_burst_ms = 20             # optional; default by actuator_type (ERM 20, LRA 10)
    rated_voltage_v = 3.0         # optional; the motor's rated voltage (ERM: average, LRA: RMS)
    overdrive_voltage_v = 3.6     # optional; the most it may get, peak (its datasheet's maximum)
    # resonant_frequency_hz = 205 # LRA only, optional; its resonance from its datasheet
    default_intensity = 0.8       # for strokes that do not say, 0..1

    [safety]
    max_intensity = 1.0           # no actuator is driven above this, 0..1
    max_stroke_duration_ms = 10000
    max_on_time_ms = 15000        # longest `buzz`
    duty_cycle_window_ms = 60000  # a motor's heat: its drive over the last minute...
    max_duty_cycle = 0.5          # ...at most this fraction of it at full drive

    [i2c]
    bus = 1                       # /dev/i2c-1
    multiplexers = [0x70, 0x71]   # TCA9548A addresses
    # Optional: every DRV2605L's EN pin on one GPIO line, pulled down (docs/sleeve-hardware.md)
    enable = { chip = "gpiochip0", line = 17 }
    wiring = [
      { row = 0, column = 0, multiplexer = 0x70, channel = 0 },
      ...
    ]

    [controls]
    # Optional: the wearer's buttons, each between a GPIO line and ground, the line pulled
    # up (docs/sleeve-hardware.md, "The wearer's buttons")
    pause_button = { chip = "gpiochip0", line = 27 }      # press: pause/resume; hold 1 s: stop
    turn_down_button = { chip = "gpiochip0", line = 22 }  # each press: intensity down a step

The whole file is checked before anything drives a motor, and every problem is
reported at once (a ``LayoutError`` with ``problems``), each naming the key, the
bad value and the allowed range.
"""

from __future__ import annotations

import ast
import difflib
import json
import math
import re
import sys
from dataclasses import dataclass, fields
from os import PathLike
from typing import TYPE_CHECKING, Any, Literal

from feelmysign.errors import LayoutError
from feelmysign.input_files import MAX_LAYOUT_BYTES, read_text

if TYPE_CHECKING:
    from collections.abc import Callable

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ActuatorType = Literal["ERM", "LRA"]
ACTUATOR_TYPES: tuple[ActuatorType, ...] = ("ERM", "LRA")

# The shortest burst the planner may give an actuator, by type, unless the layout
# sets min_burst_ms. A burst is felt only once the actuator is up to speed: an
# eccentric rotating mass spins up in about 20 ms even with the DRV2605L's
# overdrive; a linear resonant actuator, driven at its resonance (about 175 to
# 235 Hz) with closed-loop overdrive, is felt after about two periods, 10 ms.
# Measure your motors and set min_burst_ms when they differ.
MIN_BURST_MS: dict[ActuatorType, float] = {"ERM": 20.0, "LRA": 10.0}
MAX_MIN_BURST_MS = 1000.0  # a burst floor of a second already forbids any drawing

# A motor's datasheet values, as the DRV2605L datasheet (SLOS854, 8.5.2) defines them: the
# rated voltage (ERM: average; LRA: RMS at resonance) is the full-scale drive, the overdrive
# voltage (peak) bounds the chip's automatic overdrive. Defaults: a common 10 mm coin ERM
# (3.0 V rated, 3.6 V maximum) and a coin LRA of the 170-235 Hz kind (2.0 V rms rated, its
# sine's 2.8 V peak as the clamp, 205 Hz: the middle, as the chip tracks the resonance
# itself in closed loop and the frequency is only its first guess).
DEFAULT_RATED_VOLTAGE_V: dict[ActuatorType, float] = {"ERM": 3.0, "LRA": 2.0}
DEFAULT_OVERDRIVE_VOLTAGE_V: dict[ActuatorType, float] = {"ERM": 3.6, "LRA": 2.8}
DEFAULT_RESONANT_FREQUENCY_HZ = 205.0
# RATED_VOLTAGE and OD_CLAMP are 8-bit: up to 5.4 V (ERM closed loop) and 5.5 V (ERM open
# loop, closed-loop clamp 5.6 V); the chip's supply is at most 5.2 V anyway.
VOLTAGE_RANGE_V = (0.5, 5.0)
MAX_OVERDRIVE_VOLTAGE_V = 5.5
# DRIVE_TIME (5 bits, 0.5 to 3.6 ms half periods) covers 139 Hz and up; the closed-loop
# rated-voltage equation needs (4 x 300 us + 300 us) x f below 1, under 667 Hz.
RESONANT_FREQUENCY_RANGE_HZ = (140.0, 400.0)

MAX_GRID_SIDE = 64  # rows or columns; 8 multiplexers x 8 channels drive 64 actuators at most
MIN_ACTUATORS = 2  # a stroke moves between actuators; one cannot draw anything
MAX_SPACING_CM = 20.0  # wider than any forearm or back grid; catches millimetres typed as cm
MAX_DURATION_MS = 600_000.0  # 10 minutes; catches microseconds typed as milliseconds
MUX_ADDRESSES = range(0x70, 0x78)  # TCA9548A: pins A0..A2 select 0x70..0x77
MUX_CHANNELS = 8  # TCA9548A channels 0..7; one DRV2605L (fixed address 0x5A) per channel
MAX_I2C_BUS = 255  # the N of /dev/i2c-N
MAX_GPIO_LINE = 1023  # a line offset on its chip; a Raspberry Pi's gpiochip0 has 54 to 58
GPIO_CHIP = re.compile(r"(?:/dev/)?gpiochip[0-9]{1,3}")  # as gpiodetect lists them
MAX_NAME_CHARS = 64
NAME_FORBIDDEN = "/+#"  # the name may appear in MQTT topics, where these are special


@dataclass(frozen=True)
class Wire:
    """Where one actuator's DRV2605L hangs: a TCA9548A multiplexer address and channel."""

    row: int
    column: int
    multiplexer: int
    channel: int


@dataclass(frozen=True)
class GpioLine:
    """One GPIO line: its chip and its offset on it."""

    chip: str  # "gpiochip0", as gpiodetect names it
    line: int  # the line's offset on that chip (on a Raspberry Pi, the BCM GPIO number)

    @property
    def path(self) -> str:
        """The chip's character device, e.g. ``/dev/gpiochip0``."""
        return self.chip if self.chip.startswith("/dev/") else f"/dev/{self.chip}"

    @property
    def name(self) -> str:
        return f"{self.chip} line {self.line}"


@dataclass(frozen=True)
class EnableLine(GpioLine):
    """The GPIO line every DRV2605L's EN pin hangs on: high lets the chips drive their motors,
    low (the pull-down, whenever no process drives the line) shuts every one of them down."""


@dataclass(frozen=True)
class ButtonLine(GpioLine):
    """A wearer's button: between the line and ground, the line pulled up (reads low while
    pressed). ``role``: ``pause`` or ``turn_down`` (feelmysign.backends.button)."""

    role: str = "pause"

    @property
    def key(self) -> str:
        return f"controls.{self.role}_button"


@dataclass(frozen=True)
class Layout:
    """A sleeve: ``rows`` x ``columns`` actuators, ``spacing_cm`` apart.

    Grid units: x = column index 0..columns-1, y = row index 0..rows-1.
    ``wiring`` is empty for a sleeve without hardware (the simulator).
    """

    rows: int
    columns: int
    spacing_cm: float
    name: str = "sleeve"
    default_intensity: float = 1.0
    max_intensity: float = 1.0
    max_stroke_duration_ms: float = 10_000.0
    # The longest single buzz (feelmysign buzz); at least the longest stroke.
    max_on_time_ms: float = 15_000.0
    # What heats a motor is its drive over time, so the player caps each motor's energy
    # (intensity squared times time) within any window of duty_cycle_window_ms at
    # max_duty_cycle of the window at full drive. A small ERM's case warms over tens of
    # seconds, hence a minute; half of it at full drive leaves every drawing pace a person
    # keeps up (a motor used 8-20% of the time) far from the cap, and still bounds a stuck
    # stream to 30 s of full drive a minute.
    duty_cycle_window_ms: float = 60_000.0
    max_duty_cycle: float = 0.5
    actuator_type: ActuatorType = "ERM"
    # None: the actuator type's MIN_BURST_MS; read it through ``shortest_burst_ms``.
    min_burst_ms: float | None = None
    # None: the actuator type's default; read them through the properties below.
    rated_voltage_v: float | None = None
    overdrive_voltage_v: float | None = None
    resonant_frequency_hz: float | None = None  # LRA only
    i2c_bus: int = 1
    multiplexers: tuple[int, ...] = ()
    wiring: tuple[Wire, ...] = ()
    # None: no enable line, every EN pin tied high (only I2C switches a motor off).
    enable: EnableLine | None = None
    # The wearer's buttons ([controls]); None: not fitted.
    pause_button: ButtonLine | None = None
    turn_down_button: ButtonLine | None = None

    @property
    def buttons(self) -> tuple[ButtonLine, ...]:
        return tuple(b for b in (self.pause_button, self.turn_down_button) if b is not None)

    @property
    def shortest_burst_ms(self) -> float:
        """The shortest burst the planner may play: ``min_burst_ms``, else the type's default."""
        if self.min_burst_ms is not None:
            return self.min_burst_ms
        return MIN_BURST_MS[self.actuator_type]

    @property
    def rated_voltage(self) -> float:
        """The motor's rated voltage in V (ERM average, LRA RMS): set, or the type's default."""
        if self.rated_voltage_v is not None:
            return self.rated_voltage_v
        return DEFAULT_RATED_VOLTAGE_V[self.actuator_type]

    @property
    def overdrive_voltage(self) -> float:
        """The motor's overdrive (peak) voltage in V: set, or the type's default."""
        if self.overdrive_voltage_v is not None:
            return self.overdrive_voltage_v
        return DEFAULT_OVERDRIVE_VOLTAGE_V[self.actuator_type]

    @property
    def resonance_hz(self) -> float:
        """An LRA's resonant frequency in Hz: set, or the default."""
        if self.resonant_frequency_hz is not None:
            return self.resonant_frequency_hz
        return DEFAULT_RESONANT_FREQUENCY_HZ


_DEFAULTS = Layout(rows=1, columns=MIN_ACTUATORS, spacing_cm=1.0)
# The keys at the top of a layout file, before its [safety] and [i2c] tables.
TOP_KEYS = (
    "name",
    "rows",
    "columns",
    "spacing_cm",
    "actuator_type",
    "min_burst_ms",
    "rated_voltage_v",
    "overdrive_voltage_v",
    "resonant_frequency_hz",
    "default_intensity",
)
_SAFETY_KEYS = (
    "max_intensity",
    "max_stroke_duration_ms",
    "max_on_time_ms",
    "duty_cycle_window_ms",
    "max_duty_cycle",
)
MIN_DUTY_WINDOW_MS = 1000.0  # shorter is no longer about heat but about single strokes
_I2C_KEYS = ("bus", "multiplexers", "enable", "wiring")
_CONTROLS_KEYS = ("pause_button", "turn_down_button")
_ENABLE_KEYS = ("chip", "line")
_WIRE_KEYS = ("row", "column", "multiplexer", "channel")
_MEANINGS = {
    "rows": "the number of actuator rows",
    "columns": "the number of actuator columns",
    "spacing_cm": "the distance between neighbouring actuators in cm",
    "row": "the actuator's row",
    "column": "the actuator's column",
    "multiplexer": "the address of the actuator's multiplexer",
    "channel": "the multiplexer channel of the actuator's DRV2605L",
}
_MISSING: Any = object()  # a key that is not in the file (None is not a TOML value either)


def load_layout(path: str | PathLike[str]) -> Layout:
    """Read and validate a layout file; LayoutError names the path and every problem."""
    source = str(path)
    try:
        text = read_text(path, max_bytes=MAX_LAYOUT_BYTES)
    except FileNotFoundError:
        raise LayoutError(
            source,
            ["file not found; check the path, or see deploy/layouts/ for example layouts"],
        ) from None
    except UnicodeDecodeError as error:
        raise LayoutError(
            source, [f"not UTF-8 text (byte {error.start}); save the file as UTF-8"]
        ) from None
    except OSError as error:
        raise LayoutError(source, [f"cannot read the file: {error.strerror}"]) from None
    return parse_layout(text, source)


_DECLARED_TWICE = re.compile(
    r"Cannot declare \((?P<key>.*)\) twice (?P<where>\(at line \d+, column \d+\))"
)


def _toml_problem(text: str) -> str:
    """tomllib's message, said in TOML's words: a table declared twice names the table as the
    file spells it (not a Python tuple) and says how to write a list of tables."""
    found = _DECLARED_TWICE.fullmatch(text)
    if found is None:
        return text
    try:
        parts = ast.literal_eval(f"({found['key']})")
    except (ValueError, SyntaxError):
        return text
    if not isinstance(parts, tuple) or not all(isinstance(part, str) for part in parts):
        return text
    name = ".".join(parts)
    return (
        f"[{name}] is declared twice {found['where']}; a table may appear once. For a list "
        f"of entries (e.g. several practice trials), write [[{name}]] (two brackets) before "
        "each one, one per entry"
    )


def loads_toml(
    text: str,
    source: str,
    error: Callable[[str, list[str]], Exception],
    *,
    nesting: str,
) -> dict[str, Any]:
    """The TOML document in ``text``, or ``error(source, [why])`` raised: not TOML, or nested
    too deeply for Python's stack (``nesting`` says how deep the file's kind goes)."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as problem:
        raise error(source, [f"not valid TOML: {_toml_problem(str(problem))}"]) from None
    except RecursionError:
        raise error(source, [f"nested too deeply to read; {nesting}"]) from None


def parse_layout(text: str, source: str = "<string>") -> Layout:
    """Validate a layout given as TOML text; ``source`` names it in error messages."""
    nesting = "a layout nests arrays and tables 2 levels deep"
    return _build(loads_toml(text, source, LayoutError, nesting=nesting), source)


def grid_layout(
    rows: int,
    columns: int,
    spacing_cm: float,
    *,
    name: str = "grid",
    default_intensity: float = _DEFAULTS.default_intensity,
    max_intensity: float = _DEFAULTS.max_intensity,
    max_stroke_duration_ms: float = _DEFAULTS.max_stroke_duration_ms,
    max_on_time_ms: float = _DEFAULTS.max_on_time_ms,
    duty_cycle_window_ms: float = _DEFAULTS.duty_cycle_window_ms,
    max_duty_cycle: float = _DEFAULTS.max_duty_cycle,
    actuator_type: ActuatorType = _DEFAULTS.actuator_type,
    min_burst_ms: float | None = None,
) -> Layout:
    """A validated layout without wiring: for the simulator, the planner and the CLI."""
    layout = Layout(
        rows=rows,
        columns=columns,
        spacing_cm=spacing_cm,
        name=name,
        default_intensity=default_intensity,
        max_intensity=max_intensity,
        max_stroke_duration_ms=max_stroke_duration_ms,
        max_on_time_ms=max_on_time_ms,
        duty_cycle_window_ms=duty_cycle_window_ms,
        max_duty_cycle=max_duty_cycle,
        actuator_type=actuator_type,
        min_burst_ms=min_burst_ms,
    )
    return check_layout(layout, f"grid {rows} x {columns}")


def check_layout(layout: Layout, source: str = "<layout>") -> Layout:
    """Validate a layout built in code by the rules of a layout file; return it unchanged."""
    _build(_to_data(layout), source)
    return layout


def default_layout() -> Layout:
    """The paper's sleeve: 3 rows x 4 columns, 3.0 cm apart (geometry and caps, no wiring)."""
    return PAPER_SLEEVE


# --- building -----------------------------------------------------------------------------


def _build(data: dict[str, Any], source: str) -> Layout:
    problems = _Problems()
    problems.unknown_keys("", data, (*TOP_KEYS, "safety", "i2c", "controls"))
    geometry = _read_geometry(problems, data)
    caps = _read_caps(problems, data)
    hardware = _read_i2c(problems, data.get("i2c", {}), geometry["rows"], geometry["columns"])
    buttons = _read_controls(problems, data.get("controls", {}), hardware["enable"])
    _check_not_on_i2c_pins(problems, hardware, buttons)
    if problems.items:
        raise LayoutError(source, problems.items)
    return Layout(**geometry, **caps, **hardware, **buttons)


# A Raspberry Pi's I2C bus 1 (the one its header gives the chips) runs on GPIO2 (SDA) and
# GPIO3 (SCL) of its first GPIO chip.
PI_I2C1_LINES = {2: "SDA", 3: "SCL"}


def _check_not_on_i2c_pins(
    problems: _Problems, hardware: dict[str, Any], buttons: dict[str, Any]
) -> None:
    """No enable line or button on the pins of the I2C bus the chips use (bus 1 on a Pi)."""
    if hardware["i2c_bus"] != 1:
        return
    lines = {"i2c.enable": hardware["enable"]}
    lines |= {f"controls.{key}": line for key, line in buttons.items()}
    for key, found in lines.items():
        if found is None or found.chip.removeprefix("/dev/") != "gpiochip0":
            continue
        pin = PI_I2C1_LINES.get(found.line)
        if pin is not None:
            problems.add(
                f"{key}.line",
                f"{found.line} is GPIO{found.line}, the Raspberry Pi's I2C1 {pin}, which "
                "i2c.bus = 1 uses to reach the chips; wire it to a free line (GPIO17, 27 or "
                "22, see docs/sleeve-hardware.md)",
            )


def _read_geometry(problems: _Problems, data: dict[str, Any]) -> dict[str, Any]:
    rows = problems.integer("rows", data.get("rows", _MISSING), 1, MAX_GRID_SIDE)
    columns = problems.integer("columns", data.get("columns", _MISSING), 1, MAX_GRID_SIDE)
    if rows and columns and rows * columns < MIN_ACTUATORS:
        problems.add(
            "rows x columns",
            f"a sleeve needs at least {MIN_ACTUATORS} actuators for a stroke to move; "
            f"got {rows} x {columns}",
        )
    return {
        "name": problems.name("name", data.get("name", _DEFAULTS.name)),
        "rows": rows,
        "columns": columns,
        "spacing_cm": problems.number(
            "spacing_cm", data.get("spacing_cm", _MISSING), MAX_SPACING_CM
        ),
        "actuator_type": problems.actuator_type(data.get("actuator_type", _DEFAULTS.actuator_type)),
        "min_burst_ms": _read_min_burst(problems, data.get("min_burst_ms")),
        **_read_motor(problems, data),
    }


def _read_min_burst(problems: _Problems, value: Any) -> float | None:
    """The optional floor on burst length; absent means the actuator type's default."""
    if value is None:
        return None
    return problems.number("min_burst_ms", value, MAX_MIN_BURST_MS)


def _read_motor(problems: _Problems, data: dict[str, Any]) -> dict[str, Any]:
    """The motor's datasheet values (all optional); the overdrive at least the rated voltage."""
    kind = data.get("actuator_type", _DEFAULTS.actuator_type)
    low, high = VOLTAGE_RANGE_V
    read: dict[str, Any] = {}
    for key, top, unit in (
        ("rated_voltage_v", high, "V (ERM: average; LRA: RMS)"),
        ("overdrive_voltage_v", MAX_OVERDRIVE_VOLTAGE_V, "V peak"),
    ):
        value = data.get(key)
        read[key] = None if value is None else problems.within(key, value, low, top, unit)
    rated, overdrive = read["rated_voltage_v"], read["overdrive_voltage_v"]
    if kind in ACTUATOR_TYPES:
        rated = DEFAULT_RATED_VOLTAGE_V[kind] if rated is None else rated
        overdrive = DEFAULT_OVERDRIVE_VOLTAGE_V[kind] if overdrive is None else overdrive
    if rated is not None and overdrive is not None and overdrive < rated:
        problems.add(
            "overdrive_voltage_v",
            f"{overdrive:g} V is below the rated voltage {rated:g} V: the overdrive clamp must "
            "be at least the rated voltage; take both from the motor's datasheet (its maximum "
            "or overdrive voltage, and its rated voltage)",
        )
    frequency = data.get("resonant_frequency_hz")
    read["resonant_frequency_hz"] = None
    if frequency is not None:
        # A kind that is neither (a typo, said on its own) is not taken for an ERM here.
        if kind == "ERM":
            problems.add(
                "resonant_frequency_hz",
                'is for an LRA only (actuator_type = "LRA"); an ERM has no resonance to '
                "set: remove it, or set actuator_type",
            )
        else:
            low_hz, high_hz = RESONANT_FREQUENCY_RANGE_HZ
            read["resonant_frequency_hz"] = problems.within(
                "resonant_frequency_hz", frequency, low_hz, high_hz, "Hz (the LRA's resonance)"
            )
    return read


def _read_caps(problems: _Problems, data: dict[str, Any]) -> dict[str, Any]:
    """The default intensity and the [safety] caps; the default may not exceed the cap."""
    safety = problems.table("safety", data.get("safety", {}), _SAFETY_KEYS)
    caps = {
        "default_intensity": problems.number(
            "default_intensity", data.get("default_intensity", _DEFAULTS.default_intensity), 1.0
        ),
        "max_intensity": problems.number(
            "safety.max_intensity", safety.get("max_intensity", _DEFAULTS.max_intensity), 1.0
        ),
    }
    for key in ("max_stroke_duration_ms", "max_on_time_ms", "duty_cycle_window_ms"):
        value = safety.get(key, getattr(_DEFAULTS, key))
        caps[key] = problems.number(f"safety.{key}", value, MAX_DURATION_MS)
    caps["max_duty_cycle"] = problems.number(
        "safety.max_duty_cycle", safety.get("max_duty_cycle", _DEFAULTS.max_duty_cycle), 1.0
    )
    longest, on_time = caps["max_stroke_duration_ms"], caps["max_on_time_ms"]
    if longest is not None and on_time is not None and on_time < longest:
        problems.add(
            "safety.max_on_time_ms",
            f"{on_time:g} is below safety.max_stroke_duration_ms {longest:g}: a slow stroke the "
            "sleeve accepts could not be buzzed as long; raise it or lower the longest stroke",
        )
    _check_duty_cycle(problems, caps)
    default, cap = caps["default_intensity"], caps["max_intensity"]
    if default is not None and cap is not None and default > cap:
        problems.add(
            "default_intensity",
            f"{default:g} is above safety.max_intensity {cap:g}; lower it or raise the cap",
        )
    return caps


def _check_duty_cycle(problems: _Problems, caps: dict[str, Any]) -> None:
    window, duty = caps["duty_cycle_window_ms"], caps["max_duty_cycle"]
    if window is not None and window < MIN_DUTY_WINDOW_MS:
        problems.add(
            "safety.duty_cycle_window_ms",
            f"must be at least {MIN_DUTY_WINDOW_MS:g} (a motor heats over seconds); got {window:g}",
        )
        return
    longest = caps["max_stroke_duration_ms"]
    if None in (window, duty, longest) or window * duty >= longest:
        return
    problems.add(
        "safety.max_duty_cycle",
        f"{duty:g} of safety.duty_cycle_window_ms {window:g} is {window * duty:g} ms of full "
        f"drive, below safety.max_stroke_duration_ms {longest:g}: a slow stroke the sleeve "
        "accepts could never play on a rested motor; raise either or lower the longest stroke",
    )


def _read_i2c(
    problems: _Problems, value: Any, rows: int | None, columns: int | None
) -> dict[str, Any]:
    i2c = problems.table("i2c", value, _I2C_KEYS)
    bus = problems.integer("i2c.bus", i2c.get("bus", _DEFAULTS.i2c_bus), 0, MAX_I2C_BUS)
    said = len(problems.items)
    multiplexers = _read_multiplexers(problems, i2c.get("multiplexers", []))
    # A bad entry in the list is said there: the wires naming the address it was meant to be
    # are not said again as "not declared".
    declared = None if len(problems.items) > said else multiplexers
    wiring = _read_wiring(problems, i2c.get("wiring", []), rows, columns, declared)
    enable = None
    if "enable" in i2c:
        enable = _read_enable(problems, i2c["enable"], bool(i2c.get("wiring")))
    return {"i2c_bus": bus, "multiplexers": multiplexers, "wiring": wiring, "enable": enable}


def _read_enable(problems: _Problems, value: Any, wired: bool) -> EnableLine | None:
    """``enable = { chip = "gpiochip0", line = 17 }``: where the chips' EN pins are wired."""
    found = _read_gpio_line(problems, "i2c.enable", value, 17)
    if not wired:
        problems.add(
            "i2c.enable",
            "an enable line needs i2c.wiring: it switches the chips the wiring lists; add the "
            "wiring or remove enable",
        )
    return None if found is None else EnableLine(*found)


def _read_controls(problems: _Problems, value: Any, enable: EnableLine | None) -> dict[str, Any]:
    """The [controls] table: the wearer's buttons, each on a line of its own."""
    table = problems.table("controls", value, _CONTROLS_KEYS)
    buttons: dict[str, Any] = {}
    taken = {} if enable is None else {(enable.chip, enable.line): "i2c.enable"}
    for key, example_line in (("pause_button", 27), ("turn_down_button", 22)):
        found = None
        if key in table:
            found = _read_gpio_line(problems, f"controls.{key}", table[key], example_line)
        if found is not None and found in taken:
            problems.add(
                f"controls.{key}",
                f"{found[0]} line {found[1]} is already {taken[found]}'s; a button needs a line "
                "of its own (see docs/sleeve-hardware.md)",
            )
            found = None
        if found is not None:
            taken[found] = f"controls.{key}"
        role = key.removesuffix("_button")
        buttons[key] = None if found is None else ButtonLine(*found, role=role)
    return buttons


def _read_gpio_line(
    problems: _Problems, key: str, value: Any, example_line: int
) -> tuple[str, int] | None:
    """``{ chip = "gpiochip0", line = N }``: a GPIO line, as gpiodetect and gpioinfo name it."""
    name = key.rsplit(".", 1)[-1]
    example = f'{name} = {{ chip = "gpiochip0", line = {example_line} }}'
    if not isinstance(value, dict):
        problems.add(key, f"must be a table such as {example}; got {_show(value)}")
        return None
    table = problems.table(key, value, _ENABLE_KEYS)
    chip = table.get("chip", _MISSING)
    if chip is _MISSING:
        problems.add(
            f"{key}.chip",
            'missing; the GPIO chip of the line (a name such as "gpiochip0", as gpiodetect '
            "lists them) is required",
        )
        chip = None
    elif not isinstance(chip, str) or not GPIO_CHIP.fullmatch(chip):
        problems.add(
            f"{key}.chip",
            'must be a GPIO chip name such as "gpiochip0" (or its path "/dev/gpiochip0"), as '
            f"gpiodetect lists them; got {_show(chip)}",
        )
        chip = None
    raw_line = table.get("line", _MISSING)
    line = None
    if isinstance(raw_line, str):  # "GPIO17" is a name gpiod also takes, but not the offset
        problems.add(
            f"{key}.line",
            f"must be a whole number from 0 to {MAX_GPIO_LINE}, the line's offset (on a "
            f"Raspberry Pi the BCM GPIO number: 17 for GPIO17, physical pin 11); got "
            f"{_show(raw_line)}",
        )
    else:
        line = problems.integer(f"{key}.line", raw_line, 0, MAX_GPIO_LINE)
    if chip is None or line is None:
        return None
    return chip, line


def _read_multiplexers(problems: _Problems, value: Any) -> tuple[int, ...]:
    if not isinstance(value, list):
        problems.add(
            "i2c.multiplexers",
            f"must be an array of addresses such as [0x70, 0x71]; got {_show(value)}",
        )
        return ()
    addresses: list[int] = []
    for index, item in enumerate(value):
        address = problems.address(f"i2c.multiplexers[{index}]", item)
        if address is None:
            continue
        if address in addresses:
            problems.add(
                f"i2c.multiplexers[{index}]",
                f"{_hex(address)} is listed twice; list each multiplexer once",
            )
            continue
        addresses.append(address)
    return tuple(addresses)


def _read_wiring(
    problems: _Problems,
    value: Any,
    rows: int | None,
    columns: int | None,
    declared: tuple[int, ...] | None,
) -> tuple[Wire, ...]:
    """The wires of ``i2c.wiring``; ``declared`` None: the multiplexer list had a bad entry,
    and no wire's multiplexer is checked against it."""
    if not isinstance(value, list):
        problems.add(
            "i2c.wiring",
            f"must be an array of tables {{row, column, multiplexer, channel}}; got {_show(value)}",
        )
        return ()
    by_channel: dict[tuple[int, int], str] = {}
    by_actuator: dict[tuple[int, int], str] = {}
    wires: list[Wire] = []
    # The actuators entries name, even entries with another field wrong (said on their own:
    # not "not wired" again), and the entries naming each multiplexer not declared.
    named: set[tuple[int, int]] = set()
    undeclared: dict[int, list[int]] = {}
    for index, entry in enumerate(value):
        key = f"i2c.wiring[{index}]"
        wire = _read_wire(problems, key, entry, rows, columns, named)
        if wire is not None and declared is not None and wire.multiplexer not in declared:
            undeclared.setdefault(wire.multiplexer, []).append(index)
        if wire is None:
            continue
        channel, actuator = (wire.multiplexer, wire.channel), (wire.row, wire.column)
        if channel in by_channel:
            problems.add(
                key,
                f"multiplexer {_hex(wire.multiplexer)} channel {wire.channel} is already used by "
                f"{by_channel[channel]}; each channel drives one actuator",
            )
        elif actuator in by_actuator:
            problems.add(
                key,
                f"actuator (row {wire.row}, column {wire.column}) is already wired in "
                f"{by_actuator[actuator]}; wire each actuator once",
            )
        else:
            by_channel[channel] = f"{key} (row {wire.row}, column {wire.column})"
            by_actuator[actuator] = key
            wires.append(wire)
    for multiplexer, indices in undeclared.items():
        listed = ", ".join(_hex(a) for a in declared or ()) or "none"
        entries = "i2c.wiring[" + "], [".join(map(str, indices)) + "]"
        problems.add(
            f"{entries}.multiplexer",
            f"{_hex(multiplexer)} is not declared in i2c.multiplexers (declared: {listed}); "
            "add it there or fix the address",
        )
    if value and rows and columns:
        _check_all_wired(problems, rows, columns, set(by_actuator) | named)
    return tuple(sorted(wires, key=lambda w: (w.row, w.column)))


def _read_wire(
    problems: _Problems,
    key: str,
    entry: Any,
    rows: int | None,
    columns: int | None,
    named: set[tuple[int, int]],
) -> Wire | None:
    """The entry's wire, None when a field is bad; the actuator it names goes into ``named``
    when its row and column are good."""
    table = problems.table(key, entry, _WIRE_KEYS)
    if not table:
        return None
    # Without a valid grid size only the type and the lower bound can be checked.
    row = problems.integer(f"{key}.row", table.get("row", _MISSING), 0, rows - 1 if rows else None)
    column = problems.integer(
        f"{key}.column", table.get("column", _MISSING), 0, columns - 1 if columns else None
    )
    multiplexer = problems.address(f"{key}.multiplexer", table.get("multiplexer", _MISSING))
    channel = problems.integer(
        f"{key}.channel", table.get("channel", _MISSING), 0, MUX_CHANNELS - 1
    )
    if row is not None and column is not None:
        named.add((row, column))
    if row is None or column is None or multiplexer is None or channel is None:
        return None
    return Wire(row=row, column=column, multiplexer=multiplexer, channel=channel)


def _check_all_wired(
    problems: _Problems, rows: int, columns: int, wired: set[tuple[int, int]]
) -> None:
    missing = [(r, c) for r in range(rows) for c in range(columns) if (r, c) not in wired]
    if not missing:
        return
    shown = ", ".join(f"(row {r}, column {c})" for r, c in missing[:8])
    more = f" and {len(missing) - 8} more" if len(missing) > 8 else ""
    problems.add(
        "i2c.wiring",
        f"{len(missing)} of {rows * columns} actuators are not wired: {shown}{more}; "
        "add an entry for each, or remove i2c.wiring to use the simulator only",
    )


def _to_data(layout: Layout) -> dict[str, Any]:
    """A layout as the dictionary its TOML file would give, so one validator checks both."""
    wires = [{f.name: getattr(w, f.name) for f in fields(w)} for w in layout.wiring]
    # None is no TOML value: an unset optional key is simply absent from the file.
    top = {key: getattr(layout, key) for key in TOP_KEYS}
    return {
        **{key: value for key, value in top.items() if value is not None},
        "safety": {key: getattr(layout, key) for key in _SAFETY_KEYS},
        "i2c": {
            "bus": layout.i2c_bus,
            "multiplexers": list(layout.multiplexers),
            "wiring": wires,
            **(
                {}
                if layout.enable is None
                else {"enable": {"chip": layout.enable.chip, "line": layout.enable.line}}
            ),
        },
        "controls": {
            f"{button.role}_button": {"chip": button.chip, "line": button.line}
            for button in layout.buttons
        },
    }


# --- checking one value -------------------------------------------------------------------


class _Problems:
    """Collects every problem as 'key: what is wrong; got value'. Readers return None when bad."""

    def __init__(self) -> None:
        self.items: list[str] = []

    def add(self, key: str, text: str) -> None:
        self.items.append(f"{key}: {text}")

    def missing(self, key: str, value: Any, allowed: str) -> bool:
        if value is _MISSING:
            meaning = _MEANINGS.get(key.rsplit(".", 1)[-1], "a value")
            self.add(key, f"missing; {meaning} ({allowed}) is required")
            return True
        return False

    def integer(self, key: str, value: Any, low: int, high: int | None) -> int | None:
        allowed = (
            f"a whole number from {low} to {high}"
            if high is not None
            else f"a whole number from {low}"
        )
        if self.missing(key, value, allowed):
            return None
        if not isinstance(value, int) or isinstance(value, bool):
            self.add(key, f"must be {allowed}; got {_show(value)}")
            return None
        if value < low or (high is not None and value > high):
            self.add(key, f"must be {allowed}; got {value}")
            return None
        return value

    def number(self, key: str, value: Any, high: float) -> float | None:
        """A finite number above 0 and at most ``high``: sizes, caps and durations."""
        allowed = f"a number above 0 and at most {high:g}"
        if self.missing(key, value, allowed):
            return None
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            self.add(key, f"must be {allowed}; got {_show(value)}")
            return None
        if not (math.isfinite(value) and 0 < value <= high):
            self.add(key, f"must be {allowed}; got {value}")
            return None
        return float(value)

    def within(self, key: str, value: Any, low: float, high: float, unit: str) -> float | None:
        """A number from ``low`` to ``high`` in ``unit``: a motor's datasheet value."""
        allowed = f"a number from {low:g} to {high:g} {unit}, from the motor's datasheet"
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            self.add(key, f"must be {allowed}; got {_show(value)}")
            return None
        if not (math.isfinite(value) and low <= value <= high):
            self.add(key, f"must be {allowed}; got {value}")
            return None
        return float(value)

    def address(self, key: str, value: Any) -> int | None:
        allowed = f"a TCA9548A address from {_hex(MUX_ADDRESSES[0])} to {_hex(MUX_ADDRESSES[-1])}"
        if self.missing(key, value, allowed):
            return None
        if not isinstance(value, int) or isinstance(value, bool) or value not in MUX_ADDRESSES:
            shown = (
                f"{_hex(value)} ({value})"
                if isinstance(value, int) and not isinstance(value, bool)
                else _show(value)
            )
            self.add(key, f"must be {allowed}; got {shown}")
            return None
        return value

    def name(self, key: str, value: Any) -> str:
        fits = isinstance(value, str) and 0 < len(value) <= MAX_NAME_CHARS
        if fits and not any(c in NAME_FORBIDDEN or not c.isprintable() for c in value):
            return str(value)
        self.add(
            key,
            f"must be 1 to {MAX_NAME_CHARS} printable characters without "
            f"{' '.join(NAME_FORBIDDEN)} (it may appear in MQTT topics); got {_show(value)}",
        )
        return _DEFAULTS.name

    def actuator_type(self, value: Any) -> ActuatorType:
        for choice in ACTUATOR_TYPES:
            if value == choice:
                return choice
        hint = (
            f'; write it in capitals: "{value.upper()}"'
            if isinstance(value, str) and value.upper() in ACTUATOR_TYPES
            else ""
        )
        self.add("actuator_type", f'must be "ERM" or "LRA"; got {_show(value)}{hint}')
        return _DEFAULTS.actuator_type

    def table(self, key: str, value: Any, allowed: tuple[str, ...]) -> dict[str, Any]:
        if not isinstance(value, dict):
            self.add(key, f"must be a table of {', '.join(allowed)}; got {_show(value)}")
            return {}
        self.unknown_keys(f"{key}.", value, allowed)
        return value

    def unknown_keys(self, prefix: str, table: dict[str, Any], allowed: tuple[str, ...]) -> None:
        for key in table:
            if key in allowed:
                continue
            self.add(
                f"{prefix}{key}",
                f"unknown key{_suggestion(key, allowed)}; allowed here: {', '.join(allowed)}",
            )


def _suggestion(key: str, allowed: tuple[str, ...]) -> str:
    """A hint for a typo ('colums') or a key put in the wrong table ('max_intensity' at the top)."""
    tables = (("[safety]", _SAFETY_KEYS), ("[i2c]", _I2C_KEYS), ("[controls]", _CONTROLS_KEYS))
    if key == "controls" and key not in allowed:
        return " here (it is a table of its own, [controls], at the top of the file)"
    for table, keys in tables:
        if key in keys and key not in allowed:
            return f" here (it belongs in the {table} table)"
    close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.6)
    return f' (did you mean "{close[0]}"?)' if close else ""


def _hex(address: int) -> str:
    return f"0x{address:02x}"


def _show(value: Any) -> str:
    """A TOML value as the person wrote it, with its kind when the kind is the problem."""
    if isinstance(value, bool):
        return f"{str(value).lower()} (a boolean)"
    if isinstance(value, str):
        shown = json.dumps(value if len(value) <= 40 else value[:40] + "...")
        return f"{shown} (a string)"
    if isinstance(value, float):
        return f"{value} (a decimal number)"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return f"{value} ({type(value).__name__})"


PAPER_SLEEVE = grid_layout(3, 4, 3.0, name="paper-sleeve", default_intensity=0.8)
"""The sleeve of "Can You Feel My Sign?" (appendix A.1: ``TactileBrush(3, 4, 3.0)``)."""
