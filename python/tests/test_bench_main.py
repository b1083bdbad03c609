"""``python -m feelmysign.bench``'s choice of groups: make bench runs the untimed group while
it builds, then the others; a wrong group name is one clear error."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from feelmysign.bench import __main__ as bench


@pytest.fixture
def ran(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The groups main() runs, in order, each a stand-in printing one line."""
    order: list[str] = []

    def stand_in(name: str) -> Callable[[], list[str]]:
        def report() -> list[str]:
            order.append(name)
            return [f"{name} figures"]

        return report

    monkeypatch.setattr(bench, "GROUPS", {name: stand_in(name) for name in bench.GROUPS})
    return order


def test_without_names_every_group_runs_in_order(ran: list[str]) -> None:
    bench.main([])
    assert ran == list(bench.GROUPS)


def test_named_groups_run_in_the_usual_order(ran: list[str]) -> None:
    bench.main(["persistence", "algorithms"])
    assert ran == ["algorithms", "persistence"]


def test_without_leaves_a_group_out(ran: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    bench.main(["--without", "simplifier_timing"])
    assert ran == [name for name in bench.GROUPS if name != "simplifier_timing"]
    assert "simplifier_timing figures" not in capsys.readouterr().out


def test_an_unknown_group_is_one_error_naming_the_groups(
    ran: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exit_info:
        bench.main(["sleve"])
    assert exit_info.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert "no benchmark group sleve" in error
    assert "sleeve" in error and "persistence" in error
    assert ran == []
