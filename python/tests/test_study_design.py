"""The design file: the paper's example loads; every problem of a bad one is listed at once."""

from __future__ import annotations

from pathlib import Path

import pytest
from study_helpers import PAPER_DESIGN, ZIGZAG_SHAPE, zigzag_recording

from feelmysign.errors import DesignError
from feelmysign.study import load_design, parse_design
from feelmysign.study.order import participant_order, williams_rows

MINIMAL = """
[study]
name = "t"
seed = 1
repetitions = 2
resolutions = ["low", "high"]
[[shapes]]
name = "circle"
segments = [4, 16]
[[shapes]]
name = "square"
segments = [4, 8]
[questionnaire]
items = ["comfortable"]
"""


def test_the_papers_design_has_six_shapes_four_resolutions_three_repetitions() -> None:
    design = load_design(PAPER_DESIGN)
    assert len(design.shapes) == 6
    assert len(design.resolutions) == 4
    assert design.repetitions == 3
    assert design.main_trials == 72
    assert "ring" in design.shape("circle").synonyms


def test_every_problem_is_listed_with_where_and_what() -> None:
    bad = MINIMAL.replace("segments = [4, 8]", "segments = [5, 8]").replace(
        "repetitions = 2", "repetitions = 0\ncolour = 'red'"
    )
    bad += '[[shapes]]\nname = "blob"\nsegments = [1, 2]\n'
    with pytest.raises(DesignError) as caught:
        parse_design(bad, source="bad.toml")
    text = str(caught.value)
    assert "shapes[1].segments[0]: a square takes a multiple of 4" in text
    assert "study.repetitions: must be a whole number from 1 to 20; got 0" in text
    assert "study.colour: unknown key" in text
    assert "'blob' is not a library shape" in text
    assert len(caught.value.problems) == 4


def test_a_synonym_may_name_only_one_shape() -> None:
    bad = MINIMAL.replace("segments = [4, 16]", 'segments = [4, 16]\nsynonyms = ["box"]')
    bad = bad.replace("segments = [4, 8]", 'segments = [4, 8]\nsynonyms = ["Box"]')
    with pytest.raises(DesignError, match="synonym 'box' also names 'circle'"):
        parse_design(bad)


def test_a_recorded_drawing_gets_its_strokes_from_the_simplifier(tmp_path: Path) -> None:
    zigzag_recording(tmp_path / "zigzag.json")
    design = parse_design(MINIMAL + ZIGZAG_SHAPE, base_dir=tmp_path)
    coarse, fine = design.shape("zigzag").levels
    assert coarse.strokes < fine.strokes
    bad = (MINIMAL + ZIGZAG_SHAPE).replace("max_error = 1.5", "max_eror = 1.5")
    with pytest.raises(DesignError, match=r"settings\[0\]: max_eror: not a window setting"):
        parse_design(bad, base_dir=tmp_path)


def test_practice_may_play_a_recorded_drawing_at_one_of_its_resolutions(tmp_path: Path) -> None:
    zigzag_recording(tmp_path / "zigzag.json")
    practice = '[[practice]]\nshape = "zigzag"\nresolution = "low"\n[[practice]]\nshape = "line"\n'
    design = parse_design(MINIMAL + ZIGZAG_SHAPE + practice, base_dir=tmp_path)
    recorded, library = design.practice
    coarse = design.shape("zigzag").levels[0]
    assert (recorded.shape, recorded.level, recorded.segments) == ("zigzag", 0, coarse.strokes)
    assert library.level is None
    first = participant_order(design, 0)[0]
    assert (first.block, first.shape, first.level) == ("practice", "zigzag", 0)
    wrong = practice.replace('resolution = "low"', 'segments = 3\nresolution = "mid"')
    with pytest.raises(DesignError) as error:
        parse_design(MINIMAL + ZIGZAG_SHAPE + wrong + 'resolution = "low"\n', base_dir=tmp_path)
    assert "practice[0].segments: 'zigzag' is a recorded drawing" in str(error.value)
    assert "practice[1].resolution: only for a recorded drawing" in str(error.value)


def test_latin_square_rows_are_balanced_for_first_order_carry_over() -> None:
    for n in (4, 5, 24):
        rows = williams_rows(n)
        pairs = [(row[i], row[i + 1]) for row in rows for i in range(n - 1)]
        assert len(set(pairs)) == n * (n - 1)  # every ordered pair of conditions ...
        assert len(pairs) == len(rows) * (n - 1)  # ... equally often
        for position in range(n):
            assert sorted(row[position] for row in rows[:n]) == list(range(n))


def test_each_block_holds_every_condition_once_and_orders_repeat_from_the_seed() -> None:
    design = load_design(PAPER_DESIGN)
    order = participant_order(design, 3)
    main = [t for t in order if t.block == "main"]
    for repetition in (1, 2, 3):
        block = [(t.shape, t.level) for t in main if t.repetition == repetition]
        assert len(set(block)) == 24
    assert participant_order(design, 3) == order
    assert participant_order(design, 4) != order


def test_a_design_that_is_not_utf8_is_named_not_a_crash(tmp_path: Path) -> None:
    bad = tmp_path / "latin1.toml"
    bad.write_bytes('title = "Étude"\n'.encode("latin-1"))
    with pytest.raises(DesignError) as caught:
        load_design(bad)
    assert "not UTF-8 text (byte 9)" in str(caught.value) and "save the design as UTF-8" in str(
        caught.value
    )


def test_practice_written_as_one_table_gets_the_double_brackets_hint() -> None:
    with pytest.raises(DesignError) as caught:
        parse_design(MINIMAL + '[practice]\nshape = "circle"\n', source="bad.toml")
    assert "practice: must be a list of tables: write each entry as [[practice]]" in str(
        caught.value
    )


def test_several_speeds_are_refused_with_how_to_compare_speeds() -> None:
    with pytest.raises(DesignError) as caught:
        parse_design(MINIMAL + "[stimulus]\nspeed_cm_s = [3.0, 8.0]\n", source="bad.toml")
    message = str(caught.value)
    assert "stimulus.speed_cm_s: must be one number from 0.5 to 50; got a list of 2" in message
    assert "make one design file per speed" in message


def test_resolutions_that_repeat_or_go_back_are_refused_saying_what_to_do() -> None:
    bad = MINIMAL.replace('resolutions = ["low", "high"]', 'resolutions = ["a", "b", "c"]')
    bad = bad.replace("segments = [4, 16]", "segments = [12, 6, 6]")
    bad = bad.replace("segments = [4, 8]", "segments = [8, 4, 12]")
    with pytest.raises(DesignError) as caught:
        parse_design(bad, source="bad.toml")
    problems = caught.value.problems
    assert any(
        p.startswith("shapes[0].segments: must increase strictly from coarse to fine")
        and "got 12, 6, 6" in p
        and "fewest segments first" in p
        for p in problems
    ), problems
    assert any("shapes[1].segments" in p and "got 8, 4, 12" in p for p in problems), problems
    assert len(problems) == 2


def test_a_shape_listed_twice_is_one_problem() -> None:
    bad = MINIMAL + '[[shapes]]\nname = "circle"\nsegments = [4, 8]\n'
    with pytest.raises(DesignError) as caught:
        parse_design(bad)
    assert caught.value.problems == [
        "shapes: 'circle' is listed 2 times: give each shape once, with one entry per "
        "resolution in its segments (or settings)"
    ]
