"""The seed-count estimate (grainlab.reproduction.power) and the numbers docs/reproduction.md quotes from it."""

import math

import numpy as np
import pytest

from grainlab.reproduction.power import (
    interval_half_width,
    power_to_exclude_zero,
    probability_within,
    seed_table,
)
from grainlab.reproduction.stored import stored_claims


def test_no_effect_excludes_zero_at_the_one_sided_level():
    # with a true mean of 0 the two-sided 95 % interval lies above 0 with probability 0.025
    for n in (3, 10, 40):
        assert power_to_exclude_zero(0.02, 0.0, n) == pytest.approx(0.025, abs=1e-9)


def test_power_matches_sampling():
    rng = np.random.default_rng(3)
    n, sd, effect = 8, 0.02, 0.015
    draws = rng.normal(effect, sd, (40000, n))
    half = 2.3646242510102993 * draws.std(axis=1, ddof=1) / math.sqrt(n)  # t(0.975, 7)
    sampled = np.mean(draws.mean(axis=1) - half > 0)
    assert power_to_exclude_zero(sd, effect, n) == pytest.approx(sampled, abs=0.01)


def test_half_width_is_the_t_interval():
    # t(0.975, 4) = 2.7764451051977987
    assert interval_half_width(0.01, 5) == pytest.approx(2.7764451051977987 * 0.01 / math.sqrt(5), rel=1e-12)
    with pytest.raises(ValueError, match="at least 2"):
        interval_half_width(0.01, 1)


def test_within_grows_with_seeds_and_vanishes_when_the_band_is_too_narrow():
    assert probability_within(0.02, 0.001, 5) == 0.0
    small, large = probability_within(0.02, 0.015, 10), probability_within(0.02, 0.015, 40)
    assert 0.0 < small < large < 1.0


def test_the_documented_table_comes_from_the_first_five_seeds():
    doc = stored_claims("main")
    rows = {r["id"]: r for r in doc["claims"]}
    every = seed_table(rows["band_lambda_above_rest_all"]["per_seed"][:5], [10, 12, 16, 20, 30],
                       effects=(0.03, 0.022, 0.015), width=0.015)
    assert every[0]["sd"] == pytest.approx(0.0233, abs=5e-5)
    quoted = {10: (0.0167, 0.95, 0.76, 0.44, 0.10), 12: (0.0148, 0.98, 0.85, 0.53, 0.17),
              16: (0.0124, 1.00, 0.94, 0.67, 0.36), 20: (0.0109, 1.00, 0.98, 0.78, 0.56),
              30: (0.0087, 1.00, 1.00, 0.93, 0.85)}
    for row in every:
        hw, p30, p22, p15, within = quoted[int(row["n"])]
        assert row["half_width"] == pytest.approx(hw, abs=5e-5)
        assert (round(row["power_0.03"], 2), round(row["power_0.022"], 2), round(row["power_0.015"], 2),
                round(row["within_0.015"], 2)) == (p30, p22, p15, within)
    two = seed_table(rows["band_lambda_above_rest"]["per_seed"][:5], [20], effects=(0.03,), width=0.015)
    assert two[0]["sd"] == pytest.approx(0.0051, abs=5e-5)
    assert two[0]["half_width"] == pytest.approx(0.0024, abs=5e-5)
