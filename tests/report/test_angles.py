"""Friction, dilation and classical band angles (grainlab.report.angles) on known values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.report.angles import (
    ClassicalAngles,
    arthur_angle,
    dilation_angle_from_slope,
    fit_dilation,
    mobilised_friction_angle,
    mohr_coulomb_angle,
    roscoe_angle,
)

deg, rad = math.degrees, math.radians


@pytest.mark.parametrize(
    ("ratio", "phi_deg"),
    [(1.0, 0.0), (3.0, 30.0), ((1 + math.sqrt(0.5)) / (1 - math.sqrt(0.5)), 45.0)],
)
def test_friction_angle_from_the_stress_ratio(ratio, phi_deg):
    # sin(phi) = (R - 1)/(R + 1): R = 3 gives 1/2
    assert deg(mobilised_friction_angle(ratio)) == pytest.approx(phi_deg, abs=1e-9)


def test_friction_angle_of_a_peak_that_never_left_isotropy_is_undefined():
    assert math.isnan(mobilised_friction_angle(0.8))
    assert math.isnan(mobilised_friction_angle(float("nan")))


@pytest.mark.parametrize(
    ("slope", "sin_psi"),
    [(0.0, 0.0), (-2.0 / 3.0, 0.25), (-0.5, 0.2), (-2.0, 0.5), (0.5, -1.0 / 3.0)],
)
def test_dilation_angle_from_the_volumetric_slope(slope, sin_psi):
    # compression positive: d eps_v = s d eps_1, d gamma = 2 d eps_1 - d eps_v
    d_eps1 = 1e-3
    d_ev = slope * d_eps1
    expected = -d_ev / (2 * d_eps1 - d_ev)
    assert expected == pytest.approx(sin_psi)
    assert math.sin(dilation_angle_from_slope(slope)) == pytest.approx(sin_psi)


def test_dilation_angle_is_undefined_without_shearing():
    assert math.isnan(dilation_angle_from_slope(1.0))
    assert math.isnan(dilation_angle_from_slope(float("inf")))


@pytest.mark.parametrize(
    ("phi", "psi", "mc", "roscoe", "arthur"),
    [(30.0, 10.0, 60.0, 50.0, 55.0), (40.0, 20.0, 65.0, 55.0, 60.0), (36.0, 0.0, 63.0, 45.0, 54.0)],
)
def test_classical_band_angles(phi, psi, mc, roscoe, arthur):
    assert deg(mohr_coulomb_angle(rad(phi))) == pytest.approx(mc)
    assert deg(roscoe_angle(rad(psi))) == pytest.approx(roscoe)
    assert deg(arthur_angle(rad(phi), rad(psi))) == pytest.approx(arthur)
    angles = ClassicalAngles.from_angles(rad(phi), rad(psi)).degrees()
    assert angles == pytest.approx({"phi": phi, "psi": psi, "mohr_coulomb": mc, "roscoe": roscoe, "arthur": arthur})


def test_closest_classical_angle():
    a = ClassicalAngles.from_angles(rad(30.0), rad(10.0))  # 60, 50, 55
    assert a.closest(rad(49.0)) == "Roscoe"
    assert a.closest(rad(56.0)) == "Arthur"
    assert a.closest(rad(70.0)) == "Mohr-Coulomb"
    assert a.closest(float("nan")) is None


def test_dilation_fit_over_the_window_after_the_peak():
    eps = np.linspace(0.0, 0.05, 101)
    peak = 20  # 1 %
    ev = np.where(eps < 0.01, 0.2 * eps, 0.002 - 0.5 * (eps - 0.01))
    ev[50:] += 0.5 * (eps[50:] - eps[50])  # flattens after 2.5 %: outside a 1 % window
    fit = fit_dilation(eps, ev, peak, window=0.01)
    assert fit.slope == pytest.approx(-0.5)
    assert fit.n_records == 21 and fit.start_strain == pytest.approx(0.01) and fit.end_strain == pytest.approx(0.02)
    assert math.sin(fit.angle) == pytest.approx(0.2)
    assert fit.reason == ""
    wide = fit_dilation(eps, ev, peak, window=0.04)  # takes in the flatter part
    assert wide.slope > -0.5


def test_dilation_fit_without_records_after_the_peak():
    eps = np.linspace(0.0, 0.02, 41)
    ev = -eps
    fit = fit_dilation(eps, ev, peak_row=40)
    assert math.isnan(fit.angle) and "3 are needed" in fit.reason
    with pytest.raises(ValueError, match="peak_row"):
        fit_dilation(eps, ev, peak_row=41)
    with pytest.raises(ValueError, match="window"):
        fit_dilation(eps, ev, peak_row=0, window=0.0)

