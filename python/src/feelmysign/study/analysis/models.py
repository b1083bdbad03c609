"""Do shapes differ in the resolution they need (SQ2.4)? Two logistic models of correct
answers on shape and log2(strokes), both fitted with statsmodels:

- the mixed-effects model (participant as a random intercept), ``BinomialBayesMixedGLM``
  fitted by variational Bayes: shape effects with posterior SDs, and how much
  participants differ;
- the test: a GLM with standard errors robust to clustering by participant (a
  participant's answers are not independent), and a Wald chi-square test that all
  shape effects are zero. Used for the p-value because the variational fit gives
  no likelihood to test with, and it stays stable when a shape is always (or never)
  recognised, where mixed-model fits by Laplace approximation fail.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
import statsmodels.api as sm
import statsmodels.formula.api as smf
from statsmodels.genmod.bayes_mixed_glm import BinomialBayesMixedGLM

FORMULA = "correct ~ C(shape, Treatment(reference=@reference)) + log2_strokes"


@dataclass(frozen=True)
class ShapeEffect:
    shape: str
    log_odds: float  # against the reference shape, at equal strokes
    sd: float


@dataclass(frozen=True)
class ModelResult:
    reference: str
    mixed: list[ShapeEffect]
    participant_sd: float  # random intercept SD (log odds)
    slope_per_doubling: float
    wald_chi2: float
    wald_df: int
    wald_p: float
    note: str


def shape_differences(frame: pd.DataFrame) -> ModelResult:
    """``frame`` has columns participant, shape, segments, correct (0/1), main trials only."""
    data = frame.assign(log2_strokes=np.log2(frame["segments"].astype(float)))
    data["correct"] = data["correct"].astype(float)
    # The best-recognised shape as reference: the other effects are then how much harder each is.
    reference = str(data.groupby("shape")["correct"].mean().idxmax())
    formula = FORMULA.replace("@reference", repr(reference))
    shapes = sorted(s for s in data["shape"].unique() if s != reference)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        glm = smf.glm(formula, data, family=sm.families.Binomial()).fit(
            cov_type="cluster", cov_kwds={"groups": pd.factorize(data["participant"])[0]}
        )
        names = [n for n in glm.params.index if n.startswith("C(shape")]
        if names:
            contrast = np.zeros((len(names), len(glm.params)))
            for row, name in enumerate(names):
                contrast[row, list(glm.params.index).index(name)] = 1.0
            wald = glm.wald_test(contrast, scalar=True)
            chi2, df, p = float(wald.statistic), len(names), float(wald.pvalue)
        else:
            chi2, df, p = 0.0, 0, 1.0
        mixed, participant_sd, slope, note = _mixed(formula, data, shapes)
    return ModelResult(reference, mixed, participant_sd, slope, chi2, df, p, note)


def _mixed(
    formula: str, data: pd.DataFrame, shapes: list[str]
) -> tuple[list[ShapeEffect], float, float, str]:
    try:
        model = BinomialBayesMixedGLM.from_formula(
            formula, {"participant": "0 + C(participant)"}, data
        )
        result = model.fit_vb()
    except (ValueError, np.linalg.LinAlgError) as error:
        return [], float("nan"), float("nan"), f"mixed model not fitted: {error}"
    names = list(model.exog_names)
    effects = []
    for shape in shapes:
        index = next(i for i, n in enumerate(names) if n.endswith(f"[T.{shape}]"))
        effects.append(ShapeEffect(shape, float(result.fe_mean[index]), float(result.fe_sd[index])))
    slope = float(result.fe_mean[names.index("log2_strokes")])
    participant_sd = float(np.exp(result.vcp_mean[0]))
    return effects, participant_sd, slope, "mixed model fitted by variational Bayes (fit_vb)"
