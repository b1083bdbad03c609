"""A recognition study's design, as read from its TOML file (``design_file.load_design``).

The study is the one "Can You Feel My Sign?" designed in its section 6 and
could not run: shapes sent to the sleeve at several resolutions (numbers of
strokes), the wearer naming what they felt without options (SQ2.3, SQ2.4),
with the comfort check before and the questionnaire after (section 6.1), and
a threshold procedure for the shortest stroke (SQ2.2). Everything here is
plain data; ``to_json`` gives the design as exported beside the answers.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Literal

Randomisation = Literal["latin-square", "shuffled-blocks"]
RANDOMISATIONS: tuple[Randomisation, ...] = ("latin-square", "shuffled-blocks")


@dataclass(frozen=True)
class Level:
    """One resolution of one shape: how it is drawn, and the strokes it has.

    ``segments`` for a library shape; ``simplifier`` + ``settings`` for a recorded
    drawing (``strokes`` is then what the simplifier gave, computed at load).
    """

    strokes: int
    segments: int | None = None
    simplifier: str | None = None
    settings: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Shape:
    """A shape of the study: from the library (``feelmysign.shapes``) or a recorded drawing."""

    name: str
    levels: tuple[Level, ...]  # one per resolution of the design, coarse to fine
    synonyms: tuple[str, ...]  # words a participant may use for it (its name included)
    recording: str | None = None  # path of a recorded drawing, as written in the file


@dataclass(frozen=True)
class PracticeTrial:
    """A trial before the measured ones, not analysed: a library shape at ``segments``, or a
    recorded drawing of the design at resolution ``level`` (``segments`` is then its count)."""

    shape: str
    segments: int
    level: int | None = None
    speed_cm_s: float | None = None  # its own speed; None: the design's first speed


@dataclass(frozen=True)
class Questionnaire:
    """Likert items asked after the trials (section 6.1 step 4)."""

    items: tuple[str, ...]
    points: int = 5
    labels: tuple[str, ...] = ()  # one per point when given, lowest first


@dataclass(frozen=True)
class Stimulus:
    """How every shape is drawn on the sleeve.

    ``speed_cm_s`` is the design's one speed, or the first of ``speeds_cm_s`` when speed is a
    factor of the design (two or more speeds, each crossed with shape x resolution x
    repetition; empty when there is one speed).
    """

    speed_cm_s: float
    margin: float
    intensity: float | None  # None: the sleeve's default
    layout: str | None  # a sleeve layout file; None: the paper's sleeve
    speeds_cm_s: tuple[float, ...] = ()

    @property
    def speeds(self) -> tuple[float, ...]:
        """Every speed of the design, in the order listed (one for a design of one speed)."""
        return self.speeds_cm_s or (self.speed_cm_s,)


@dataclass(frozen=True)
class ThresholdDimension:
    """The range QUEST+ searches for one of SQ2.2's thresholds (log-spaced grid)."""

    minimum: float
    maximum: float
    steps: int
    fixed: float  # the other dimension's value while this one varies


@dataclass(frozen=True)
class Threshold:
    """The 4AFC direction task for SQ2.2 (shortest stroke length and duration)."""

    trials: int
    max_trials: int
    stop_width: float  # stop early once the 95% interval's width / threshold is below this
    lapse_rate: float
    length: ThresholdDimension  # grid units; fixed = duration_ms
    duration: ThresholdDimension  # ms; fixed = length in grid units


@dataclass(frozen=True)
class Design:
    name: str
    seed: int
    randomisation: Randomisation
    repetitions: int
    resolutions: tuple[str, ...]  # labels of the levels, coarse to fine
    shapes: tuple[Shape, ...]
    practice: tuple[PracticeTrial, ...]
    questionnaire: Questionnaire
    comfort: tuple[str, ...]  # yes/no questions of the comfort check (section 6.1 step 2)
    stimulus: Stimulus
    criterion: float  # accuracy at which the needed resolution is read off (SQ2.3)
    guess_rate: float  # chance of naming the shape by luck (free answers: near 0)
    threshold: Threshold
    source: str = "<design>"

    def shape(self, name: str) -> Shape:
        for shape in self.shapes:
            if shape.name == name:
                return shape
        raise KeyError(name)

    @property
    def shape_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.shapes)

    @property
    def speeds(self) -> tuple[float, ...]:
        return self.stimulus.speeds

    @property
    def speed_is_factor(self) -> bool:
        """Two or more speeds, crossed with the other factors: trials, exports and the
        analysis then carry each trial's speed."""
        return len(self.stimulus.speeds) > 1

    @property
    def main_trials(self) -> int:
        return len(self.shapes) * len(self.resolutions) * len(self.speeds) * self.repetitions

    def practice_speed_cm_s(self, practice: PracticeTrial) -> float:
        return self.speeds[0] if practice.speed_cm_s is None else practice.speed_cm_s

    def to_json(self) -> dict[str, Any]:
        """The design as exported (design.json): ``stimulus.speed_cm_s`` one number, or the
        list of speeds as the design file gives it; a practice trial's speed when it has one
        of its own."""
        data = asdict(self)
        data.pop("source")
        stimulus = data["stimulus"]
        speeds = stimulus.pop("speeds_cm_s")
        if speeds:
            stimulus["speed_cm_s"] = list(speeds)
        for practice in data["practice"]:
            if practice["speed_cm_s"] is None:
                del practice["speed_cm_s"]
        return data
