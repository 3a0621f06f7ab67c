"""The verdict rules on constructed data: a claim that holds, one that fails, one that is noise."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from grainlab.reproduction.verdicts import (
    INCONCLUSIVE,
    NOT_REPRODUCED,
    REPRODUCED,
    ProportionRule,
    SideRule,
    ValueRule,
    t_interval,
)


def test_t_interval_is_the_textbook_one():
    # mean 2, s = 1, n = 3: 2 +- t(0.975, 2) / sqrt(3)
    low, high = t_interval(np.array([1.0, 2.0, 3.0]))
    half = 4.302652729749464 / math.sqrt(3.0)
    assert low == pytest.approx(2.0 - half, rel=1e-12) and high == pytest.approx(2.0 + half, rel=1e-12)
    assert t_interval(np.array([0.5, 0.5, 0.5])) == (0.5, 0.5)


def test_a_paired_difference_of_the_papers_sign_is_reproduced():
    # band minus rest lambda, five seeds: clearly positive
    j = SideRule(+1).judge([0.031, 0.028, 0.035, 0.026, 0.030])
    assert j.verdict == REPRODUCED and j.n == 5 and j.ci95[0] > 0
    assert j.p_value == pytest.approx(stats.ttest_1samp([0.031, 0.028, 0.035, 0.026, 0.030], 0.0).pvalue)


def test_a_difference_of_the_other_sign_is_not_reproduced():
    j = SideRule(+1).judge([-0.012, -0.015, -0.010, -0.014, -0.013])
    assert j.verdict == NOT_REPRODUCED and j.ci95[1] < 0


def test_noise_is_inconclusive():
    rng = np.random.default_rng(3)
    values = rng.normal(0.0, 0.01, 5)
    values -= values.mean()  # exactly no effect: the interval must contain 0
    assert SideRule(+1).judge(values).verdict == INCONCLUSIVE
    assert SideRule(-1).judge(values).verdict == INCONCLUSIVE


def test_a_threshold_counts_from_its_reference():
    rule = SideRule(+1, 0.6)  # an ROC AUC that must exceed 0.6
    assert rule.judge([0.71, 0.69, 0.73]).verdict == REPRODUCED
    assert rule.judge([0.52, 0.50, 0.51]).verdict == NOT_REPRODUCED
    assert rule.judge([0.55, 0.65, 0.62]).verdict == INCONCLUSIVE


def test_value_rule_inside_outside_and_across_the_tolerance_band():
    rule = ValueRule(0.325, 0.355)
    assert rule.judge([0.338, 0.341, 0.340, 0.339]).verdict == REPRODUCED
    assert rule.judge([0.19, 0.20, 0.21]).verdict == NOT_REPRODUCED
    assert rule.judge([0.30, 0.35, 0.33]).verdict == INCONCLUSIVE


def test_seeds_without_a_value_are_left_out_and_too_few_are_inconclusive():
    j = SideRule(+1).judge([0.03, math.nan, None, 0.04, 0.035])
    assert j.n == 3 and j.verdict == REPRODUCED
    few = SideRule(+1).judge([0.03, math.nan])
    assert few.verdict == INCONCLUSIVE and few.n == 1 and "at least 2" in few.reason


def test_proportions_need_a_significant_majority():
    rule = ProportionRule()
    assert rule.judge([1, 1, 1, 1, 1]).verdict == REPRODUCED  # p = 1/32
    assert rule.judge([0, 0, 0, 0, 0]).verdict == NOT_REPRODUCED
    assert rule.judge([1, 1, 1, 0, 1]).verdict == INCONCLUSIVE  # p = 6/32
    assert rule.judge([1, 1, 1]).verdict == INCONCLUSIVE  # 3 of 3: p = 1/8
    j = rule.judge([1, 1, 1, 1, 1])
    assert j.mean == 1.0 and j.ci95[1] == 1.0 and j.ci95[0] == pytest.approx(0.025 ** (1 / 5))
    with pytest.raises(ValueError, match="0 or 1"):
        rule.judge([0.5, 1.0])


def test_bad_rules_are_refused():
    with pytest.raises(ValueError, match="sign"):
        SideRule(0)
    with pytest.raises(ValueError, match="low"):
        ValueRule(1.0, 0.0)
