"""The simplifiers' parameters, declared once, and what is derived from them: range checks,
the shared ones in every simplifier, and ``feelmysign simplify``'s options."""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass, fields
from pathlib import Path

import pytest

from feelmysign.cli import build_parser, main
from feelmysign.errors import ParameterError
from feelmysign.simplify.angle import AngleParams
from feelmysign.simplify.params import ParamSpec, SharedParams, param, specs_of
from feelmysign.simplify.registry import ALGORITHMS, ONLY_FOR, OWNERS, PARAMETERS
from feelmysign.simplify.window import WindowParams

SHARED = list(specs_of(SharedParams))
NUMBERS = [spec for spec in PARAMETERS.values() if spec.kind is not bool]


def test_the_shared_parameters_are_declared_once_and_come_after_each_own() -> None:
    for algorithm in ALGORITHMS.values():
        names = [f.name for f in fields(algorithm.params)]
        assert names[-len(SHARED) :] == SHARED, algorithm.name
        for name in SHARED:
            assert algorithm.specs[name] == specs_of(SharedParams)[name]
    assert [name for name, owners in OWNERS.items() if len(owners) > 1] == SHARED


def test_every_parameter_belongs_to_the_algorithms_that_declare_it() -> None:
    for name, owners in OWNERS.items():
        assert owners == [a.name for a in ALGORITHMS.values() if name in a.specs]
    assert set(ONLY_FOR) == set(AngleParams.__dataclass_fields__) ^ set(
        WindowParams.__dataclass_fields__
    )


def test_the_declared_defaults_are_the_dataclasses_defaults() -> None:
    for algorithm in ALGORITHMS.values():
        defaults = algorithm.params()
        for name, spec in algorithm.specs.items():
            assert getattr(defaults, name) == spec.default
            assert type(spec.default) is spec.kind


@pytest.mark.parametrize("spec", NUMBERS, ids=lambda s: s.name)
def test_a_value_out_of_range_names_the_parameter_the_value_and_the_range(
    spec: ParamSpec,
) -> None:
    assert spec.minimum is not None and spec.maximum is not None
    algorithm = ALGORITHMS[OWNERS[spec.name][0]]
    with pytest.raises(ParameterError) as raised:
        algorithm.params(**{spec.name: spec.maximum + 1})
    assert str(raised.value) == (
        f"{spec.name} = {spec.maximum + 1!r} is not allowed; "
        f"it must be in [{spec.minimum:g}, {spec.maximum:g}]"
    )


def test_a_default_of_another_type_than_its_field_is_refused() -> None:
    @dataclass(frozen=True)
    class Wrong:
        limit_ms: float = param(3, 0, 10, help="a limit", label="Limit")

    with pytest.raises(TypeError, match=r"Wrong\.limit_ms"):
        specs_of(Wrong)


def test_a_condition_on_a_parameter_that_is_not_a_switch_of_its_class_is_refused() -> None:
    @dataclass(frozen=True)
    class NoSwitch:
        limit_ms: float = param(3.0, 0, 10, help="a limit", label="Limit", only_when=("on", True))

    @dataclass(frozen=True)
    class NumberSwitch:
        on: float = param(1.0, 0, 1, help="a number", label="On")
        limit_ms: float = param(3.0, 0, 10, help="a limit", label="Limit", only_when=("on", True))

    for wrong in (NoSwitch, NumberSwitch):
        with pytest.raises(TypeError, match=rf"{wrong.__name__}\.limit_ms: only_when names 'on'"):
            specs_of(wrong)


def test_a_conditional_parameter_applies_only_under_its_condition() -> None:
    @dataclass(frozen=True)
    class Cores:
        fast: bool = param(True, help="the fast core", label="Fast")
        slow_limit: float = param(1.0, 0, 2, help="a", label="A", only_when=("fast", False))

    spec = specs_of(Cores)["slow_limit"]
    assert spec.only_when == ("fast", False)
    assert spec.applies({"fast": False}) and not spec.applies({"fast": True})
    assert specs_of(Cores)["fast"].applies({"fast": True})  # no condition: always read
    row = spec.to_table(["x"])
    assert row["only_when"] == {"name": "fast", "value": False}
    assert specs_of(Cores)["fast"].to_table(["x"])["only_when"] is None


def test_the_table_carries_each_condition() -> None:
    table = json.loads((Path(__file__).parents[2] / "testdata/params/params.json").read_text())
    conditions = {row["name"]: row["only_when"] for row in table["parameters"] if row["only_when"]}
    assert conditions == {
        name: {"name": spec.only_when[0], "value": spec.only_when[1]}
        for name, spec in PARAMETERS.items()
        if spec.only_when is not None
    }
    assert set(conditions) == {"max_bend", "bend_floor", "lookahead_ms"}


def _simplify_parser() -> argparse.ArgumentParser:
    parser = build_parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return subparsers.choices["simplify"]  # type: ignore[no-any-return]


def test_every_parameter_that_shapes_the_strokes_is_an_option_with_its_help_and_range() -> None:
    options = {a.dest: a for a in _simplify_parser()._actions if a.dest in PARAMETERS}
    expected = {s.name for s in PARAMETERS.values() if s.panel in ("simplifier", "sleeve")}
    assert set(options) == expected
    for name, action in options.items():
        spec = PARAMETERS[name]
        assert action.help is not None and spec.help in action.help
        assert action.default is None  # the recording's value applies when not given
        if spec.kind is not bool:
            assert (
                f"({spec.minimum:g} to {spec.maximum:g}; default: {spec.default:g})" in action.help
            )
        if name in ONLY_FOR:
            # Read by one core only: "window with --least-squares: ..."
            condition = ""
            if spec.only_when is not None:
                switch, value = spec.only_when
                condition = f" with --{'' if value else 'no-'}{switch.replace('_', '-')}"
            assert action.help.startswith(f"{ONLY_FOR[name]}{condition}: ")


def _recording(path: Path) -> Path:
    samples = [{"t_ms": 8.0 * k, "x": 10.0 * k, "y": 20.0, "pressure": 0.5} for k in range(40)]
    path.write_text(json.dumps({"canvas": {"width_px": 800, "height_px": 600}, "paths": [samples]}))
    return path


@pytest.mark.parametrize("spec", NUMBERS, ids=lambda s: s.name)
def test_the_cli_refuses_a_value_out_of_range_naming_it(
    spec: ParamSpec, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    if spec.panel not in ("simplifier", "sleeve"):
        pytest.skip(f"{spec.name} is the recording's, not an option")
    assert spec.minimum is not None and spec.maximum is not None
    flag = "--" + spec.name.replace("_", "-")
    args = ["simplify", str(_recording(tmp_path / "r.json")), "--algorithm", OWNERS[spec.name][0]]
    # A usage error (exit 2), named as the option, with the range, before the recording is read.
    too_big = f"{spec.maximum + 1:g}"
    with pytest.raises(SystemExit) as caught:
        main([*args, flag, too_big])
    assert caught.value.code == 2
    err = capsys.readouterr().err
    kind = "a whole number" if spec.kind is int else "a number"
    assert f"Error: {flag}: {too_big} is out of range; give {kind} from " in err, err
    assert f"from {spec.minimum:g} to {spec.maximum:g}" in err, err


@pytest.mark.parametrize(("flag", "owner"), [("--no-recover", "angle"), ("--recover", "angle")])
def test_an_option_of_the_other_simplifier_is_a_usage_error_naming_it(
    flag: str, owner: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["simplify", str(_recording(tmp_path / "r.json")), "--algorithm", "window", flag]
    with pytest.raises(SystemExit) as exited:
        main(args)
    assert exited.value.code == 2
    assert f"{flag} only applies to --algorithm {owner}" in capsys.readouterr().err
