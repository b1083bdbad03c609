"""Analysis of a recognition study: accuracy with Wilson intervals, psychometric fits per
shape with bootstrap intervals (SQ2.3), a mixed-effects model of shape differences (SQ2.4),
plots and a Markdown report."""

from feelmysign.study.analysis.analyse import analyse_study

__all__ = ["analyse_study"]
