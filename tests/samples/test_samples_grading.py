"""Gradings: draws match their CDFs, mean areas, mass curves, validation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from grainlab.samples import PAPER_GRADING, GradingCurve, UniformByMass, UniformByNumber

A, B = 0.5e-3, 3.0e-3
N = 20_000
# Kolmogorov-Smirnov critical value at the 0.1% level: a correct sampler fails it once in 1000 seeds
KS_LIMIT = 1.95 / math.sqrt(N)

GRADINGS = {
    "uniform_number": UniformByNumber(A, B),
    "uniform_mass": UniformByMass(A, B),
    "curve_log": GradingCurve([0.5e-3, 1e-3, 2e-3, 3e-3], [0, 30, 80, 100]),
    "curve_linear": GradingCurve([0.5e-3, 1e-3, 2e-3, 3e-3], [0, 30, 80, 100], interpolation="linear"),
    "curve_flat_segment": GradingCurve([0.5e-3, 1e-3, 2e-3, 3e-3], [0, 40, 40, 100]),
}


@pytest.mark.parametrize("name", GRADINGS)
def test_draws_follow_the_number_cdf(name):
    g = GRADINGS[name]
    d = g.sample(N, np.random.default_rng(2024))
    assert d.min() >= g.d_min and d.max() <= g.d_max
    result = stats.kstest(d, g.number_cdf)
    assert result.statistic < KS_LIMIT


@pytest.mark.parametrize("name", GRADINGS)
def test_mass_weighted_draws_follow_the_grading_curve(name):
    """The percent passing by mass of a large draw (2D mass ∝ d^2) is the curve."""
    g = GRADINGS[name]
    d = np.sort(g.sample(200_000, np.random.default_rng(7)))
    mass = np.cumsum(d**2) / np.sum(d**2) * 100.0
    sieves = np.linspace(g.d_min, g.d_max, 26)[1:-1]
    k = np.searchsorted(d, sieves, side="right") - 1
    assert np.max(np.abs(mass[k] - g.passing(sieves))) < 0.6  # percentage points


@pytest.mark.parametrize("name", GRADINGS)
def test_mean_disk_area_matches_monte_carlo(name):
    g = GRADINGS[name]
    area = math.pi * g.sample(400_000, np.random.default_rng(11)) ** 2 / 4
    standard_error = area.std() / math.sqrt(len(area))
    assert abs(area.mean() - g.mean_disk_area()) < 4 * standard_error


@pytest.mark.parametrize("name", GRADINGS)
def test_ppf_inverts_cdf_and_passing_spans_0_to_100(name):
    g = GRADINGS[name]
    u = np.linspace(0.0, 1.0, 101)
    assert np.allclose(g.number_cdf(g.number_ppf(u)), u, atol=1e-12)
    assert g.passing(g.d_min) == pytest.approx(0.0, abs=1e-12)
    assert g.passing(g.d_max) == pytest.approx(100.0, abs=1e-12)
    p = g.passing(np.linspace(g.d_min, g.d_max, 50))
    assert np.all(np.diff(p) >= -1e-12)


def test_uniform_by_mass_formulas():
    g = UniformByMass(A, B)
    assert g.mean_square_diameter() == pytest.approx(A * B, rel=1e-15)
    # number density ∝ d^-2: half the particles are finer than the harmonic mean of the ends
    assert g.number_cdf(2 * A * B / (A + B)) == pytest.approx(0.5, rel=1e-12)
    assert g.passing(0.5 * (A + B)) == pytest.approx(50.0, rel=1e-12)
    assert g.passing(np.array([1e-3, 2e-3])) == pytest.approx([20.0, 60.0])


def test_uniform_by_number_formulas():
    g = UniformByNumber(A, B)
    assert g.mean_square_diameter() == pytest.approx((A * A + A * B + B * B) / 3)
    assert g.number_cdf(1.75e-3) == pytest.approx(0.5)
    assert g.passing(1e-3) == pytest.approx(100 * (1e-9 - A**3) / (B**3 - A**3))


def test_linear_two_point_curve_is_uniform_by_mass():
    curve = GradingCurve([A, B], [0, 100], interpolation="linear")
    exact = UniformByMass(A, B)
    d = np.linspace(A, B, 40)
    assert np.allclose(curve.number_cdf(d), exact.number_cdf(d), rtol=0, atol=1e-13)
    assert curve.mean_disk_area() == pytest.approx(exact.mean_disk_area(), rel=1e-13)
    u = np.random.default_rng(0).random(1000)
    assert np.allclose(curve.number_ppf(u), exact.number_ppf(u), rtol=1e-13)


def test_log_curve_is_straight_on_a_semilog_chart():
    curve = GradingCurve([0.5e-3, 1e-3, 4e-3], [0, 50, 100])
    assert curve.passing(math.sqrt(0.5e-3 * 1e-3)) == pytest.approx(25.0)
    assert curve.passing(2e-3) == pytest.approx(75.0)


def test_paper_grading_is_uniform_by_number_with_mean_radius_0_875_mm():
    assert isinstance(PAPER_GRADING, UniformByNumber)
    assert (PAPER_GRADING.d_min, PAPER_GRADING.d_max) == (0.5e-3, 3.0e-3)
    mean_radius = PAPER_GRADING.number_ppf(0.5) / 2  # uniform: mean = median
    assert mean_radius == pytest.approx(0.875e-3, rel=1e-14)


def test_sampling_is_seeded():
    g = UniformByMass(A, B)
    assert np.array_equal(g.sample(10, np.random.default_rng(3)), g.sample(10, np.random.default_rng(3)))
    assert not np.array_equal(g.sample(10, np.random.default_rng(3)), g.sample(10, np.random.default_rng(4)))


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: UniformByNumber(-1e-3, 1e-3), "d_min"),
        (lambda: UniformByNumber(1e-3, float("nan")), "d_max"),
        (lambda: UniformByMass(3e-3, 1e-3), "d_min: must be <= d_max"),
        (lambda: GradingCurve([1e-3, 0.5e-3, 2e-3], [0, 50, 100]), r"sieve_sizes_m\[1\]"),
        (lambda: GradingCurve([-1e-3, 1e-3], [0, 100]), r"sieve_sizes_m\[0\]"),
        (lambda: GradingCurve([1e-3, 2e-3, 3e-3], [0, 60, 50]), r"percent_passing\[2\]: must not decrease"),
        (lambda: GradingCurve([1e-3, 2e-3, 3e-3], [0, 120, 100]), r"percent_passing\[1\]: must be in 0..100"),
        (lambda: GradingCurve([1e-3, 2e-3, 3e-3], [-5, 50, 100]), r"percent_passing\[0\]: must be in 0..100"),
        (lambda: GradingCurve([1e-3, 2e-3], [10, 100]), r"percent_passing\[0\]: the smallest sieve"),
        (lambda: GradingCurve([1e-3, 2e-3], [0, 90]), r"percent_passing\[1\]: the largest sieve"),
        (lambda: GradingCurve([1e-3, 2e-3], [0, 50, 100]), "percent_passing: expected 2 values"),
        (lambda: GradingCurve([1e-3, 2e-3], [0, 100], interpolation="cubic"), "interpolation"),
    ],
)
def test_bad_input_names_the_field(make, field):
    with pytest.raises(ValueError, match=field):
        make()


def test_equal_bounds_give_one_size():
    g = UniformByNumber(1e-3, 1e-3)
    assert np.all(g.sample(5, np.random.default_rng(0)) == 1e-3)
    assert g.mean_disk_area() == pytest.approx(math.pi * 1e-6 / 4)
