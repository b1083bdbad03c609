"""Do shapes differ in the resolution they need (SQ2.4)? A test valid at every number of
participants, and a mixed-effects model for the size of each difference.

- The test: a sign-flip permutation test over participants (Fisher's randomisation test
  of a mean; Good 2005, ch. 3). A logistic GLM without shape (``correct ~
  log2(strokes) + C(participant)``, statsmodels) gives each trial's expected accuracy
  at its number of strokes for that participant; each participant's mean residual per
  shape, centred over the shapes, is their *shape profile* (how much better or worse
  than the strokes and their own overall level predict each shape was for them).
  Fitted to everyone at once without the participant term, the model's curve sits
  between able and less able participants, so each profile carried its owner's ability
  (near the curve's steep part, not at ceiling), which sign flips count as spread and
  the data's mean does not: the test was conservative (0.020 at 24 participants). The
  direction of the shapes' mean log2(strokes), which the shared slope's fit pins, is
  left out of the profiles for the same reason. With no shape effect, a profile is as
  likely as its negative, so flipping the signs of whole participants' profiles gives
  the null distribution of the statistic (the squared length of the mean profile).
  Participants, not trials, are the unit: a participant's answers are not
  independent, and a test that treats them as such (or a cluster-robust Wald test with
  few clusters) claims differences that are not there. Every flip is enumerated up to
  ``EXACT_UP_TO`` participants; above, ``FLIPS`` random ones (seeded).
- Refused below ``MIN_PARTICIPANTS``, with the reason: there the test cannot reach
  p < 0.05 whatever the data.
- The mixed-effects model (participant as a random intercept), ``BinomialBayesMixedGLM``
  fitted by variational Bayes: shape effects in log odds with posterior SDs, and how
  much participants differ. Descriptive only (the variational fit gives no likelihood
  to test with); it may fail (a shape always recognised), and the report says so.
"""

from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import statsmodels.api as sm
from statsmodels.genmod.bayes_mixed_glm import BinomialBayesMixedGLM

from feelmysign.plural import plural

FORMULA = "correct ~ C(shape, Treatment(reference=@reference)) + log2_strokes"
# Each participant's own intercept (how well they do overall), one slope for everyone.
NULL_FORMULA = "correct ~ log2_strokes + C(participant)"
# The sign-flip test's smallest possible p is 2 / 2^n with n participants (the observed
# profiles and their exact negative give the same statistic). With 5 that is 0.0625:
# the test could never report a difference at the 5% level, so it is not run below 6.
MIN_PARTICIPANTS = 6
# The speed test's own minimum: on simulated studies with no speed effect (paper's shapes x 3
# speeds, 200 each; bench.study_calibration --speed-runs) it found one in 8.5% (5.4 to 13.2)
# of studies of 8 participants, and in 3.5% of 12.
MIN_SPEED_PARTICIPANTS = 12
EXACT_UP_TO = 14  # 2^14 = 16384 flips, every one
FLIPS = 9999  # random flips above that (the observed one is added: p >= 1 / 10000)


@dataclass(frozen=True)
class ShapeEffect:
    shape: str
    log_odds: float  # against the reference shape, at equal strokes
    sd: float


@dataclass(frozen=True)
class ShapeTest:
    method: str
    participants: int
    shapes: int
    statistic: float | None  # squared length of the mean shape profile (accuracy units^2)
    p: float | None
    flips: int  # sign patterns the p-value is counted over (0: not run)
    refused: str | None  # why no test is reported, when none is
    participants_needed: int


@dataclass(frozen=True)
class SpeedEffect:
    speed_cm_s: float
    log_odds: float  # against the first speed of the design, at equal shape and strokes
    sd: float


@dataclass(frozen=True)
class SpeedTest:
    """The shape test's method over the speeds (``speed_flip_test``)."""

    method: str
    participants: int
    speeds: int
    statistic: float | None  # squared length of the mean speed profile (accuracy units^2)
    p: float | None
    flips: int
    refused: str | None
    participants_needed: int


@dataclass(frozen=True)
class ModelResult:
    reference: str
    mixed: list[ShapeEffect]
    participant_sd: float  # random intercept SD (log odds)
    slope_per_doubling: float
    test: ShapeTest
    note: str
    # Speed a factor of the design (a ``speed`` column): its test, and its effects in the
    # mixed model (which then has speed as a fixed effect too); else None and empty.
    speed_test: SpeedTest | None = None
    speed_effects: list[SpeedEffect] = field(default_factory=list)
    reference_speed_cm_s: float | None = None


def shape_differences(frame: pd.DataFrame, *, seed: int = 0) -> ModelResult:
    """``frame`` has columns participant, shape, segments, correct (0/1), main trials only;
    and ``speed`` (cm/s) when speed is a factor of the design."""
    data = frame.assign(log2_strokes=np.log2(frame["segments"].astype(float)))
    data["correct"] = data["correct"].astype(float)
    # The best-recognised shape as reference: the other effects are then how much harder each is.
    reference = str(data.groupby("shape")["correct"].mean().idxmax())
    formula = FORMULA.replace("@reference", repr(reference))
    shapes = sorted(s for s in data["shape"].unique() if s != reference)
    # Speeds are crossed with shape x strokes within every participant: the shape test's
    # profiles hold the same mix of speeds for every shape, so it needs no speed term.
    test = sign_flip_test(data, seed=seed)
    if "speed" not in data or data["speed"].nunique() < 2:
        mixed, participant_sd, slope, note, _ = _mixed(formula, data, shapes)
        return ModelResult(reference, mixed, participant_sd, slope, test, note)
    speeds = sorted(float(v) for v in data["speed"].unique())
    first = speeds[0]
    formula += f" + C(speed, Treatment(reference={first!r}))"
    mixed, participant_sd, slope, note, effects = _mixed(formula, data, shapes, speeds[1:])
    return ModelResult(
        reference,
        mixed,
        participant_sd,
        slope,
        test,
        note,
        speed_flip_test(data, seed=seed),
        effects,
        first,
    )


def null_design(data: pd.DataFrame) -> np.ndarray:
    """The design matrix of ``NULL_FORMULA``, column for column and bit for bit as the
    formula interface (patsy) builds it: intercept, one treatment column per participant
    after the first in sorted order, log2(strokes); column-major, as patsy hands it to the
    fit, so that the fit is the same to the last bit. Built directly: the formula's parsing
    and checks cost more than the fit itself in the calibration's thousands of studies."""
    participants = np.asarray(sorted(data["participant"].unique()))
    codes = pd.Categorical(data["participant"], categories=participants).codes
    dummies = codes[:, None] == np.arange(1, len(participants))[None, :]
    columns = [np.ones(len(data)), *dummies.T.astype(float), data["log2_strokes"].to_numpy(float)]
    return np.asfortranarray(np.column_stack(columns))


def shape_profiles(data: pd.DataFrame) -> np.ndarray:
    """Per participant (rows) and shape (columns): the mean of correct minus the accuracy a
    shape-free logistic model of log2(strokes) with the participant's own intercept expects,
    centred over the shapes, less its part along the shapes' mean log2(strokes)."""
    if data["correct"].nunique() > 1:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a near-perfect fit warns; its values are still right
            glm = sm.GLM(
                data["correct"].to_numpy(float), null_design(data), family=sm.families.Binomial()
            ).fit()
        expected = np.asarray(glm.fittedvalues, dtype=float)
    else:  # every answer the same: the model is that constant
        expected = data["correct"].to_numpy(float)
    residual = data.assign(residual=data["correct"].to_numpy(float) - expected)
    table = residual.pivot_table(
        index="participant", columns="shape", values="residual", aggfunc="mean"
    )
    # A shape a participant has no coded answer for adds nothing to their profile.
    profile = table.to_numpy(float)
    profile = np.where(np.isnan(profile), np.nanmean(profile, axis=1, keepdims=True), profile)
    profile = profile - profile.mean(axis=1, keepdims=True)
    # The shared slope's fit sets the residuals' sum weighted by log2(strokes) to zero, which
    # pins everyone's mean profile along the shapes' mean log2(strokes): there the data's own
    # mean cannot vary, while sign flips would; that direction is left out of the test.
    levels = data.groupby("shape")["log2_strokes"].mean().reindex(table.columns).to_numpy(float)
    direction = levels - levels.mean()
    if np.linalg.norm(direction) > 0:
        direction /= np.linalg.norm(direction)
        profile = profile - np.outer(profile @ direction, direction)
    return np.asarray(profile)


def sign_flip_test(data: pd.DataFrame, *, seed: int = 0) -> ShapeTest:
    participants, shapes = int(data["participant"].nunique()), int(data["shape"].nunique())
    method = "sign-flip permutation test over participants"
    if participants < MIN_PARTICIPANTS:
        reason = (
            f"{plural(participants, 'participant')}: the test over participants needs at least "
            f"{MIN_PARTICIPANTS}; with fewer, its smallest possible p is 2/2^n "
            f"= {2 / 2**participants:.3g}, so it could never show a difference"
        )
        return ShapeTest(method, participants, shapes, None, None, 0, reason, MIN_PARTICIPANTS)
    observed, p, flips = _flip(shape_profiles(data), seed)
    return ShapeTest(method, participants, shapes, observed, p, flips, None, MIN_PARTICIPANTS)


def _flip(profile: np.ndarray, seed: int) -> tuple[float, float, int]:
    """The statistic (squared length of the mean profile), its p over sign flips of whole
    participants (rows), and the number of sign patterns counted."""
    participants = profile.shape[0]
    if participants <= EXACT_UP_TO:
        signs = np.array(list(itertools.product((1.0, -1.0), repeat=participants)))
    else:
        rng = np.random.default_rng(seed)
        signs = np.vstack([np.ones(participants), rng.choice((1.0, -1.0), (FLIPS, participants))])
    means = signs @ profile / participants
    statistics = np.sum(means * means, axis=1)
    observed = float(statistics[0])  # the first sign pattern is all +1: the data as measured
    # A relative tolerance: sums in another order differ in the last bits.
    p = float(np.mean(statistics >= observed * (1 - 1e-9)))
    assert math.isfinite(observed) and observed >= 0.0
    return observed, p, len(signs)


def speed_profiles(data: pd.DataFrame) -> np.ndarray:
    """Per participant (rows) and speed (columns, ascending): the mean of correct minus the
    accuracy the shape test's speed-free model expects, centred over the speeds.

    Nothing of the model's fit is taken out along the speeds, unlike the shapes' mean
    log2(strokes): every speed plays the same shapes at the same strokes, so the expected
    accuracies average alike at every speed and the profile is, to within unclear answers
    left out, the participant's share correct per speed less their mean over speeds."""
    if data["correct"].nunique() > 1:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            glm = sm.GLM(
                data["correct"].to_numpy(float), null_design(data), family=sm.families.Binomial()
            ).fit()
        expected = np.asarray(glm.fittedvalues, dtype=float)
    else:
        expected = data["correct"].to_numpy(float)
    residual = data.assign(residual=data["correct"].to_numpy(float) - expected)
    table = residual.pivot_table(
        index="participant", columns="speed", values="residual", aggfunc="mean"
    )
    profile = table.to_numpy(float)
    profile = np.where(np.isnan(profile), np.nanmean(profile, axis=1, keepdims=True), profile)
    return np.asarray(profile - profile.mean(axis=1, keepdims=True))


def speed_flip_test(data: pd.DataFrame, *, seed: int = 0) -> SpeedTest:
    """Does accuracy differ between speeds at equal shape and strokes? The shape test's
    sign-flip over participants, with per-speed profiles (``speed_profiles``). With no speed
    effect a participant's speed profile is as likely as its negative: exactly so with two
    speeds (their two shares are exchangeable), as for the shapes with more."""
    participants, speeds = int(data["participant"].nunique()), int(data["speed"].nunique())
    method = "sign-flip permutation test over participants"
    needed = MIN_SPEED_PARTICIPANTS
    if participants < needed:
        reason = (
            f"{plural(participants, 'participant')}: the speed test needs at least {needed}; "
            "with 8, on simulated studies with no speed effect, it found one in 8.5% of them "
            "(docs/study.md), more than the 5% it should"
        )
        return SpeedTest(method, participants, speeds, None, None, 0, reason, needed)
    observed, p, flips = _flip(speed_profiles(data), seed)
    return SpeedTest(method, participants, speeds, observed, p, flips, None, needed)


def _mixed(
    formula: str, data: pd.DataFrame, shapes: list[str], speeds: list[float] | None = None
) -> tuple[list[ShapeEffect], float, float, str, list[SpeedEffect]]:
    """The mixed model's shape effects, participant SD, slope and how it was fitted; and,
    with ``speeds`` (the design's after its first, a term of ``formula``), their effects."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = BinomialBayesMixedGLM.from_formula(
                formula, {"participant": "0 + C(participant)"}, data
            )
            result = model.fit_vb()
    except Exception as error:  # descriptive only: the report says why it is missing
        return [], float("nan"), float("nan"), f"mixed model not fitted: {error}", []
    names = list(model.exog_names)
    effects = []
    for shape in shapes:
        index = next(i for i, n in enumerate(names) if n.endswith(f"[T.{shape}]"))
        effects.append(ShapeEffect(shape, float(result.fe_mean[index]), float(result.fe_sd[index])))
    speed_effects = []
    for speed in speeds or []:
        index = next(i for i, n in enumerate(names) if n.endswith(f"[T.{speed!r}]"))
        speed_effects.append(
            SpeedEffect(speed, float(result.fe_mean[index]), float(result.fe_sd[index]))
        )
    slope = float(result.fe_mean[names.index("log2_strokes")])
    participant_sd = float(np.exp(result.vcp_mean[0]))
    note = "mixed model fitted by variational Bayes (fit_vb)"
    return effects, participant_sd, slope, note, speed_effects
