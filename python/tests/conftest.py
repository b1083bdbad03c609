"""Shared fixtures: a real Mosquitto, started through ``feelmysign.broker.Broker``.

``broker`` (function scope)
    A running :class:`feelmysign.broker.Broker` on free 127.0.0.1 ports, its state in a
    fresh temporary directory, sleeve id ``sleeve1``; stopped (no process left) after the
    test. What a test uses from it:

    - ``broker.credentials``: a :class:`feelmysign.broker.Credentials` with ``mqtt_url``,
      ``mqtt_host``, ``mqtt_port``, ``ws_url``, ``ws_port``, ``sleeve_id``,
      ``sleeve.username`` / ``sleeve.password`` and ``sender.username`` / ``sender.password``;
    - ``broker.credentials_path``: the ``credentials.json`` to pass as ``--credentials FILE``;
    - ``broker.log_path``: Mosquitto's log, worth printing when a test fails.

``broker_credentials`` (function scope)
    Just ``broker.credentials``.

``start_broker`` (function scope)
    A factory ``start_broker(**options) -> Broker`` for other options (``sleeve_id=...``,
    ``state_dir=...`` to restart on the same state); every broker it started is stopped
    after the test.

A test that uses any of them is marked ``broker`` automatically (``pytest -m "not broker"``
skips it); a missing Mosquitto fails it with the command that installs it.

Every test, and every process it starts, keeps its state (``$XDG_STATE_HOME``: a broker's
default state directory, the sleeve's wiring memos, its pace memory and the note of the stroke
it plays) in a temporary directory of its own, never in the home directory of whoever runs the
tests: a sleeve killed in the middle of a stroke by one test leaves a note that a sleeve of the
same id started by another would report (a ``safety`` event ``crashed``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, settings

from feelmysign.broker import Broker, Credentials

# No property test may fail for taking long: Hypothesis' own timing checks (a deadline
# of 200 ms an example, data generation "too slow") fail on a loaded machine. Built on the
# profile Hypothesis chose (on CI its "ci" profile, derandomized).
settings.register_profile(
    "feelmysign",
    parent=settings.get_profile(settings.get_current_profile_name()),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("feelmysign")

BROKER_FIXTURES = frozenset({"broker", "broker_credentials", "start_broker"})

StartBroker = Callable[..., Broker]


@pytest.fixture(scope="session", autouse=True)
def _state_home(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """``$XDG_STATE_HOME`` for the whole session (a test may still set its own)."""
    state_home = tmp_path_factory.mktemp("xdg-state")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("XDG_STATE_HOME", str(state_home))
        yield state_home


@pytest.fixture(scope="session", autouse=True)
def _lock_dir(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """The real buses' lock files (feelmysign.backends.bus_lock) in a folder of this session's
    own: a test on /dev/i2c-1 meets neither this machine's sleeve nor another test run."""
    folder = tmp_path_factory.mktemp("locks")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("FEELMYSIGN_LOCK_DIR", str(folder))
        yield folder


@pytest.fixture(autouse=True)
def _state_home_of_each_test(
    _state_home: Path, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[Path]:
    """``$XDG_STATE_HOME`` of one test (a test may still set its own): what its sleeves
    keep across a restart is its own."""
    state_home = tmp_path_factory.mktemp("xdg-state-test")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("XDG_STATE_HOME", str(state_home))
        yield state_home


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if BROKER_FIXTURES.intersection(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.broker)


@pytest.fixture
def start_broker(tmp_path: Path) -> Iterator[StartBroker]:
    started: list[Broker] = []

    def start(**options: Any) -> Broker:
        options.setdefault("state_dir", tmp_path / f"broker-{len(started)}")
        options.setdefault("port", 0)
        options.setdefault("ws_port", 0)
        broker = Broker(**options)
        broker.start()
        started.append(broker)
        return broker

    yield start
    for broker in started:
        broker.stop()


@pytest.fixture
def broker(start_broker: StartBroker) -> Broker:
    return start_broker()


@pytest.fixture
def broker_credentials(broker: Broker) -> Credentials:
    return broker.credentials


@pytest.fixture
def capped_layout(tmp_path: Path) -> Path:
    """A 3 x 4 layout whose safety cap (0.5) is below what a sender may ask for."""
    layout = tmp_path / "capped.toml"
    layout.write_text(
        "rows = 3\ncolumns = 4\nspacing_cm = 3.0\ndefault_intensity = 0.4\n"
        "[safety]\nmax_intensity = 0.5\n"
    )
    return layout
