"""The simulator backend and the rate-limited actuator telemetry, on an injected clock."""

from __future__ import annotations

import json
import threading
from pathlib import Path

import pytest

from feelmysign.backends import (
    ActuatorFrame,
    ActuatorTelemetry,
    Backend,
    RecordedChange,
    SimBackend,
)
from feelmysign.layout import Layout

PAPER = Layout(rows=3, columns=4, spacing_cm=3.0, name="paper-sleeve")


class FakeClock:
    """Milliseconds that move only when the test says so."""

    def __init__(self, now_ms: float = 1000.0) -> None:
        self.now_ms = now_ms

    def __call__(self) -> float:
        return self.now_ms

    def advance(self, ms: float) -> None:
        self.now_ms += ms


# -- the simulator ------------------------------------------------------------------------


def test_sim_records_each_change_relative_to_its_start() -> None:
    clock = FakeClock(5000.0)
    with SimBackend(PAPER, clock=clock) as sim:
        clock.advance(12.5)
        sim.set_intensity(0, 3, 0.8)
        clock.advance(100.0)
        sim.set_intensity(0, 3, 0.8)  # no change: not recorded
        sim.set_intensity(2, 0, 0.25)
        clock.advance(50.0)
        sim.set_intensity(0, 3, 0.0)
        assert sim.changes == [
            RecordedChange(12.5, 0, 3, 0.8),
            RecordedChange(112.5, 2, 0, 0.25),
            RecordedChange(162.5, 0, 3, 0.0),
        ]
        assert sim.snapshot() == [[0.0, 0.0, 0.0, 0.0], [0.0] * 4, [0.25, 0.0, 0.0, 0.0]]


def test_sim_writes_json_lines_as_it_goes(tmp_path: Path) -> None:
    record = tmp_path / "felt.jsonl"
    clock = FakeClock()
    opened_wall_ms = 1_795_000_000_000.0
    sim = SimBackend(PAPER, clock=clock, record=record, wall_clock=lambda: opened_wall_ms)

    def line(t_ms: float, row: int, column: int, intensity: float, *source: object) -> object:
        drawing, seq = source or (None, None)
        return {
            **{"t_ms": t_ms, "wall_ms": opened_wall_ms + t_ms, "row": row, "column": column},
            **{"intensity": intensity, "drawing": drawing, "seq": seq},
        }

    with sim:
        clock.advance(3.0)
        sim.note_source("d1", 0)
        sim.set_intensity(1, 2, 0.5)
        clock.advance(4.25)
        sim.note_source("d1", 1)
        sim.set_intensity(1, 1, 1.0)
        # Readable before close: a crash would not lose these lines.
        lines = record.read_text(encoding="utf-8").splitlines()
        assert [json.loads(text) for text in lines] == [
            line(3.0, 1, 2, 0.5, "d1", 0),
            line(7.25, 1, 1, 1.0, "d1", 1),
        ]
        clock.advance(1.0)
    # Closing switches off what was on, and records it: no stroke made those changes.
    lines = record.read_text(encoding="utf-8").splitlines()
    assert [json.loads(text) for text in lines[2:]] == [
        line(8.25, 1, 1, 0.0),
        line(8.25, 1, 2, 0.0),
    ]
    assert sim.record_path == record


def test_sim_all_off_zeroes_the_grid_and_records_only_what_was_on() -> None:
    sim = SimBackend(PAPER, clock=FakeClock())
    sim.open()
    sim.set_intensity(0, 0, 0.3)
    sim.all_off()
    assert sim.snapshot() == [[0.0] * 4 for _ in range(3)]
    assert [(c.row, c.column, c.intensity) for c in sim.changes] == [(0, 0, 0.3), (0, 0, 0.0)]
    sim.all_off()
    assert len(sim.changes) == 2


def test_sim_has_the_backend_interface_and_checks_like_the_hardware() -> None:
    sim = SimBackend(PAPER)
    assert isinstance(sim, Backend)
    with pytest.raises(RuntimeError, match="open it first"):
        sim.set_intensity(0, 0, 0.5)
    with sim:
        with pytest.raises(ValueError, match=r"intensity = -0\.1 .* \[0, 1\]"):
            sim.set_intensity(0, 0, -0.1)
        with pytest.raises(ValueError, match=r"column = 4 .* 0\.\.3 \(the grid is 3 x 4\)"):
            sim.set_intensity(0, 4, 0.5)
    sim.close()  # idempotent
    with pytest.raises(RuntimeError, match="closed"):
        sim.open()


def test_sim_keeps_a_bounded_number_of_changes() -> None:
    with SimBackend(PAPER, clock=FakeClock(), keep_changes=2) as sim:
        for intensity in (0.1, 0.2, 0.3):
            sim.set_intensity(0, 0, intensity)
        assert [c.intensity for c in sim.changes] == [0.2, 0.3]


# -- telemetry ----------------------------------------------------------------------------


def test_telemetry_publishes_the_first_change_then_coalesces_a_burst() -> None:
    clock = FakeClock(0.0)
    frames: list[ActuatorFrame] = []
    telemetry = ActuatorTelemetry(frames.append, rate_hz=20.0, clock=clock)
    assert telemetry.interval_ms == 50.0
    assert telemetry.due_in_ms() is None and not telemetry.poll()

    telemetry.update([[0.1, 0.0]])
    assert telemetry.due_in_ms() == 0.0
    assert telemetry.poll()  # a quiet start publishes at once
    for step in range(1, 5):  # a burst within the interval: nothing published
        clock.advance(10.0)
        telemetry.update([[0.1 * step, 0.5]])
        assert not telemetry.poll()
    assert telemetry.due_in_ms() == 10.0
    clock.advance(10.0)
    assert telemetry.poll()  # the burst's last state, one interval after the first frame
    assert not telemetry.poll()

    assert [f.intensities for f in frames] == [((0.1, 0.0),), ((0.4, 0.5),)]
    assert [f.t_ms for f in frames] == [0.0, 40.0]
    assert telemetry.changes == 5 and telemetry.frames_published == 2


def test_telemetry_flush_publishes_whatever_the_rate() -> None:
    clock = FakeClock(0.0)
    frames: list[ActuatorFrame] = []
    telemetry = ActuatorTelemetry(frames.append, clock=clock)
    telemetry.update([[1.0]])
    telemetry.poll()
    telemetry.update([[0.0]])
    assert not telemetry.poll()
    assert telemetry.flush()
    assert frames[-1].intensities == ((0.0,),)
    assert not telemetry.flush()


def test_telemetry_frames_are_copies_and_serialise_for_mqtt() -> None:
    frames: list[ActuatorFrame] = []
    telemetry = ActuatorTelemetry(frames.append, clock=FakeClock(7.0))
    grid = [[0.0, 1.0], [0.5, 0.0]]
    telemetry.update(grid)
    grid[0][0] = 0.9  # the backend keeps changing its own grid
    telemetry.poll()
    assert frames[0].as_dict() == {
        "t_ms": 7.0,
        "rows": 2,
        "columns": 2,
        "intensities": [[0.0, 1.0], [0.5, 0.0]],
    }
    assert json.loads(json.dumps(frames[0].as_dict()))["rows"] == 2


def test_a_failing_publisher_is_counted_and_never_raises() -> None:
    def broken(frame: ActuatorFrame) -> None:
        raise ConnectionError("broker gone")

    telemetry = ActuatorTelemetry(broken, clock=FakeClock())
    telemetry.update([[0.5]])
    assert not telemetry.poll()
    assert telemetry.publish_errors == 1


def test_telemetry_rejects_a_rate_that_is_not_positive() -> None:
    with pytest.raises(ValueError, match=r"rate_hz = 0"):
        ActuatorTelemetry(lambda frame: None, rate_hz=0)


def test_the_sim_feeds_telemetry_and_the_final_state_after_close() -> None:
    clock = FakeClock(0.0)
    frames: list[ActuatorFrame] = []
    telemetry = ActuatorTelemetry(frames.append, rate_hz=10.0, clock=clock)
    with SimBackend(PAPER, clock=clock, telemetry=telemetry) as sim:
        sim.set_intensity(0, 0, 1.0)
        telemetry.poll()
        clock.advance(5.0)
        sim.set_intensity(0, 1, 1.0)
        assert not telemetry.poll()
    clock.advance(100.0)
    assert telemetry.poll()
    assert frames[0].intensities[0][:2] == (1.0, 0.0)
    assert frames[-1].intensities == tuple((0.0,) * 4 for _ in range(3))
    assert telemetry.changes == 3  # two changes, then all off


def test_the_telemetry_thread_publishes_the_final_state() -> None:
    published = threading.Event()
    frames: list[ActuatorFrame] = []

    def publish(frame: ActuatorFrame) -> None:
        frames.append(frame)
        if frame.intensities == ((0.0, 0.75),):
            published.set()

    with ActuatorTelemetry(publish, rate_hz=1000.0) as telemetry:
        telemetry.update([[0.5, 0.0]])
        telemetry.update([[0.0, 0.75]])
        assert published.wait(timeout=10.0)
    assert frames[-1].intensities == ((0.0, 0.75),)
