"""The Weibull fit (grainlab.analysis.weibull) against strengths drawn from a known
Weibull law: it recovers m and sigma_0, its 95 % bootstrap interval covers the true m in
most samples of 30, the plot's points are the median ranks, and bad input is refused."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.analysis.weibull import weibull_fit, weibull_points


@pytest.mark.parametrize(("m", "scale"), [(3.0, 5e5), (8.0, 2e6)])
def test_the_fit_recovers_modulus_and_scale_of_a_known_weibull_law(m, scale):
    strengths = scale * np.random.default_rng(11).weibull(m, 3000)
    fit = weibull_fit(strengths, resamples=100)
    assert fit.modulus == pytest.approx(m, rel=0.05) and fit.scale == pytest.approx(scale, rel=0.02)
    assert fit.r_squared > 0.98 and fit.n == 3000
    assert fit.modulus_interval[0] < fit.modulus < fit.modulus_interval[1]
    assert fit.survival(fit.scale) == pytest.approx(np.exp(-1.0))


def test_the_interval_covers_the_true_modulus_in_most_samples_of_thirty():
    rng = np.random.default_rng(2)
    fits = [weibull_fit(7e5 * rng.weibull(4.0, 30), resamples=300) for _ in range(40)]
    covered = sum(f.modulus_interval[0] <= 4.0 <= f.modulus_interval[1] for f in fits)
    assert covered >= 32  # 95 % intervals: 38 expected, a bootstrap of 30 is a little narrow
    assert 3.4 < np.median([f.modulus for f in fits]) < 4.8


def test_the_points_are_the_median_ranks():
    x, y = weibull_points([3.0, 1.0, 2.0, 4.0])
    np.testing.assert_allclose(x, np.log([1.0, 2.0, 3.0, 4.0]))
    np.testing.assert_allclose(y, np.log(-np.log(1 - (np.arange(1, 5) - 0.5) / 4)))
    assert weibull_fit([1.0, 2.0, 3.0, 4.0]).to_dict()["estimator"].startswith("median ranks")


@pytest.mark.parametrize(("values", "message"), [([1.0, 2.0], "at least 3"), ([1.0, -2.0, 3.0], "finite and > 0"),
                                                 ([2.0, 2.0, 2.0], "all equal")])
def test_bad_strengths_are_refused(values, message):
    with pytest.raises(ValueError, match=message):
        weibull_fit(values)
