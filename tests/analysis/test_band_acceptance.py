"""The band readings' shared acceptance rules (analysis/band_acceptance.py)."""

import math

import numpy as np

from grainlab.analysis.band_acceptance import (
    candidate_reason,
    crossing_problems,
    permutation_p_value,
    profile_prominence,
    reduction_problems,
    significance_problems,
    slab_eta2,
    strain_band_problems,
    transition_problems,
)

X, Y = np.meshgrid(np.arange(40.0), np.arange(20.0))
LATTICE = np.c_[X.ravel(), Y.ravel()]  # 40 x 20 grains of diameter 1


def test_a_band_across_the_sample_crosses_it_and_a_corner_band_does_not():
    along_x = np.array([1.0, 0.0])
    s = LATTICE[:, 1] - 10.0  # a horizontal band through the middle, 3 rows thick
    assert crossing_problems(LATTICE, along_x, s, 3.0, 1.0, 1.0) == []
    # the same band cut to the left quarter of the sample: its grains span 9 of a 39 chord
    s_short = np.where(LATTICE[:, 0] < 10.0, s, 100.0)
    (problem,) = crossing_problems(LATTICE, along_x, s_short, 3.0, 1.0, 1.0)
    assert "span 9.0 mean diameters of a 9.0-diameter chord" in problem
    assert "smaller side is 19.0" in problem
    # a band at 45 degrees through the corner: its chord is shorter than 3/4 of the side
    diagonal = np.array([1.0, 1.0]) / math.sqrt(2.0)
    s_corner = (LATTICE - [36.0, 0.0]) @ np.array([-1.0, 1.0]) / math.sqrt(2.0)
    assert crossing_problems(LATTICE, diagonal, s_corner, 2.0, 1.0, 1.0)
    # the centre line crosses the whole sample but the band's grains cover 25 of its 39
    s_part = np.where(LATTICE[:, 0] < 26.0, s, 1.6)  # outside the band, inside the 2.0 reach
    assert "span 25.0 mean diameters of a 39.0-diameter chord" in crossing_problems(
        LATTICE, along_x, s_part, 3.0, 2.0, 1.0
    )[0]
    assert crossing_problems(LATTICE, along_x, s_part, 3.0, 2.0, 1.0, crossing=0.6) == []


def test_prominence_is_the_band_excess_over_the_largest_excess_beyond_its_flanks():
    distance = np.arange(-20.0, 21.0)
    smooth = np.zeros(distance.size)
    smooth[20] = 1.0  # the band, at the centre line
    smooth[35] = 0.25  # 15 diameters away: beyond 0.5 + max(1, 2) = 2.5
    smooth[22] = 0.9  # within the flank: not elsewhere
    crossing = np.ones(distance.size, bool)
    prominence, elsewhere = profile_prominence(1.0, smooth, distance, crossing, 0.0, 1.0, 1.0)
    assert (prominence, elsewhere) == (4.0, 0.25)
    crossing[35] = False  # a bin that only clips a corner does not count
    assert profile_prominence(1.0, smooth, distance, crossing, 0.0, 1.0, 1.0) == (math.inf, 0.0)
    assert profile_prominence(0.0, smooth, distance, crossing, 0.0, 1.0, 1.0)[0] == 0.0


def test_the_strain_band_tests_name_what_fails():
    assert strain_band_problems(0.0, 0.0, 0.0, 5.0, 1.0, 2.0) == [
        "no part of the profile stands above the background strain"
    ]
    assert strain_band_problems(1.0, 4.0, 0.25, 5.0, 1.0, 2.0) == []
    thin, flat = strain_band_problems(1.0, 1.5, 2.0 / 3.0, 0.5, 1.0, 2.0)
    assert thin == "thinner (0.50 mean diameters) than min_thickness = 1"
    assert "prominence 1.50 < min_prominence = 2" in flat and "67 % as high" in flat


def test_the_displacement_band_tests_name_what_fails():
    assert reduction_problems(0.6, 0.6) == []
    assert "they remove 28 % of its residual" in reduction_problems(0.28, 0.6)[0]
    assert transition_problems(True, 0.1, 0.9) == []
    assert "share <= 0.1" in transition_problems(False, 0.1, 0.9)[0]


def test_significance_against_rearrangements():
    null = np.linspace(0.0, 0.5, 19)
    assert permutation_p_value(0.9, null) == 0.05  # above every rearrangement: 1/20
    assert permutation_p_value(0.0, null) == 1.0
    assert significance_problems(0.05, 19, "strain values") == []
    (problem,) = significance_problems(0.1, 19, "field values")
    assert problem == "not significant (p = 0.10 against 19 random rearrangements of the field values)"


def test_eta2_of_values_set_by_the_row_is_one_and_of_a_checkerboard_across_the_rows_is_not():
    rows = LATTICE[:, 1].copy()
    assert slab_eta2(LATTICE, rows, np.array([0.0, 1.0]), 1.0) == 1.0
    columns = LATTICE[:, 0] % 2  # varies along the rows only: no share explained across them
    assert slab_eta2(LATTICE, columns, np.array([0.0, 1.0]), 1.0) < 0.0 + 1e-12


def test_a_candidate_reason_names_its_angle_and_thickness():
    reason = candidate_reason(131.24, 5.46, ["a", "b"])
    assert reason == "best candidate at 131.2 deg, 5.5 mean diameters thick: a; b"
