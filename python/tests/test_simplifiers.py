"""Properties both simplifiers keep, over each one's random paths (see test_angle, test_window)."""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from simplifier_checks import assert_dropped_say_why, run
from test_angle import paths as angle_paths
from test_window import paths as window_paths

EACH_SIMPLIFIER = pytest.mark.parametrize(
    "paths", [angle_paths(), window_paths()], ids=["angle", "window"]
)


# The angle simplifier's only: the window simplifier merges a piece too short to send into the
# next, or sends it when it cannot without breaking its error bound, and drops only a path that
# is one short piece in all (test_window: no piece is dropped ...).
@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_sent_strokes_meet_the_minimums_and_dropped_say_why(data: st.DataObject) -> None:
    params, samples = data.draw(angle_paths())
    assert_dropped_say_why(params, samples)


@EACH_SIMPLIFIER
@settings(max_examples=100, deadline=None)
@given(data=st.data())
def test_replay_is_deterministic(paths: st.SearchStrategy[Any], data: st.DataObject) -> None:
    params, samples = data.draw(paths)
    assert run(params, [samples]) == run(params, [samples])
