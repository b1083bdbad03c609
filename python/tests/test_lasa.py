"""The LASA importer: 210 recordings of 30 shapes, in canvas coordinates, times in ms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import loadmat

from feelmysign.research import lasa, metrics
from feelmysign.research.evaluate import grid_points
from feelmysign.research.rerun import rerun
from feelmysign.simplify.registry import ALGORITHMS, params_for


@pytest.fixture(scope="module")
def demos() -> list[lasa.LasaDemo]:
    return lasa.load_lasa()


def test_all_shapes_and_demonstrations(demos: list[lasa.LasaDemo]) -> None:
    assert len(demos) == 210
    assert len({d.shape for d in demos}) == 30
    assert len({d.name for d in demos}) == 210
    assert {d.demo for d in demos} == set(range(1, 8))


def test_each_is_one_path_of_increasing_times_inside_its_canvas(
    demos: list[lasa.LasaDemo],
) -> None:
    for demo in demos:
        recording = demo.recording
        assert len(recording.paths) == 1
        samples = recording.paths[0]
        times = np.array([s.t_ms for s in samples])
        assert times[0] == 0.0 and np.all(np.diff(times) > 0), demo.name
        assert 1000 < times[-1] < 20_000, demo.name  # seconds became ms
        xs, ys = np.array([s.x for s in samples]), np.array([s.y for s in samples])
        assert xs.min() > 0 and xs.max() < recording.width_px, demo.name
        assert ys.min() > 0 and ys.max() < recording.height_px, demo.name
        assert {s.pressure for s in samples} == {0.5}


def test_y_is_flipped_and_the_scale_kept() -> None:
    raw = loadmat(str(lasa.data_folder() / "Angle.mat"))["demos"][0][0][0][0]["pos"]
    recording = lasa.load_lasa(["Angle"])[0].recording
    samples = recording.paths[0]
    dx_data, dy_data = raw[0][-1] - raw[0][0], raw[1][-1] - raw[1][0]
    dx_canvas, dy_canvas = samples[-1].x - samples[0].x, samples[-1].y - samples[0].y
    assert dx_canvas == pytest.approx(dx_data * lasa.PX_PER_UNIT)
    assert dy_canvas == pytest.approx(-dy_data * lasa.PX_PER_UNIT)  # up in the data, down here


def test_an_unknown_shape_lists_the_shapes() -> None:
    with pytest.raises(lasa.LasaError, match="Angle"):
        lasa.load_lasa(["Circle"])


def test_window_stays_within_its_error_on_every_demonstration(
    demos: list[lasa.LasaDemo],
) -> None:
    """The window simplifier's promise, measured by the research metric on real pen data."""
    window = ALGORITHMS["window"]
    for max_error in (0.05, 0.2):
        for demo in demos:
            params = params_for(window, demo.recording, {"max_error": max_error})
            result = rerun(demo.recording, params)
            frames = result.frames[0]
            deviation = metrics.max_deviation(
                [f.t_ms for f in frames],
                grid_points(params, frames),
                [item.segment for item in result.segments],
            )
            assert deviation <= max_error + 1e-9, (demo.name, max_error, deviation)
