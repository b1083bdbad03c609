"""The design file: the paper's example loads; every problem of a bad one is listed at once."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from study_helpers import PAPER_DESIGN, ZIGZAG_SHAPE, zigzag_recording

from feelmysign.errors import DesignError
from feelmysign.layout import PAPER_SLEEVE
from feelmysign.study import load_design, parse_design
from feelmysign.study.order import participant_order, williams_rows
from feelmysign.study.stimulus import trial_strokes

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
    assert caught.value.problems == [
        "practice: must be a list of tables; got a single [practice] table: write [[practice]] "
        "(two brackets) before each entry instead, one per entry"
    ]


def test_practice_declared_twice_as_a_table_is_named_in_toml_words() -> None:
    twice = '[practice]\nshape = "circle"\n[practice]\nshape = "line"\n'
    with pytest.raises(DesignError) as caught:
        parse_design(MINIMAL + twice, source="bad.toml")
    (problem,) = caught.value.problems
    assert problem.startswith("not valid TOML: [practice] is declared twice (at line ")
    assert "write [[practice]] (two brackets) before each one" in problem
    assert "('practice',)" not in problem


SPEEDS = "[stimulus]\nspeed_cm_s = [3, 6, 12]\n"


def test_a_list_of_speeds_crosses_with_shape_resolution_and_repetition() -> None:
    design = parse_design(MINIMAL + SPEEDS + '[[practice]]\nshape = "line"\n')
    assert design.speeds == (3.0, 6.0, 12.0) and design.speed_is_factor
    assert design.main_trials == 2 * 2 * 3 * 2
    order = participant_order(design, 1)
    (practice,) = [t for t in order if t.block == "practice"]
    assert practice.speed_cm_s == 3.0  # the first listed speed
    main = [t for t in order if t.block == "main"]
    for repetition in (1, 2):
        block = [(t.shape, t.level, t.speed_cm_s) for t in main if t.repetition == repetition]
        assert sorted(block) == sorted(
            (shape, level, speed)
            for shape in ("circle", "square")
            for level in (0, 1)
            for speed in (3.0, 6.0, 12.0)
        )
    # The speeds are mixed within a block, not played one after another.
    assert len({t.speed_cm_s for t in main[:3]}) > 1
    assert design.to_json()["stimulus"]["speed_cm_s"] == [3.0, 6.0, 12.0]


def test_with_one_speed_orders_and_design_json_are_what_they_were() -> None:
    one = parse_design(MINIMAL)
    listed = parse_design(MINIMAL + "[stimulus]\nspeed_cm_s = [5]\n")
    assert not one.speed_is_factor and one.speeds == (5.0,) and one.main_trials == 8
    assert listed == one
    assert one.to_json()["stimulus"] == {
        "speed_cm_s": 5.0,
        "margin": 0.0,
        "intensity": None,
        "layout": None,
    }
    order = [(t.shape, t.level, t.segments) for t in participant_order(one, 2)]
    conditions = [("circle", 0, 4), ("circle", 1, 16), ("square", 0, 4), ("square", 1, 8)]
    rows = williams_rows(4)
    expected = [conditions[i] for r in (4, 5) for i in rows[r % len(rows)]]
    assert order == expected  # the Latin square of the conditions, as before speeds


def test_a_practice_trial_may_have_its_own_speed() -> None:
    practice = '[[practice]]\nshape = "circle"\nspeed_cm_s = 2.5\n'
    design = parse_design(MINIMAL + SPEEDS + practice)
    assert design.practice[0].speed_cm_s == 2.5
    assert participant_order(design, 0)[0].speed_cm_s == 2.5
    assert design.to_json()["practice"][0]["speed_cm_s"] == 2.5
    with pytest.raises(DesignError) as caught:
        parse_design(MINIMAL + practice.replace("2.5", "'slow'"), source="bad.toml")
    assert caught.value.problems == [
        "practice[0].speed_cm_s: must be a number from 0.5 to 50; got 'slow'"
    ]


@pytest.mark.parametrize(
    ("speeds", "problem"),
    [
        (
            "[3, 6, 3.0]",
            "stimulus.speed_cm_s: each speed once; 3 cm/s is listed more than once in "
            "[3, 6, 3.0]: remove the copies (study.repetitions says how often each condition "
            "is played)",
        ),
        (
            "[]",
            "stimulus.speed_cm_s: the list is empty; give one number from 0.5 to 50 cm/s, or a "
            "list of different ones (e.g. [3, 6, 12])",
        ),
        ("[3, 0.2]", "stimulus.speed_cm_s[1]: must be a number from 0.5 to 50; got 0.2"),
        ("[3, 'fast']", "stimulus.speed_cm_s[1]: must be a number from 0.5 to 50; got 'fast'"),
        ("[3, true]", "stimulus.speed_cm_s[1]: must be a number from 0.5 to 50; got true"),
        (
            "[1, 2, 3, 4, 5, 6, 7, 8, 9]",
            "stimulus.speed_cm_s: at most 8 speeds; got 9: each speed plays every shape x "
            "resolution x repetition again; keep the speeds the question needs",
        ),
    ],
)
def test_a_bad_list_of_speeds_is_refused_saying_what_and_what_to_do(
    speeds: str, problem: str
) -> None:
    with pytest.raises(DesignError) as caught:
        parse_design(MINIMAL + f"[stimulus]\nspeed_cm_s = {speeds}\n", source="bad.toml")
    assert caught.value.problems == [problem]


def test_a_speed_too_slow_for_a_shape_is_refused_before_anything_is_sent() -> None:
    slow = MINIMAL + '[stimulus]\nspeed_cm_s = [0.5, 5]\n[[shapes]]\nname = "line"\n'
    with pytest.raises(DesignError) as caught:
        parse_design(slow + "segments = [1, 2]\n", source="bad.toml")
    square, line = caught.value.problems  # one problem per level too slow to play
    assert square.startswith(
        "shapes[1].segments[0]: square at resolution 'low' (4 segments) is too slow at "
        "0.5 cm/s: a stroke would last longer than the sleeve plays one (10000 ms, the "
        "layout's max_stroke_duration_ms); the slowest speed it plays at is "
    )
    assert line.startswith("shapes[2].segments[0]: line at resolution 'low' (1 segment)")
    # The slowest speed named plays, and a step slower does not.
    found = re.search(r"the slowest speed it plays at is ([0-9.]+) cm/s", line)
    assert found is not None
    slowest = float(found[1])
    square_fixed = MINIMAL.replace("segments = [4, 8]", "segments = [8, 12]")
    for speed, plays in ((slowest, True), (round(slowest - 0.1, 6), False)):
        design = (
            square_fixed + f'[stimulus]\nspeed_cm_s = [{speed}, 5]\n[[shapes]]\nname = "line"\n'
        )
        try:
            parse_design(design + "segments = [1, 2]\n")
        except DesignError as error:
            assert not plays and [p[:21] for p in error.problems] == ["shapes[2].segments[0]"]
        else:
            assert plays
    fixed = slow.replace("segments = [4, 8]", "segments = [8, 12]") + "segments = [2, 4]\n"
    assert parse_design(fixed).speeds == (0.5, 5.0)


def test_a_recorded_drawing_is_redrawn_at_each_speed_only_when_speed_is_a_factor(
    tmp_path: Path,
) -> None:
    zigzag_recording(tmp_path / "zigzag.json")
    one = parse_design(MINIMAL + ZIGZAG_SHAPE, base_dir=tmp_path)
    several = parse_design(MINIMAL + ZIGZAG_SHAPE + SPEEDS, base_dir=tmp_path)
    kept = {t.speed_cm_s for t in participant_order(one, 0) if t.shape == "zigzag"}
    assert kept == {None}  # one speed: the drawing keeps the hand's timing
    drawn = {t.speed_cm_s for t in participant_order(several, 0) if t.shape == "zigzag"}
    assert drawn == {3.0, 6.0, 12.0}
    own = trial_strokes(one, tmp_path, "zigzag", level=1, segments=None, drawing="d")
    at = {
        speed: trial_strokes(
            several, tmp_path, "zigzag", level=1, segments=None, drawing="d", speed_cm_s=speed
        )
        for speed in (3.0, 6.0)
    }
    assert [(s.start, s.end) for s in at[3.0]] == [(s.start, s.end) for s in own]
    for slow, fast in zip(at[3.0], at[6.0], strict=True):
        assert slow.duration_ms == pytest.approx(2 * fast.duration_ms, rel=1e-3)
        assert slow.duration_ms == pytest.approx(
            slow.length * PAPER_SLEEVE.spacing_cm / 3.0 * 1000, rel=1e-3
        )


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


def test_the_example_design_with_speeds_loads() -> None:
    design = load_design(PAPER_DESIGN.parent / "speeds.toml")
    assert design.speeds == (3.0, 6.0, 12.0) and design.main_trials == 4 * 3 * 3 * 2
    assert [design.practice_speed_cm_s(p) for p in design.practice] == [3.0, 12.0]
