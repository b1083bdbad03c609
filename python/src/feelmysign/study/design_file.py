"""Read and check a study design file (TOML), reporting every problem at once.

See ``deploy/studies/paper.toml`` (the paper's design) and docs/study.md. A
design is checked completely before anything is sent: every shape's levels
must be drawable on the sleeve (segments allowed for that shape, or simplifier
settings that leave strokes of the recording), and no synonym may name two
shapes.
"""

from __future__ import annotations

import math
import uuid
from collections.abc import Callable
from functools import partial
from itertools import pairwise
from pathlib import Path
from typing import Any

from feelmysign.errors import DesignError, FeelMySignError
from feelmysign.input_files import MAX_DESIGN_BYTES, read_text
from feelmysign.layout import Layout, loads_toml
from feelmysign.plural import plural
from feelmysign.shapes import SHAPES
from feelmysign.simplify.registry import ALGORITHMS
from feelmysign.study.coding import normalise
from feelmysign.study.design import (
    RANDOMISATIONS,
    Design,
    Level,
    PracticeTrial,
    Questionnaire,
    Randomisation,
    Shape,
    Stimulus,
    Threshold,
    ThresholdDimension,
)
from feelmysign.study.problems import MISSING, Problems
from feelmysign.study.stimulus import at_speed, library_strokes, recorded_strokes, stimulus_layout
from feelmysign.study.threshold import check_fits

MAX_SHAPES = 24
MAX_LEVELS = 12
MAX_REPETITIONS = 20
MAX_LIKERT_POINTS = 11
MAX_SPEEDS = 8
SPEED_RANGE_CM_S = (0.5, 50.0)
_TOP = ("study", "stimulus", "shapes", "practice", "comfort", "questionnaire", "threshold")
_STUDY = ("name", "seed", "randomisation", "repetitions", "resolutions", "criterion", "guess_rate")


def load_design(path: str | Path) -> Design:
    """The design in ``path``; DesignError listing every problem, or naming the unreadable file."""
    file = Path(path)
    try:
        text = read_text(file, max_bytes=MAX_DESIGN_BYTES)
    except OSError as error:
        raise DesignError(
            str(path), [f"cannot read the file: {error.strerror or error}"]
        ) from error
    except UnicodeDecodeError as error:
        raise DesignError(
            str(path), [f"not UTF-8 text (byte {error.start}); save the design as UTF-8 TOML"]
        ) from None
    return parse_design(text, source=str(path), base_dir=file.resolve().parent)


def parse_design(text: str, *, source: str = "<design>", base_dir: Path = Path(".")) -> Design:
    nesting = "a design nests arrays and tables 3 levels deep"
    data = loads_toml(text, source, DesignError, nesting=nesting)
    problems = Problems(source)
    problems.unknown("", data, _TOP)
    study = problems.table("study", data.get("study", MISSING), required=True)
    problems.unknown("study", study, _STUDY)
    resolutions = problems.texts("study.resolutions", study.get("resolutions", MISSING))
    if len(resolutions) > MAX_LEVELS:
        problems.add("study.resolutions", f"at most {MAX_LEVELS} resolutions")
    if len(set(resolutions)) != len(resolutions):
        problems.add("study.resolutions", "each resolution needs its own label")
    stimulus = _stimulus(problems, data.get("stimulus", MISSING), base_dir)
    shapes = _shapes(problems, data.get("shapes", MISSING), resolutions, stimulus, base_dir)
    design = Design(
        name=problems.text("study.name", study.get("name", MISSING)) or "",
        seed=problems.integer("study.seed", study.get("seed", MISSING), 0, 2**63 - 1) or 0,
        randomisation=_randomisation(problems, study.get("randomisation", MISSING)),
        repetitions=problems.integer(
            "study.repetitions", study.get("repetitions", MISSING), 1, MAX_REPETITIONS
        )
        or 1,
        resolutions=resolutions,
        shapes=shapes,
        practice=_practice(
            problems, data.get("practice", []), shapes, resolutions, stimulus, base_dir
        ),
        questionnaire=_questionnaire(problems, data.get("questionnaire", MISSING)),
        comfort=_comfort(problems, data.get("comfort", {})),
        stimulus=stimulus,
        criterion=_number_or(problems, "study.criterion", study, 0.05, 0.99, 0.75),
        guess_rate=_number_or(problems, "study.guess_rate", study, 0.0, 0.5, 0.0),
        threshold=_threshold(problems, data.get("threshold", {})),
        source=source,
    )
    if design.guess_rate >= design.criterion:
        problems.add("study.criterion", "must be above study.guess_rate")
    try:
        check_fits(stimulus_layout(stimulus, base_dir), design.threshold)
    except FeelMySignError as error:
        problems.add("threshold", str(error))
    problems.raise_if_any()
    return design


def _number_or(
    problems: Problems, key: str, table: dict[str, Any], low: float, high: float, default: float
) -> float:
    value = problems.number(
        key, table.get(key.rsplit(".", 1)[-1], MISSING), low, high, required=False
    )
    return default if value is None else value


def _randomisation(problems: Problems, value: Any) -> Randomisation:
    chosen = problems.choice("study.randomisation", value, RANDOMISATIONS, "latin-square")
    return "shuffled-blocks" if chosen == "shuffled-blocks" else "latin-square"


def _stimulus(problems: Problems, value: Any, base_dir: Path) -> Stimulus:
    table = problems.table("stimulus", value)
    problems.unknown("stimulus", table, ("speed_cm_s", "margin", "intensity", "layout"))
    speeds = _speeds(problems, table.get("speed_cm_s", 5.0)) or (5.0,)
    margin = problems.number("stimulus.margin", table.get("margin", 0.0), 0.0, 1.0)
    intensity = problems.number(
        "stimulus.intensity", table.get("intensity", MISSING), 0.05, 1.0, required=False
    )
    layout = problems.text("stimulus.layout", table.get("layout", MISSING), required=False)
    # One speed is the design's speed; a list of two or more makes speed a factor.
    factor = speeds if len(speeds) > 1 else ()
    stimulus = Stimulus(speeds[0], margin or 0.0, intensity, layout, factor)
    try:
        stimulus_layout(stimulus, base_dir)
    except FeelMySignError as error:
        problems.add("stimulus.layout", str(error))
        return Stimulus(stimulus.speed_cm_s, stimulus.margin, intensity, None, factor)
    return stimulus


def _speeds(problems: Problems, value: Any) -> tuple[float, ...] | None:
    """``speed_cm_s``: one number, or a list of different speeds (speed as a factor)."""
    key = "stimulus.speed_cm_s"
    low, high = SPEED_RANGE_CM_S
    if not isinstance(value, list):
        speed = problems.number(key, value, low, high)
        return None if speed is None else (speed,)
    example = (
        f"one number from {low:g} to {high:g} cm/s, or a list of different ones (e.g. [3, 6, 12])"
    )
    if not value:
        problems.add(key, f"the list is empty; give {example}")
        return None
    if len(value) > MAX_SPEEDS:
        problems.add(
            key,
            f"at most {MAX_SPEEDS} speeds; got {len(value)}: each speed plays every shape x "
            "resolution x repetition again; keep the speeds the question needs",
        )
        return None
    speeds = [problems.number(f"{key}[{i}]", v, low, high) for i, v in enumerate(value)]
    if any(speed is None for speed in speeds):
        return None
    found = [float(speed) for speed in speeds if speed is not None]
    twice = sorted({speed for speed in found if found.count(speed) > 1})
    if twice:
        shown = ", ".join(f"{speed:g}" for speed in twice)
        problems.add(
            key,
            f"each speed once; {shown} cm/s is listed more than once in {value!r}: remove the "
            "copies (study.repetitions says how often each condition is played)",
        )
        return None
    return tuple(found)


def _drawable(
    problems: Problems,
    where: str,
    what: str,
    speeds: tuple[float, ...],
    make: Callable[[float], object],
    layout: Layout,
) -> bool:
    """``make(speed)`` gives strokes the sleeve plays at every speed of ``speeds``: a slow speed
    can make a stroke last longer than the sleeve allows. One problem per level, naming it
    (``what``) and the slowest speed it plays at."""
    for speed in speeds:
        try:
            make(speed)
        except FeelMySignError:
            slowest = _slowest_speed(make, speed)
            allowed = (
                f"the slowest speed it plays at is {slowest:g} cm/s: give that speed or a "
                "faster one"
                if slowest is not None
                else f"no speed up to {SPEED_RANGE_CM_S[1]:g} cm/s plays it"
            )
            problems.add(
                where,
                f"{what} is too slow at {speed:g} cm/s: a stroke would last longer than the "
                f"sleeve plays one ({layout.max_stroke_duration_ms:g} ms, the layout's "
                f"max_stroke_duration_ms); {allowed} (or more segments)",
            )
            return False
    return True


_SPEED_STEP_CM_S = 0.1  # the slowest allowed speed is rounded up to this step


def _slowest_speed(make: Callable[[float], object], too_slow_cm_s: float) -> float | None:
    """The slowest speed, in steps of 0.1 cm/s above ``too_slow_cm_s``, at which ``make``
    succeeds (a faster speed only shortens the strokes); None when even the fastest allowed
    fails."""

    def plays(step: int) -> bool:
        try:
            make(step * _SPEED_STEP_CM_S)
        except FeelMySignError:
            return False
        return True

    low = math.floor(too_slow_cm_s / _SPEED_STEP_CM_S)  # fails (at or below the slow speed)
    high = round(SPEED_RANGE_CM_S[1] / _SPEED_STEP_CM_S)
    if not plays(high):
        return None
    while high - low > 1:
        middle = (low + high) // 2
        if plays(middle):
            high = middle
        else:
            low = middle
    return round(high * _SPEED_STEP_CM_S, 6)


def _shapes(
    problems: Problems,
    value: Any,
    resolutions: tuple[str, ...],
    stimulus: Stimulus,
    base_dir: Path,
) -> tuple[Shape, ...]:
    items = problems.array("shapes", value)
    if items is None:
        return ()
    if not 1 <= len(items) <= MAX_SHAPES:
        problems.add("shapes", f"give 1 to {MAX_SHAPES} [[shapes]]; got {len(items)}")
    shapes: list[Shape] = []
    for index, item in enumerate(items):
        shape = _shape(problems, f"shapes[{index}]", item, resolutions, stimulus, base_dir)
        if shape is not None:
            shapes.append(shape)
    _check_names_and_synonyms(problems, shapes)
    return tuple(shapes)


def _shape(
    problems: Problems,
    key: str,
    item: Any,
    resolutions: tuple[str, ...],
    stimulus: Stimulus,
    base_dir: Path,
) -> Shape | None:
    levels = len(resolutions)
    table = problems.table(key, item, required=True)
    problems.unknown(
        key, table, ("name", "segments", "recording", "simplifier", "settings", "synonyms")
    )
    name = problems.text(f"{key}.name", table.get("name", MISSING), max_chars=40)
    synonyms = problems.texts(f"{key}.synonyms", table.get("synonyms", []))
    if name is None:
        return None
    words = tuple(dict.fromkeys([normalise(name), *(normalise(s) for s in synonyms)]))
    recording = problems.text(f"{key}.recording", table.get("recording", MISSING), required=False)
    if recording is None:
        found = _library_levels(problems, key, name, table.get("segments", MISSING), levels)
        if found is not None and not _library_drawable(
            problems, key, name, found, resolutions, stimulus, base_dir
        ):
            return None
    else:
        found = _recorded_levels(problems, key, table, recording, resolutions, stimulus, base_dir)
    if found is not None and not _coarse_to_fine(problems, key, recording, found):
        return None
    return None if found is None else Shape(name, found, words, recording)


def _coarse_to_fine(
    problems: Problems, key: str, recording: str | None, levels: tuple[Level, ...]
) -> bool:
    """The levels must gain strokes from each resolution to the next: the analysis reads
    accuracy against strokes, and a level that repeats or goes back is a mistyped design."""
    strokes = [level.strokes for level in levels]
    if all(a < b for a, b in pairwise(strokes)):
        return True
    shown = ", ".join(map(str, strokes))
    if recording is None:
        problems.add(
            f"{key}.segments",
            f"must increase strictly from coarse to fine (each more than the one before); "
            f"got {shown}: list each resolution once, fewest segments first",
        )
    else:
        problems.add(
            f"{key}.settings",
            f"the settings must give strictly more strokes from coarse to fine (each more "
            f"than the one before); they gave {shown} strokes: order the settings from "
            "coarsest to finest and change any that give the same count",
        )
    return False


def _library_drawable(
    problems: Problems,
    key: str,
    name: str,
    levels: tuple[Level, ...],
    resolutions: tuple[str, ...],
    stimulus: Stimulus,
    base_dir: Path,
) -> bool:
    layout = _layout_or_none(stimulus, base_dir)
    if layout is None:
        return True  # the layout's own problem is reported
    return all(
        _drawable(
            problems,
            f"{key}.segments[{i}]",
            f"{name} at resolution {resolution!r} ({plural(level.strokes, 'segment')})",
            stimulus.speeds,
            partial(library_strokes, name, level.strokes, stimulus, layout, "-"),
            layout,
        )
        for i, (level, resolution) in enumerate(zip(levels, resolutions, strict=True))
    )


def _layout_or_none(stimulus: Stimulus, base_dir: Path) -> Layout | None:
    try:
        return stimulus_layout(stimulus, base_dir)
    except FeelMySignError:
        return None


def _library_levels(
    problems: Problems, key: str, name: str, value: Any, levels: int
) -> tuple[Level, ...] | None:
    spec = SHAPES.get(name)
    if spec is None:
        problems.add(
            f"{key}.name",
            f"{name!r} is not a library shape ({', '.join(SHAPES)}); for a drawing of your "
            "own give recording = 'file.json' with simplifier and settings",
        )
        return None
    segments = problems.array(f"{key}.segments", value)
    if segments is None:
        return None
    if len(segments) != levels:
        problems.add(f"{key}.segments", f"give one per resolution ({levels}); got {len(segments)}")
        return None
    out = []
    for i, count in enumerate(segments):
        if not isinstance(count, int) or isinstance(count, bool) or not spec.accepts(count):
            problems.add(f"{key}.segments[{i}]", f"a {name} takes {spec.allowed()}; got {count!r}")
            return None
        out.append(Level(strokes=count, segments=count))
    return tuple(out)


def _recorded_levels(
    problems: Problems,
    key: str,
    table: dict[str, Any],
    recording: str,
    resolutions: tuple[str, ...],
    stimulus: Stimulus,
    base_dir: Path,
) -> tuple[Level, ...] | None:
    levels = len(resolutions)
    simplifier = problems.choice(
        f"{key}.simplifier", table.get("simplifier", MISSING), tuple(ALGORITHMS), "window"
    )
    settings = problems.array(f"{key}.settings", table.get("settings", MISSING))
    if simplifier is None or settings is None:
        return None
    if len(settings) != levels:
        problems.add(f"{key}.settings", f"give one per resolution ({levels}); got {len(settings)}")
        return None
    layout = stimulus_layout(stimulus, base_dir)
    out = []
    for i, overrides in enumerate(settings):
        where = f"{key}.settings[{i}]"
        if not isinstance(overrides, dict):
            problems.add(
                where, "must be a table of the simplifier's settings, e.g. {max_error = 0.5}"
            )
            return None
        specs = ALGORITHMS[simplifier].specs
        unknown = [name for name in overrides if name not in specs]
        if unknown:
            problems.add(
                where, f"{', '.join(unknown)}: not a {simplifier} setting ({', '.join(specs)})"
            )
            return None
        try:
            for name, setting in overrides.items():
                specs[name].check(setting)
            strokes = recorded_strokes(
                base_dir / recording, simplifier, overrides, stimulus, layout, str(uuid.uuid4())
            )
        except FeelMySignError as error:
            problems.add(where, str(error))
            return None
        # Speed a factor: the drawing is redrawn at each speed (stimulus.trial_strokes).
        speeds = stimulus.speeds_cm_s
        what = f"{recording} at resolution {resolutions[i]!r} ({plural(len(strokes), 'stroke')})"
        redraw = partial(at_speed, strokes, layout=layout)
        if not _drawable(problems, where, what, speeds, redraw, layout):
            return None
        out.append(Level(len(strokes), simplifier=simplifier, settings=dict(overrides)))
    return tuple(out)


def _check_names_and_synonyms(problems: Problems, shapes: list[Shape]) -> None:
    owners: dict[str, str] = {}
    seen: set[str] = set()
    for shape in shapes:
        if shape.name in seen:
            continue  # reported once, with every listing, below
        seen.add(shape.name)
        listed = sum(other.name == shape.name for other in shapes)
        if listed > 1:
            problems.add(
                "shapes",
                f"{shape.name!r} is listed {listed} times: give each shape once, with one "
                "entry per resolution in its segments (or settings)",
            )
        for word in shape.synonyms:
            owner = owners.setdefault(word, shape.name)
            if owner != shape.name:
                problems.add(
                    f"shapes ({shape.name})",
                    f"synonym {word!r} also names {owner!r}: an answer must point to one shape",
                )


def _practice(
    problems: Problems,
    value: Any,
    shapes: tuple[Shape, ...],
    resolutions: tuple[str, ...],
    stimulus: Stimulus,
    base_dir: Path,
) -> tuple[PracticeTrial, ...]:
    """Library shapes at ``segments``, or the design's recorded drawings at ``resolution``; at
    their own ``speed_cm_s``, or the design's first speed."""
    recorded = {shape.name: shape for shape in shapes if shape.recording is not None}
    items = problems.array("practice", value, required=False) or []
    layout = _layout_or_none(stimulus, base_dir)
    out = []
    for index, item in enumerate(items):
        key = f"practice[{index}]"
        table = problems.table(key, item, required=True)
        problems.unknown(key, table, ("shape", "segments", "resolution", "speed_cm_s"))
        names = (*SHAPES, *recorded)
        name = problems.choice(f"{key}.shape", table.get("shape", MISSING), names, "")
        own = table.get("speed_cm_s", MISSING)
        speed = problems.number(f"{key}.speed_cm_s", own, *SPEED_RANGE_CM_S, required=False)
        if not name or (own is not MISSING and speed is None):
            if name == "":
                problems.add(f"{key}.shape", f"missing; give one of {', '.join(names)}")
            continue
        played_at = stimulus.speed_cm_s if speed is None else speed
        if name in recorded:
            if "segments" in table:
                problems.add(
                    f"{key}.segments",
                    f"{name!r} is a recorded drawing: give its resolution "
                    f"({', '.join(resolutions)}) instead of segments",
                )
                continue
            label = table.get("resolution", resolutions[-1] if resolutions else "")
            if label not in resolutions:
                problems.add(f"{key}.resolution", f"one of {', '.join(resolutions)}; got {label!r}")
                continue
            level = resolutions.index(label)
            chosen = recorded[name].levels[level]
            if speed is not None and layout is not None and chosen.simplifier is not None:
                # Its own speed: the drawing is redrawn at it (stimulus.trial_strokes).
                path = base_dir / str(recorded[name].recording)
                strokes = recorded_strokes(
                    path, chosen.simplifier, chosen.settings, stimulus, layout, "-"
                )
                redrawn = partial(at_speed, strokes, layout=layout)
                what = f"practice trial {index + 1} ({name} at resolution {label!r})"
                if not _drawable(problems, f"{key}.speed_cm_s", what, (speed,), redrawn, layout):
                    continue
            out.append(PracticeTrial(name, chosen.strokes, level, speed))
            continue
        if "resolution" in table:
            problems.add(
                f"{key}.resolution",
                f"only for a recorded drawing of the design; {name!r} takes segments",
            )
            continue
        spec = SHAPES[name]
        segments = table.get("segments", spec.default_segments)
        if (
            not isinstance(segments, int)
            or isinstance(segments, bool)
            or not spec.accepts(segments)
        ):
            problems.add(f"{key}.segments", f"a {name} takes {spec.allowed()}; got {segments!r}")
            continue
        if layout is not None and not _drawable(
            problems,
            f"{key}.segments" if speed is None else f"{key}.speed_cm_s",
            f"practice trial {index + 1} ({name}, {plural(segments, 'segment')})",
            (played_at,),
            partial(library_strokes, name, segments, stimulus, layout, "-"),
            layout,
        ):
            continue
        out.append(PracticeTrial(name, segments, None, speed))
    return tuple(out)


def _comfort(problems: Problems, value: Any) -> tuple[str, ...]:
    table = problems.table("comfort", value)
    problems.unknown("comfort", table, ("questions",))
    default = ["Does the sleeve sit comfortably?", "Can you feel the test buzz clearly?"]
    return problems.texts("comfort.questions", table.get("questions", default))


def _questionnaire(problems: Problems, value: Any) -> Questionnaire:
    table = problems.table("questionnaire", value, required=True)
    problems.unknown("questionnaire", table, ("points", "labels", "items"))
    points = problems.integer("questionnaire.points", table.get("points", 5), 2, MAX_LIKERT_POINTS)
    labels = problems.texts("questionnaire.labels", table.get("labels", []), required=False)
    items = problems.texts("questionnaire.items", table.get("items", MISSING))
    if points is not None and labels and len(labels) != points:
        problems.add("questionnaire.labels", f"give one label per point ({points}) or none")
    if not items:
        problems.add("questionnaire.items", "give at least one Likert item")
    return Questionnaire(items, points or 5, labels)


def _threshold(problems: Problems, value: Any) -> Threshold:
    table = problems.table("threshold", value)
    problems.unknown(
        "threshold",
        table,
        ("trials", "max_trials", "stop_width", "lapse_rate", "length", "duration"),
    )
    trials = problems.integer("threshold.trials", table.get("trials", 40), 5, 500) or 40
    max_trials = problems.integer("threshold.max_trials", table.get("max_trials", trials), 5, 1000)
    if max_trials is not None and max_trials < trials:
        problems.add("threshold.max_trials", f"must be at least threshold.trials ({trials})")
    length = _dimension(
        problems, "threshold.length", table.get("length", {}), (0.1, 2.0, 25), "duration_ms", 500.0
    )
    duration = _dimension(
        problems, "threshold.duration", table.get("duration", {}), (20.0, 1500.0, 25), "length", 2.0
    )
    return Threshold(
        trials=trials,
        max_trials=max_trials or trials,
        stop_width=problems.number("threshold.stop_width", table.get("stop_width", 0.0), 0, 10)
        or 0.0,
        lapse_rate=problems.number("threshold.lapse_rate", table.get("lapse_rate", 0.02), 0, 0.2)
        or 0.0,
        length=length,
        duration=duration,
    )


def _dimension(
    problems: Problems,
    key: str,
    value: Any,
    defaults: tuple[float, float, int],
    fixed_name: str,
    fixed_default: float,
) -> ThresholdDimension:
    table = problems.table(key, value)
    problems.unknown(key, table, ("minimum", "maximum", "steps", fixed_name))
    low = problems.number(f"{key}.minimum", table.get("minimum", defaults[0]), 1e-3, 1e5)
    high = problems.number(f"{key}.maximum", table.get("maximum", defaults[1]), 1e-3, 1e5)
    steps = problems.integer(f"{key}.steps", table.get("steps", defaults[2]), 5, 200)
    fixed = problems.number(f"{key}.{fixed_name}", table.get(fixed_name, fixed_default), 1e-3, 1e5)
    if low is not None and high is not None and low >= high:
        problems.add(key, f"minimum ({low:g}) must be below maximum ({high:g})")
    return ThresholdDimension(
        low or defaults[0], high or defaults[1], steps or defaults[2], fixed or fixed_default
    )
