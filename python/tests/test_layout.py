"""Sleeve layouts: the example files, every kind of problem, and properties of wirings."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from feelmysign.cli import main
from feelmysign.errors import LayoutError
from feelmysign.layout import (
    MIN_BURST_MS,
    MUX_ADDRESSES,
    MUX_CHANNELS,
    PAPER_SLEEVE,
    TOP_KEYS,
    EnableLine,
    Layout,
    Wire,
    check_layout,
    default_layout,
    grid_layout,
    load_layout,
    parse_layout,
)

LAYOUTS = Path(__file__).resolve().parents[2] / "deploy" / "layouts"
GRID = "rows = 3\ncolumns = 4\nspacing_cm = 3.0\n"


def problems_of(text: str) -> list[str]:
    with pytest.raises(LayoutError) as caught:
        parse_layout(text, "test.toml")
    assert caught.value.source == "test.toml"
    return caught.value.problems


def wiring_toml(wires: list[tuple[int, int, int, int]], multiplexers: str = "[0x70, 0x71]") -> str:
    entries = ",\n".join(
        f"  {{ row = {r}, column = {c}, multiplexer = {m}, channel = {ch} }}"
        for r, c, m, ch in wires
    )
    return f"{GRID}[i2c]\nmultiplexers = {multiplexers}\nwiring = [\n{entries}\n]\n"


def paper_wires() -> list[tuple[int, int, int, int]]:
    return [(r, c, 0x70 + (4 * r + c) // 8, (4 * r + c) % 8) for r in range(3) for c in range(4)]


# --- the example files --------------------------------------------------------------------


def test_paper_sleeve_file_matches_the_paper() -> None:
    layout = load_layout(LAYOUTS / "paper-sleeve.toml")
    # Same geometry and caps as the built-in paper sleeve; the file adds the wiring.
    assert Layout(**{**layout.__dict__, "multiplexers": (), "wiring": ()}) == PAPER_SLEEVE
    assert (layout.rows, layout.columns, layout.spacing_cm) == (3, 4, 3.0)
    assert layout.actuator_type == "ERM" and layout.multiplexers == (0x70, 0x71)
    assert {(w.row, w.column) for w in layout.wiring} == set(itertools.product(range(3), range(4)))
    assert {w.multiplexer for w in layout.wiring if w.row < 2} == {0x70}
    assert {w.multiplexer for w in layout.wiring if w.row == 2} == {0x71}


@pytest.mark.parametrize("path", sorted(LAYOUTS.glob("*.toml")), ids=lambda p: p.name)
def test_every_example_layout_is_valid_and_fully_wired(path: Path) -> None:
    layout = load_layout(path)
    assert len(layout.wiring) == layout.rows * layout.columns
    assert check_layout(layout) is layout


def test_default_layout_is_the_papers_sleeve_without_hardware() -> None:
    layout = default_layout()
    assert layout is PAPER_SLEEVE
    assert (layout.rows, layout.columns, layout.spacing_cm, layout.wiring) == (3, 4, 3.0, ())


def test_only_the_grid_is_required() -> None:
    layout = parse_layout(GRID)
    assert layout == Layout(rows=3, columns=4, spacing_cm=3.0)


def test_addresses_may_be_written_in_decimal_too() -> None:
    text = wiring_toml([(r, c, 112, 4 * r + c) for r, c in [(0, 0), (0, 1)]], "[112]")
    layout = parse_layout(
        text.replace("rows = 3", "rows = 1").replace("columns = 4", "columns = 2")
    )
    assert layout.wiring == (Wire(0, 0, 0x70, 0), Wire(0, 1, 0x70, 1))


def test_the_shortest_burst_follows_the_actuator_type_unless_set() -> None:
    assert parse_layout(GRID).shortest_burst_ms == MIN_BURST_MS["ERM"]
    lra = parse_layout(GRID + 'actuator_type = "LRA"\n')
    assert lra.min_burst_ms is None and lra.shortest_burst_ms == MIN_BURST_MS["LRA"]
    assert MIN_BURST_MS["LRA"] < MIN_BURST_MS["ERM"]  # an LRA starts faster
    own = parse_layout(GRID + 'actuator_type = "LRA"\nmin_burst_ms = 15\n')
    assert own.min_burst_ms == own.shortest_burst_ms == 15.0
    assert check_layout(grid_layout(3, 4, 3.0, min_burst_ms=12.5)).shortest_burst_ms == 12.5


# --- problems -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (GRID + "colums = 4\n", 'colums: unknown key (did you mean "columns"?)'),
        (
            GRID + "max_intensity = 1\n",
            "max_intensity: unknown key here (it belongs in the [safety]",
        ),
        (
            GRID + "[safety]\nmax_intensty = 1\n",
            'safety.max_intensty: unknown key (did you mean "max_intensity"?)',
        ),
        (
            "columns = 4\nspacing_cm = 3\n",
            "rows: missing; the number of actuator rows (a whole number from 1 to 64)",
        ),
        (
            "rows = 3.0\ncolumns = 4\nspacing_cm = 3\n",
            "rows: must be a whole number from 1 to 64; got 3.0 (a decimal number)",
        ),
        (
            "rows = 65\ncolumns = 4\nspacing_cm = 3\n",
            "rows: must be a whole number from 1 to 64; got 65",
        ),
        (
            'rows = "3"\ncolumns = 4\nspacing_cm = 3\n',
            'rows: must be a whole number from 1 to 64; got "3" (a string)',
        ),
        ("rows = true\ncolumns = 4\nspacing_cm = 3\n", "got true (a boolean)"),
        (
            "rows = 1\ncolumns = 1\nspacing_cm = 3\n",
            "rows x columns: a sleeve needs at least 2 actuators",
        ),
        (
            "rows = 3\ncolumns = 4\nspacing_cm = 0\n",
            "spacing_cm: must be a number above 0 and at most 20; got 0",
        ),
        (
            "rows = 3\ncolumns = 4\nspacing_cm = 30\n",
            "spacing_cm: must be a number above 0 and at most 20; got 30",
        ),
        (
            "rows = 3\ncolumns = 4\nspacing_cm = nan\n",
            "spacing_cm: must be a number above 0 and at most 20; got nan",
        ),
        (
            GRID + "default_intensity = 1.5\n",
            "default_intensity: must be a number above 0 and at most 1; got 1.5",
        ),
        (
            GRID + "default_intensity = 0.9\n[safety]\nmax_intensity = 0.5\n",
            "default_intensity: 0.9 is above safety.max_intensity 0.5",
        ),
        (
            GRID + "[safety]\nmax_on_time_ms = -5\n",
            "safety.max_on_time_ms: must be a number above 0 and at most 600000; got -5",
        ),
        (
            GRID + "[safety]\nmax_stroke_duration_ms = inf\n",
            "safety.max_stroke_duration_ms: must be a number above 0",
        ),
        (
            GRID + 'actuator_type = "lra"\n',
            'actuator_type: must be "ERM" or "LRA"; got "lra" (a string); write it in capitals',
        ),
        (
            GRID + "min_burst_ms = 0\n",
            "min_burst_ms: must be a number above 0 and at most 1000; got 0",
        ),
        (
            GRID + 'min_burst_ms = "20"\n',
            'min_burst_ms: must be a number above 0 and at most 1000; got "20" (a string)',
        ),
        (GRID + 'name = "a/b"\n', "name: must be 1 to 64 printable characters without / + #"),
        (GRID + 'name = ""\n', "name: must be 1 to 64"),
        (GRID + "safety = 3\n", "safety: must be a table of max_intensity"),
        (GRID + "[i2c]\nbus = -1\n", "i2c.bus: must be a whole number from 0 to 255; got -1"),
        (GRID + "[i2c]\nmultiplexers = 0x70\n", "i2c.multiplexers: must be an array of addresses"),
        (
            GRID + "[i2c]\nmultiplexers = [0x70, 0x78]\n",
            "i2c.multiplexers[1]: must be a TCA9548A address from 0x70 to 0x77; got 0x78 (120)",
        ),
        (
            GRID + "[i2c]\nmultiplexers = [0x70, 0x70]\n",
            "i2c.multiplexers[1]: 0x70 is listed twice",
        ),
        (
            GRID + '[i2c]\nmultiplexers = ["0x70"]\n',
            'i2c.multiplexers[0]: must be a TCA9548A address from 0x70 to 0x77; got "0x70" (a '
            "string)",
        ),
        (
            GRID + "[i2c]\nwiring = 5\n",
            "i2c.wiring: must be an array of tables {row, column, multiplexer, channel}",
        ),
        (
            GRID + "[i2c]\nmultiplexers = [0x70]\nwiring = [5]\n",
            "i2c.wiring[0]: must be a table of row, column, multiplexer, channel; got 5",
        ),
        ("rows = 3\ncolumns = [\n", "not valid TOML: "),
    ],
)
def test_each_problem_names_the_key_the_value_and_the_range(text: str, expected: str) -> None:
    problems = problems_of(text)
    assert any(expected in problem for problem in problems), problems


def test_wiring_problems() -> None:
    wires = paper_wires()
    wires[1] = (0, 1, 0x70, 0)  # channel 0 of 0x70 again
    wires[2] = (0, 0, 0x70, 2)  # actuator (0, 0) again
    wires[3] = (3, 3, 0x70, 3)  # a row the grid does not have
    wires[4] = (1, 0, 0x72, 4)  # a multiplexer not declared
    wires[5] = (1, 1, 0x70, 8)  # a channel the TCA9548A does not have
    problems = problems_of(wiring_toml(wires))
    expected = [
        "i2c.wiring[1]: multiplexer 0x70 channel 0 is already used by i2c.wiring[0] "
        "(row 0, column 0)",
        "i2c.wiring[2]: actuator (row 0, column 0) is already wired in i2c.wiring[0]",
        "i2c.wiring[3].row: must be a whole number from 0 to 2; got 3",
        "i2c.wiring[4].multiplexer: 0x72 is not declared in i2c.multiplexers "
        "(declared: 0x70, 0x71)",
        "i2c.wiring[5].channel: must be a whole number from 0 to 7; got 8",
        # Entries 1 and 5 name (0, 1) and (1, 1): wrong in another field, said above.
        "i2c.wiring: 2 of 12 actuators are not wired: (row 0, column 2), (row 0, column 3);",
    ]
    for text in expected:
        assert any(problem.startswith(text) for problem in problems), (text, problems)
    assert len(problems) == len(expected)


PAPER_TEXT = (LAYOUTS / "paper-sleeve.toml").read_text()


@pytest.mark.parametrize(
    ("change", "only"),
    [
        # An LRA's key with actuator_type mistyped: not blamed on an ERM as well.
        (
            ('actuator_type = "ERM"', 'actuator_type = "lra"\nresonant_frequency_hz = 175'),
            'actuator_type: must be "ERM" or "LRA"; got "lra" (a string); write it in capitals',
        ),
        # A bad channel: its actuator is not called unwired as well.
        (
            ("multiplexer = 0x71, channel = 3 }", "multiplexer = 0x71, channel = 8 }"),
            "i2c.wiring[11].channel: must be a whole number from 0 to 7; got 8",
        ),
        # A bad address in the list: the wires naming the one meant are not each said again.
        (
            ("multiplexers = [0x70, 0x71]", "multiplexers = [0x70, 0x80]"),
            "i2c.multiplexers[1]: must be a TCA9548A address from 0x70 to 0x77; got 0x80",
        ),
        # An address left out of the list: one line for its four wires.
        (
            ("multiplexers = [0x70, 0x71]", "multiplexers = [0x70]"),
            "i2c.wiring[8], [9], [10], [11].multiplexer: 0x71 is not declared in "
            "i2c.multiplexers (declared: 0x70)",
        ),
    ],
)
def test_one_mistake_is_said_once_without_follow_on_lines(
    change: tuple[str, str], only: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    old, new = change
    assert PAPER_TEXT.count(old) == 1
    layout = tmp_path / "sleeve.toml"
    layout.write_text(PAPER_TEXT.replace(old, new))
    assert main(["validate", "--layout", str(layout), "0,0,1,1,500"]) != 0
    problems = [line for line in capsys.readouterr().err.splitlines() if line.startswith("  - ")]
    assert len(problems) == 1 and problems[0].startswith(f"  - {only}"), problems


def test_every_problem_is_reported_at_once() -> None:
    text = (
        'name = ""\nrows = 0\ncolumns = 99\nspacing_cm = -1\nactuator_type = "PIEZO"\n'
        "default_intensity = 2\ncolour = 1\n[safety]\nmax_intensity = 0\n"
        "[i2c]\nbus = 1000\nmultiplexers = [0x10]\n"
    )
    assert len(problems_of(text)) == 10


def test_a_missing_wiring_key_is_named() -> None:
    problems = problems_of(
        f"{GRID}[i2c]\nmultiplexers = [0x70]\nwiring = [{{ row = 0, column = 0 }}]\n"
    )
    assert any(p.startswith("i2c.wiring[0].channel: missing;") for p in problems)
    assert any(p.startswith("i2c.wiring[0].multiplexer: missing;") for p in problems)


def test_a_missing_file_names_the_path(tmp_path: Path) -> None:
    path = tmp_path / "nope.toml"
    with pytest.raises(LayoutError) as caught:
        load_layout(path)
    assert str(path) in str(caught.value) and "file not found" in str(caught.value)


def test_unreadable_files_name_the_path(tmp_path: Path) -> None:
    with pytest.raises(LayoutError, match="cannot read the file"):
        load_layout(tmp_path)
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(b'name = "manche \xe9"\n' + GRID.encode())
    with pytest.raises(LayoutError, match="not UTF-8"):
        load_layout(latin1)


def test_grid_layout_is_checked_like_a_file() -> None:
    assert grid_layout(4, 6, 2.5).wiring == ()
    with pytest.raises(LayoutError) as caught:
        grid_layout(0, 100, 2.5, max_intensity=0.5, default_intensity=0.8)
    assert len(caught.value.problems) == 3


def test_check_layout_catches_a_bad_layout_built_in_code() -> None:
    layout = Layout(
        rows=1, columns=2, spacing_cm=1.0, multiplexers=(0x70,), wiring=(Wire(0, 0, 0x70, 0),)
    )
    with pytest.raises(LayoutError, match=r"1 of 2 actuators are not wired: \(row 0, column 1\)"):
        check_layout(layout)


# --- properties ---------------------------------------------------------------------------

TOML_LITERALS = st.sampled_from(
    [
        "3",
        "3.0",
        "-1",
        "0",
        "0x70",
        "nan",
        "inf",
        "true",
        '"x"',
        '""',
        "[1, 2]",
        "[]",
        "{a = 1}",
        "1979-05-27",
        "0.5",
    ]
)
KEYS = [*TOP_KEYS, "colour"]  # every top-level key, and one a layout may not have


@given(st.dictionaries(st.sampled_from(KEYS), TOML_LITERALS))
def test_parse_layout_returns_a_layout_or_raises_layout_error(values: dict[str, str]) -> None:
    text = "".join(f"{key} = {value}\n" for key, value in values.items())
    try:
        layout = parse_layout(text)
    except LayoutError as error:
        assert error.problems and all(": " in problem for problem in error.problems)
    else:
        assert 1 <= layout.rows <= 64 and 1 <= layout.columns <= 64


@st.composite
def full_wirings(draw: st.DrawFn) -> tuple[int, int, list[tuple[int, int, int, int]]]:
    rows = draw(st.integers(min_value=1, max_value=8))
    columns = draw(st.integers(min_value=2, max_value=8))
    slots = list(itertools.product(MUX_ADDRESSES, range(MUX_CHANNELS)))
    chosen = draw(st.permutations(slots))[: rows * columns]
    actuators = itertools.product(range(rows), range(columns))
    return rows, columns, [(r, c, m, ch) for (r, c), (m, ch) in zip(actuators, chosen, strict=True)]


def wired_text(rows: int, columns: int, wires: list[tuple[int, int, int, int]]) -> str:
    addresses = ", ".join(hex(a) for a in MUX_ADDRESSES)
    text = wiring_toml(wires, f"[{addresses}]")
    return text.replace("rows = 3", f"rows = {rows}").replace("columns = 4", f"columns = {columns}")


@given(full_wirings())
def test_any_complete_wiring_is_accepted(
    wiring: tuple[int, int, list[tuple[int, int, int, int]]],
) -> None:
    rows, columns, wires = wiring
    layout = parse_layout(wired_text(rows, columns, wires))
    assert sorted((w.row, w.column, w.multiplexer, w.channel) for w in layout.wiring) == sorted(
        wires
    )


@given(full_wirings(), st.data())
def test_dropping_an_entry_names_the_unwired_actuator(
    wiring: tuple[int, int, list[tuple[int, int, int, int]]], data: st.DataObject
) -> None:
    rows, columns, wires = wiring
    index = data.draw(st.integers(min_value=0, max_value=len(wires) - 1))
    row, column, _, _ = wires.pop(index)
    problems = problems_of(wired_text(rows, columns, wires))
    assert problems == [
        f"i2c.wiring: 1 of {rows * columns} actuators are not wired: (row {row}, column {column}); "
        "add an entry for each, or remove i2c.wiring to use the simulator only"
    ]


@given(full_wirings(), st.data())
def test_a_repeated_channel_is_named(
    wiring: tuple[int, int, list[tuple[int, int, int, int]]], data: st.DataObject
) -> None:
    rows, columns, wires = wiring
    first, second = data.draw(st.permutations(range(len(wires))))[:2]
    r, c, _, _ = wires[second]
    wires[second] = (r, c, wires[first][2], wires[first][3])
    problems = problems_of(wired_text(rows, columns, wires))
    assert any(
        "is already used by" in p and f"i2c.wiring[{max(first, second)}]" in p for p in problems
    )


def test_on_time_cap_below_the_longest_stroke_is_refused() -> None:
    text = (
        "rows = 3\ncolumns = 4\nspacing_cm = 3.0\n"
        "[safety]\nmax_stroke_duration_ms = 10000\nmax_on_time_ms = 5000\n"
    )
    with pytest.raises(LayoutError) as error:
        parse_layout(text)
    assert any("max_on_time_ms" in p and "buzzed" in p for p in error.value.problems)


def test_the_duty_cycle_cap_is_read_with_its_defaults_and_checked() -> None:
    grid = "rows = 3\ncolumns = 4\nspacing_cm = 3.0\n"
    default = parse_layout(grid)
    assert (default.duty_cycle_window_ms, default.max_duty_cycle) == (60_000.0, 0.5)
    tight = parse_layout(grid + "[safety]\nduty_cycle_window_ms = 30000\nmax_duty_cycle = 0.4\n")
    assert (tight.duty_cycle_window_ms, tight.max_duty_cycle) == (30_000.0, 0.4)
    cases = {
        "max_duty_cycle = 1.5": "safety.max_duty_cycle: must be a number above 0 and at most 1;",
        "max_duty_cycle = 0": "safety.max_duty_cycle: must be a number above 0 and at most 1;",
        "duty_cycle_window_ms = 500": "safety.duty_cycle_window_ms: must be at least 1000",
        "duty_cycle_window_ms = 15000\nmax_duty_cycle = 0.5": (
            "safety.max_duty_cycle: 0.5 of safety.duty_cycle_window_ms 15000 is 7500 ms of full "
            "drive, below safety.max_stroke_duration_ms 10000"
        ),
    }
    for text, problem in cases.items():
        with pytest.raises(LayoutError) as error:
            parse_layout(grid + "[safety]\n" + text + "\n")
        assert any(p.startswith(problem) for p in error.value.problems), error.value.problems


# --- the wearer's buttons ([controls]) ------------------------------------------------------

_WIRED = Path(__file__).resolve().parents[2] / "deploy" / "layouts" / "paper-sleeve.toml"


def test_the_wearers_buttons_are_read_from_their_own_table() -> None:
    text = _WIRED.read_text() + (
        '\n[controls]\npause_button = { chip = "gpiochip0", line = 27 }\n'
        'turn_down_button = { chip = "/dev/gpiochip0", line = 22 }\n'
    )
    layout = parse_layout(text)
    assert layout.pause_button is not None and layout.turn_down_button is not None
    assert (layout.pause_button.name, layout.pause_button.role) == ("gpiochip0 line 27", "pause")
    assert (layout.turn_down_button.path, layout.turn_down_button.role) == (
        "/dev/gpiochip0",
        "turn_down",
    )
    assert check_layout(layout) is layout  # a layout built in code keeps its buttons


def test_a_button_in_the_wrong_table_or_on_a_taken_line_says_where_it_belongs() -> None:
    misplaced = _WIRED.read_text().replace(
        "[i2c]\n",
        '[i2c]\nenable = { chip = "gpiochip0", line = 17 }\n'
        'pause_button = { chip = "gpiochip0", line = 27 }\ncontrols = 1\n',
        1,
    )
    taken = '\n[controls]\nturn_down_button = { chip = "gpiochip0", line = 17 }\n'
    with pytest.raises(LayoutError) as raised:
        parse_layout(misplaced + taken)
    problems = "\n".join(raised.value.problems)
    assert "i2c.pause_button: unknown key here (it belongs in the [controls] table)" in problems
    assert "i2c.controls: unknown key here (it is a table of its own, [controls]" in problems
    assert "controls.turn_down_button: gpiochip0 line 17 is already i2c.enable's" in problems


def test_a_button_line_given_by_its_name_is_refused_with_the_offset_to_use() -> None:
    text = (
        _WIRED.read_text()
        + '\n[controls]\npause_button = { chip = "gpiochip0", line = "GPIO27" }\n'
    )
    with pytest.raises(LayoutError, match=r"controls\.pause_button\.line: must be a whole number"):
        parse_layout(text)


@pytest.mark.parametrize(("line", "pin"), [(2, "SDA"), (3, "SCL")])
def test_an_enable_line_or_button_on_the_pis_i2c_pins_is_refused(line: int, pin: str) -> None:
    wired = wiring_toml(paper_wires())
    enable = f'enable = {{ chip = "gpiochip0", line = {line} }}\n'
    button = f'\n[controls]\npause_button = {{ chip = "gpiochip0", line = {line} }}\n'
    (problem,) = problems_of(wired.replace("[i2c]\n", "[i2c]\nbus = 1\n" + enable))
    assert problem.startswith(
        f"i2c.enable.line: {line} is GPIO{line}, the Raspberry Pi's I2C1 {pin}"
    )
    assert "GPIO17" in problem
    (problem,) = problems_of(wired + button)  # bus 1 is the default
    assert problem.startswith(f"controls.pause_button.line: {line} is GPIO{line}")
    # On another bus (or another chip) those pins are free.
    other_bus = wired.replace("[i2c]\n", "[i2c]\nbus = 3\n" + enable)
    assert parse_layout(other_bus).enable == EnableLine("gpiochip0", line)
    assert parse_layout(wired.replace("[i2c]\n", "[i2c]\n" + enable.replace("chip0", "chip4")))
