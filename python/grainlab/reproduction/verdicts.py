"""Verdict rules: how the per-seed values of a claim become ``reproduced``,
``not reproduced`` or ``inconclusive`` (fixed before any run).

:class:`ValueRule`, :class:`SideRule` and :class:`ProportionRule` judge the finite
values into a :class:`Judgement`: docs/reproduction.md, "Verdict rules".

Example
-------
>>> SideRule(+1).judge([0.02, 0.03, 0.025, 0.04, 0.03]).verdict
'reproduced'
>>> SideRule(+1).judge([-0.02, 0.03, -0.025, 0.04, 0.001]).verdict
'inconclusive'
>>> ValueRule(0.325, 0.355).judge([0.20, 0.21, 0.19]).verdict
'not reproduced'
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import stats

__all__ = [
    "INCONCLUSIVE",
    "NOT_REPRODUCED",
    "REPRODUCED",
    "VERDICTS",
    "Judgement",
    "ProportionRule",
    "SideRule",
    "ValueRule",
    "t_interval",
]

REPRODUCED = "reproduced"
NOT_REPRODUCED = "not reproduced"
INCONCLUSIVE = "inconclusive"
VERDICTS = (REPRODUCED, NOT_REPRODUCED, INCONCLUSIVE)

#: Confidence level of every interval, and the level of the tests.
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Judgement:
    """The statistics of one claim over the seeds, and its verdict."""

    mean: float
    ci95: tuple[float, float]
    n: int
    p_value: float
    verdict: str
    reason: str


def _finite(values: Sequence[float | None]) -> np.ndarray:
    v = np.array([np.nan if x is None else float(x) for x in values], dtype=np.float64)
    return v[np.isfinite(v)]


def t_interval(values: np.ndarray, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """Two-sided t-interval of the mean of ``values`` (n >= 2); a point when all are equal."""
    n = values.size
    mean = float(values.mean())
    sem = _sem(values)
    if not math.isfinite(sem):
        return (math.nan, math.nan)
    if sem == 0.0:
        return (mean, mean)
    low, high = stats.t.interval(confidence, n - 1, loc=mean, scale=sem)
    return (float(low), float(high))


def _sem(values: np.ndarray) -> float:
    n = values.size
    return float(np.std(values, ddof=1) / math.sqrt(n)) if n > 1 else math.nan


def t_test_p(values: np.ndarray, reference: float) -> float:
    """Two-sided p-value of the one-sample t-test of ``values`` against ``reference``
    (0 or 1 when every value is the same)."""
    sem = _sem(values)
    diff = float(values.mean()) - reference
    if not math.isfinite(sem):
        return math.nan
    if sem == 0.0:
        return 1.0 if diff == 0.0 else 0.0
    return float(2.0 * stats.t.sf(abs(diff) / sem, values.size - 1))


def _too_few(v: np.ndarray) -> Judgement:
    mean = float(v.mean()) if v.size else math.nan
    return Judgement(mean, (math.nan, math.nan), int(v.size), math.nan, INCONCLUSIVE,
                     f"{v.size} seed(s) with a value; at least 2 are needed")


@dataclass(frozen=True)
class ValueRule:
    """The paper gives a value: the 95 % CI of the mean must lie in ``[low, high]``."""

    low: float
    high: float

    def __post_init__(self) -> None:
        if not self.low <= self.high:
            raise ValueError(f"ValueRule: low {self.low} above high {self.high}")

    @property
    def test(self) -> str:
        return (f"95 % t-interval of the mean over seeds against the tolerance band "
                f"[{self.low:.4g}, {self.high:.4g}]: inside reproduced, outside not reproduced, "
                "across an edge inconclusive")

    def judge(self, values: Sequence[float | None]) -> Judgement:
        v = _finite(values)
        if v.size < 2:
            return _too_few(v)
        low, high = t_interval(v)
        mid = 0.5 * (self.low + self.high)
        p = t_test_p(v, mid)
        if self.low <= low and high <= self.high:
            verdict, reason = REPRODUCED, "the interval lies inside the tolerance band"
        elif high < self.low or low > self.high:
            verdict, reason = NOT_REPRODUCED, "the interval lies outside the tolerance band"
        else:
            verdict, reason = INCONCLUSIVE, "the interval crosses an edge of the tolerance band"
        return Judgement(float(v.mean()), (low, high), int(v.size), p, verdict, reason)

    def to_dict(self) -> dict[str, Any]:
        return {"rule": "value", "low": self.low, "high": self.high}


@dataclass(frozen=True)
class SideRule:
    """The paper gives a direction: the 95 % CI of the mean must lie on ``sign``'s
    side of ``reference`` (+1 above, -1 below)."""

    sign: int
    reference: float = 0.0

    def __post_init__(self) -> None:
        if self.sign not in (1, -1):
            raise ValueError(f"SideRule: sign must be +1 or -1, got {self.sign}")

    @property
    def test(self) -> str:
        side = "above" if self.sign > 0 else "below"
        return (f"95 % t-interval of the mean over seeds entirely {side} {self.reference:g}: reproduced; "
                "entirely on the other side: not reproduced; containing it: inconclusive")

    def judge(self, values: Sequence[float | None]) -> Judgement:
        v = _finite(values)
        if v.size < 2:
            return _too_few(v)
        low, high = t_interval(v)
        p = t_test_p(v, self.reference)
        above, below = low > self.reference, high < self.reference
        if (above and self.sign > 0) or (below and self.sign < 0):
            verdict, reason = REPRODUCED, "the interval lies on the paper's side"
        elif above or below:
            verdict, reason = NOT_REPRODUCED, "the interval lies on the other side"
        else:
            verdict, reason = INCONCLUSIVE, f"the interval contains {self.reference:g}"
        return Judgement(float(v.mean()), (low, high), int(v.size), p, verdict, reason)

    def to_dict(self) -> dict[str, Any]:
        return {"rule": "side", "sign": self.sign, "reference": self.reference}


@dataclass(frozen=True)
class ProportionRule:
    """The paper reports an event: the share of seeds where it happens must
    exceed one half (exact one-sided binomial tests at 5 %)."""

    @property
    def test(self) -> str:
        return ("exact one-sided binomial test at 5 % of the share of seeds where it happens against 1/2: "
                "above reproduced, below not reproduced, neither inconclusive")

    def judge(self, values: Sequence[float | None]) -> Judgement:
        v = _finite(values)
        if v.size < 2:
            return _too_few(v)
        if not np.all((v == 0) | (v == 1)):
            raise ValueError(f"ProportionRule: per-seed values must be 0 or 1, got {v.tolist()}")
        k, n = int(v.sum()), int(v.size)
        greater = stats.binomtest(k, n, 0.5, alternative="greater")
        less = stats.binomtest(k, n, 0.5, alternative="less")
        ci = stats.binomtest(k, n, 0.5).proportion_ci(CONFIDENCE, method="exact")
        if greater.pvalue < 1 - CONFIDENCE:
            verdict, reason, p = REPRODUCED, f"{k} of {n} seeds (p = {greater.pvalue:.3g})", greater.pvalue
        elif less.pvalue < 1 - CONFIDENCE:
            verdict, reason, p = NOT_REPRODUCED, f"{k} of {n} seeds (p = {less.pvalue:.3g})", less.pvalue
        else:
            p = min(greater.pvalue, less.pvalue)
            verdict, reason = INCONCLUSIVE, f"{k} of {n} seeds: neither share is significant at 5 %"
        return Judgement(k / n, (float(ci.low), float(ci.high)), n, float(p), verdict, reason)

    def to_dict(self) -> dict[str, Any]:
        return {"rule": "proportion", "reference": 0.5}
