"""The short Markdown report of an analysis: what was done, the tables, the figures."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from feelmysign.plural import plural
from feelmysign.study.analysis.models import ShapeTest, SpeedTest
from feelmysign.study.analysis.psychometric import (
    ABOVE,
    AT_OR_BELOW,
    SLOPE_BOUNDS,
    Interval,
    Needed,
    is_step,
)
from feelmysign.study.store import DISCARDED, StudyStore

if TYPE_CHECKING:
    from feelmysign.study.analysis.analyse import Analysis


def needed_text(needed: Needed) -> str:
    """A needed resolution as far as the tested range can say."""
    if needed.kind == AT_OR_BELOW:
        return f"≤ {needed.lowest_tested:g} (at or below the lowest tested)"
    if needed.kind == ABOVE:
        return f"> {needed.highest_tested:g} (above the highest tested)"
    assert needed.strokes is not None
    return f"{needed.strokes:.1f}"


def interval_text(interval: Interval, digits: int = 1) -> str:
    """An interval truncated to the tested range; an open end is written ≤ or ≥."""
    if interval.low_open and interval.high <= interval.low:
        return f"≤ {interval.low:g}"  # wholly at or below the lowest tested
    if interval.high_open and interval.low >= interval.high:
        return f"≥ {interval.high:g}"
    low = f"≤ {interval.low:g}" if interval.low_open else f"{interval.low:.{digits}f}"
    high = f"≥ {interval.high:g}" if interval.high_open else f"{interval.high:.{digits}f}"
    return f"{low} - {high}"


def _p(value: float) -> str:
    return "p < 0.001" if value < 0.001 else f"p = {value:.3f}"


def _not_estimable(participants: int, why: str) -> str:
    return f"not estimable with {plural(participants, 'participant')} ({why})"


def interval_notes(shape: str, needed: Needed) -> list[str]:
    """Where an interval says more or other than the bound: why it is wide, or that the two
    disagree (never a bound and an interval left side by side without a word)."""
    notes = []
    named = (
        ("95% interval", needed.interval),
        ("profile likelihood", needed.profile),
        ("cluster bootstrap", needed.cluster),
    )
    for name, interval in named:
        if needed.kind == AT_OR_BELOW and interval.high_open:
            notes.append(
                f"{shape}, {name}: reaches above the highest tested resolution although every "
                "tested resolution reached the criterion: some resampled studies (or the "
                "likelihood) allow curves that stay below it at the tested resolutions, because "
                "the share correct there is close to the criterion with few answers. The bound "
                f"≤ {needed.lowest_tested:g} is what these data show; the interval says how "
                "uncertain that is."
            )
        elif needed.kind == AT_OR_BELOW and not interval.low_open:
            notes.append(
                f"{shape}, {name}: {interval_text(interval)} disagrees with the bound "
                f"≤ {needed.lowest_tested:g}; the fitted curve and the counts differ, read the "
                "accuracy table."
            )
        elif needed.kind == ABOVE and not interval.high_open:
            notes.append(
                f"{shape}, {name}: {interval_text(interval)} disagrees with the bound "
                f"> {needed.highest_tested:g}; the fitted curve and the counts differ, read the "
                "accuracy table."
            )
    return notes


def cluster_not_estimable(interval: Interval | None, participants: int) -> str | None:
    """Why the cluster bootstrap's interval says nothing, or None when it stands: resampling
    participants needs some to differ; with one every sample is the same person, with two
    most are one person twice (a zero-width interval)."""
    if interval is not None and participants >= 3:
        return None
    return _not_estimable(participants, "resampling participants needs 3 or more")


def slope_not_estimable(slope: float) -> str | None:
    """Why there is no slope, or None: at its upper bound the answers jump from wrong to
    right between two tested resolutions (or never change), so no slope was measured."""
    if is_step(slope):
        return (
            f"not estimable: at the fit's limit ({SLOPE_BOUNDS[1]:g}), the answers change "
            "from wrong to right between two tested resolutions or not at all (each interval "
            "of the needed resolution then spans at least those two)"
        )
    return None


def spread_not_estimable(spread: float, participants: int) -> str | None:
    if participants < 2 or not math.isfinite(spread):
        return _not_estimable(participants, "a spread between participants needs 2 or more")
    return None


def dispersion_not_estimable(dispersion: float, participants: int) -> str | None:
    if participants < 2 or not math.isfinite(dispersion):
        return _not_estimable(
            participants, "it compares participants' counts: 2 or more, and answers that vary"
        )
    return None


def model_sd_not_estimable(participants: int) -> str | None:
    """Why the shape model's participant SD says nothing, or None when it stands."""
    if participants >= 2:
        return None
    return _not_estimable(participants, "a spread needs 2 or more")


def _cluster_text(interval: Interval | None, participants: int) -> str:
    why = cluster_not_estimable(interval, participants)
    if why is not None or interval is None:
        return why or ""
    return interval_text(interval)


def _slope_text(slope: float) -> str:
    return slope_not_estimable(slope) or f"{slope:.2f}"


def _spread_text(spread: float, participants: int) -> str:
    return spread_not_estimable(spread, participants) or f"{spread:.2f}"


def _dispersion_text(dispersion: float, participants: int) -> str:
    return dispersion_not_estimable(dispersion, participants) or f"{dispersion:.2f}"


def shape_test_sentence(test: ShapeTest) -> str:
    """What the shape test found, or why there is none: for the report and the terminal."""
    if test.refused is not None or test.p is None or test.statistic is None:
        return (
            f"No test of whether shapes differ is reported: {test.refused}. Run at least "
            f"{plural(test.participants_needed, 'participant')} (8 or more for the calibrated "
            "false-positive rate in docs/research.md)."
        )
    return (
        f"Test that shapes differ at equal strokes: {test.method} ({test.participants} "
        f"participants, {test.shapes} shapes; each participant's mean residual per shape "
        "against a shape-free logistic model of log2(strokes) with each participant's own "
        "intercept, centred over shapes and without the shapes' mean log2(strokes), which "
        "the model's slope fits; statistic: "
        f"squared length of the mean profile = {test.statistic:.4g}, over {test.flips} sign "
        f"patterns): {_p(test.p)}."
    )


def speed_test_sentence(test: SpeedTest) -> str:
    """What the speed test found, or why there is none."""
    if test.refused is not None or test.p is None or test.statistic is None:
        return (
            f"No test of whether speeds differ is reported: {test.refused}. Run at least "
            f"{plural(test.participants_needed, 'participant')}."
        )
    return (
        f"Test that speeds differ at equal shape and strokes: {test.method}, as for the shapes "
        f"({test.participants} participants, {test.speeds} speeds; each participant's mean "
        "residual per speed against the same speed-free model, centred over speeds; every "
        "speed plays the same shapes at the same strokes, so nothing else is taken out; "
        f"statistic: squared length of the mean profile = {test.statistic:.4g}, over "
        f"{test.flips} sign patterns): {_p(test.p)}."
    )


def _speeds_text(speeds: tuple[float, ...]) -> str:
    return f"{len(speeds)} speeds ({', '.join(f'{v:g}' for v in speeds)} cm/s)"


def _head(analysis: Analysis, key: str) -> str:
    """The first cells of a row: the shape, and its speed when speed is a factor."""
    if not analysis.speeds:
        return key
    shape, speed = analysis.cells[key]
    return f"{shape} | {speed:g}"


def write_report(path: Path, store: StudyStore, analysis: Analysis) -> Path:
    design = store.design
    by_speed = f"{_speeds_text(analysis.speeds)} x " if analysis.speeds else ""
    speed_column = " speed (cm/s) |" if analysis.speeds else ""
    lines = [
        f"# {design.name}",
        "",
        f"{plural(analysis.participants, 'participant')} ({analysis.simulated} simulated), "
        f"{plural(analysis.trials, 'measured trial')}: {plural(len(design.shapes), 'shape')} x "
        f"{plural(len(design.resolutions), 'resolution')} x {by_speed}"
        f"{plural(design.repetitions, 'repetition')}, "
        "order by "
        f"{design.randomisation} (seed {design.seed}). Answers were free; they were coded to "
        f"shapes by synonyms, unclear ones by the researcher. "
        f"{plural(analysis.unclear, 'answer')} still "
        + ("awaits review and is" if analysis.unclear == 1 else "await review and are")
        + " left out.",
        "",
        "## Accuracy by shape and resolution",
        "",
        "Share named correctly, with 95% Wilson intervals.",
        "",
        "| shape |" + speed_column + " " + " | ".join(design.resolutions) + " |",
        "|---|" + "---|" * (len(design.resolutions) + bool(analysis.speeds)),
    ]
    for shape, rows in analysis.accuracy.items():
        cells = [
            f"{k}/{n} = {k / n:.0%} [{low:.0%}, {high:.0%}] ({plural(strokes, 'stroke')})"
            if n
            else "-"
            for strokes, k, n, low, high in rows
        ]
        lines.append(f"| {_head(analysis, shape)} | " + " | ".join(cells) + " |")
    lines += _participant_section(analysis, [shape.name for shape in design.shapes])
    lines += [
        "",
        "![accuracy](accuracy.png)",
        "",
        f"## Resolution needed for {analysis.criterion:.0%} correct (SQ2.3)",
        "",
        "Per shape, a logistic psychometric function of log2(strokes) (guess rate "
        f"{design.guess_rate:g}, lapse rate fixed at 2%) fitted by maximum likelihood. "
        "Interval: parametric bootstrap with the participants' spread, 95% (each participant's "
        "curve shifted along log2(strokes) by a normal amount; the curve and the SD of the "
        "shifts fitted by maximum marginal likelihood; each new study of the same design "
        "draws an SD from its profile likelihood and the curve most likely at that SD, every "
        "simulated participant with a shift of their own, pooled and refitted; bias-corrected "
        "percentiles). Beside it the profile-likelihood interval and "
        "the cluster bootstrap over participants, both too narrow when participants differ. "
        "Participants' SD: the fitted SD of the shifts, in doublings of strokes (0: alike). "
        "Dispersion: Pearson chi-square per degree of freedom of each participant's number of "
        "correct answers against the fitted curve (about 1 when participants differ only by "
        "chance).",
        "",
        "| shape |" + speed_column + " strokes needed | 95% interval | profile likelihood | "
        "cluster bootstrap | slope per doubling | participants' SD | dispersion |",
        "|---|---|---|---|---|---|---|---|" + "---|" * bool(analysis.speeds),
    ]
    people = analysis.participants
    for shape, t in analysis.thresholds.items():
        needed = analysis.needed[shape]
        lines.append(
            f"| {_head(analysis, shape)} | {needed_text(needed)} | "
            f"{interval_text(needed.interval)} | "
            f"{interval_text(needed.profile)} | {_cluster_text(needed.cluster, people)} | "
            f"{_slope_text(t.fit.slope)} | {_spread_text(t.population.spread, people)} | "
            f"{_dispersion_text(t.dispersion, people)} |"
        )
    notes = [
        n for shape in analysis.thresholds for n in interval_notes(shape, analysis.needed[shape])
    ]
    if notes:
        lines += ["", *(f"- {n}" for n in notes)]
    lines += [
        "",
        "A number is given only where the tested resolutions bracket the criterion. "
        "'≤ n (at or below the lowest tested)': the share correct reached the criterion at "
        "every tested resolution, so the data say only that n strokes are enough; '> n (above "
        "the highest tested)': it reached it at none. Intervals are cut at the tested range: "
        "'≤ n' or '≥ n' at an end means the interval goes on beyond what was tested.",
    ]
    lines += _truth_section(analysis)
    lines += [
        "",
        "![needed resolution](needed-resolution.png)",
        "",
        "## Do shapes differ? (SQ2.4)",
        "",
    ]
    model = analysis.model
    if model is None:
        lines.append("Not enough data (two shapes with coded answers at least).")
    else:
        lines += [shape_test_sentence(model.test), ""]
        if model.mixed:
            lines += [
                f"Mixed-effects model (participant random intercept; {model.note}; "
                f"descriptive): reference shape {model.reference}; slope "
                f"{model.slope_per_doubling:.2f} log odds per doubling of strokes; participant "
                + (
                    "SD " + (model_sd_not_estimable(analysis.participants) or "") + "."
                    if model_sd_not_estimable(analysis.participants)
                    else f"SD {model.participant_sd:.2f} log odds."
                ),
                "",
                "| shape | log odds vs " + model.reference + " | posterior SD |",
                "|---|---|---|",
                *(f"| {e.shape} | {e.log_odds:.2f} | {e.sd:.2f} |" for e in model.mixed),
            ]
        else:
            lines.append(f"Mixed-effects model: {model.note}.")
    lines += _speed_section(analysis)
    lines += _threshold_section(analysis)
    lines += [
        "",
        "Files: trials.csv (one row per trial, anonymised), questionnaire.csv, threshold.csv, "
        "threshold-runs.csv, "
        "design.json, results.json.",
        "",
    ]
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


def _speed_section(analysis: Analysis) -> list[str]:
    """Speed a factor: its test and its effects in the mixed model (the needed resolution per
    shape and speed is in the table above)."""
    if not analysis.speeds:
        return []
    lines = [
        "",
        "## Does speed matter?",
        "",
        f"Every shape was drawn at {_speeds_text(analysis.speeds)}, crossed with shape, "
        "resolution and repetition and mixed within each block; the tables above read each "
        "shape at each speed on its own, by the same rules. The shape test above holds the "
        "same mix of speeds for every shape, so a speed effect does not show in it as a shape "
        "difference.",
        "",
    ]
    model = analysis.model
    if model is None or model.speed_test is None:
        return [*lines, "Not enough data (two shapes with coded answers at least)."]
    lines.append(speed_test_sentence(model.speed_test))
    if model.speed_effects:
        lines += [
            "",
            f"Mixed-effects model above, with speed as a fixed effect (descriptive): each "
            f"speed's log odds of a correct answer against {model.reference_speed_cm_s:g} cm/s "
            "(the slowest), at equal shape and strokes.",
            "",
            f"| speed (cm/s) | log odds vs {model.reference_speed_cm_s:g} cm/s | posterior SD |",
            "|---|---|---|",
            *(f"| {e.speed_cm_s:g} | {e.log_odds:.2f} | {e.sd:.2f} |" for e in model.speed_effects),
        ]
    return lines


def _truth_section(analysis: Analysis) -> list[str]:
    """A dry run's known truth beside the estimates (in-range simulated wearers)."""
    truth = analysis.simulated_truth
    if not truth:
        return []
    lines = [
        "",
        f"**Dry run: known truth.** {len(truth['participants'])} of the participants are "
        "simulated in-range wearers, who answer by a known curve per shape (each "
        "participant's curve shifted along log2(strokes) by their own amount). The strokes at "
        f"which their average participant reaches {truth['criterion']:.0%} correct:",
        "",
        "| shape | true strokes needed | estimate | 95% interval | interval covers the truth |",
        "|---|---|---|---|---|",
    ]
    # In the design's order; the interval to two decimals, as the truth (6.0 may be 5.96).
    shown = {analysis.shape_of(key) for key in analysis.accuracy}
    for key in [*analysis.accuracy, *(s for s in truth["shapes"] if s not in shown)]:
        shape = analysis.shape_of(key)
        if shape not in truth["shapes"]:
            continue
        needed = analysis.needed.get(key)
        value = float(truth["shapes"][shape]["needed_strokes"])
        if needed is None:
            lines.append(f"| {key} | {value:.2f} | - | - | - |")
            continue
        interval = needed.interval
        covers = (interval.low_open or interval.low <= value) and (
            interval.high_open or value <= interval.high
        )
        lines.append(
            f"| {key} | {value:.2f} | {needed_text(needed)} | {interval_text(interval, 2)} | "
            f"{'yes' if covers else 'no'} |"
        )
    if analysis.speeds:
        lines += [
            "",
            "The simulated wearers feel no difference between speeds: the same truth holds at "
            "every speed (docs/study.md).",
        ]
    return lines


def _participant_section(analysis: Analysis, shapes: list[str]) -> list[str]:
    if not analysis.per_participant:
        return []
    speeds = [f"{speed:g}" for speed in analysis.speeds]
    lines = [
        "",
        "## Per participant",
        "",
        "Measured trials answered, awaiting review, and correct of the coded ones, overall and "
        "per shape" + (" and per speed (cm/s)." if speeds else "."),
        "",
        "| participant | simulated | trials | awaiting review | correct | "
        + " | ".join([*shapes, *(f"{speed} cm/s" for speed in speeds)])
        + " |",
        "|---|---|---|---|---|" + "---|" * (len(shapes) + len(speeds)),
    ]
    for row in analysis.per_participant:
        share = f"{row['correct'] / row['coded']:.0%}" if row["coded"] else "-"
        counts = [row["by_shape"][shape] for shape in shapes]
        counts += [row["by_speed"][speed] for speed in speeds]
        cells = [f"{k}/{n}" if n else "-" for k, n in counts]
        lines.append(
            f"| {row['participant']} | {'yes' if row['simulated'] else 'no'} | {row['trials']} | "
            f"{row['unclear']} | {row['correct']}/{row['coded']} = {share} | "
            + " | ".join(cells)
            + " |"
        )
    return lines


def _threshold_section(analysis: Analysis) -> list[str]:
    measured = [run for run in analysis.threshold_runs if not run["simulated"]]
    simulated = [run for run in analysis.threshold_runs if run["simulated"]]
    if not measured and not simulated:
        return []
    lines = [
        "",
        "## Shortest and briefest stroke whose direction is felt (SQ2.2)",
        "",
        "QUEST+ on a Weibull function, four directions (25% by chance); threshold = posterior "
        "mean (about 71% correct), interval = 95% credible interval. Where the interval reaches "
        "an end of the tested range, the run gives a bound, not a measurement.",
        "",
    ]
    lines += _runs_table(measured) if measured else ["No measured run."]
    if simulated:
        lines += [
            "",
            f"**Simulated runs (dry runs, not measurements): {len(simulated)}.** A simulated "
            "observer answered these (or the participant is simulated); they are flagged "
            "`simulated` in threshold.csv and results.json and are not part of the results above.",
            "",
            *_runs_table(simulated),
        ]
    return lines


def _runs_table(runs: list[dict[str, Any]]) -> list[str]:
    lines = [
        "| participant | varied | threshold | 95% interval | trials | stopped after |",
        "|---|---|---|---|---|---|",
    ]
    for run in runs:
        unit = "grid units" if run["dimension"] == "length" else "ms"
        if run["threshold"] is None:
            what = "discarded" if run["stop_reason"] == DISCARDED else "not finished"
            lines.append(
                f"| {run['participant']} | {run['dimension']} | {what} | | {run['trials']} | |"
            )
            continue
        threshold = f"{run['threshold']:.3g} {unit}"
        if run.get("censored") == "above":
            threshold = "not measured: may lie above the tested range"
        elif run.get("censored") == "below":
            threshold = f"at most {threshold} (the bottom of the tested range)"
        lines.append(
            f"| {run['participant']} | {run['dimension']} | {threshold} | "
            f"{run['low']:.3g} - {run['high']:.3g} | {run['trials']} | {run['stop_reason']} |"
        )
    return lines
