"""Porosity readings on configurations with known answers; the particle count."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.samples import (
    PAPER_GRADING,
    UniformByMass,
    disk_area_in_box,
    lens_area,
    nominal_porosity,
    overlap_corrected_porosity,
    particle_count,
)


def grid_area(centres, radii, box, n=1500):
    """Brute-force area of the union of disks inside the box, on an n x n grid of cell centres."""
    x0, y0, x1, y1 = box
    x = x0 + (np.arange(n) + 0.5) * (x1 - x0) / n
    y = y0 + (np.arange(n) + 0.5) * (y1 - y0) / n
    gx, gy = np.meshgrid(x, y)
    covered = np.zeros_like(gx, dtype=bool)
    for (cx, cy), r in zip(centres, radii, strict=True):
        covered |= (gx - cx) ** 2 + (gy - cy) ** 2 < r * r
    return covered.mean() * (x1 - x0) * (y1 - y0)


def test_lens_of_equal_disks_matches_the_textbook_formula():
    r = 1.0
    d = np.linspace(0.05, 1.95, 20)
    exact = 2 * r * r * np.arccos(d / (2 * r)) - 0.5 * d * np.sqrt(4 * r * r - d * d)
    assert np.allclose(lens_area(r, r, d), exact, rtol=1e-13, atol=1e-15)


def test_lens_limits():
    assert lens_area(1.0, 0.5, 2.0) == 0.0  # apart
    assert lens_area(1.0, 0.5, 1.5) == 0.0  # touching
    assert lens_area(1.0, 0.5, 0.3) == pytest.approx(math.pi * 0.25)  # the small one inside
    assert lens_area(1.0, 1.0, 0.0) == pytest.approx(math.pi)
    # continuous at internal tangency
    assert lens_area(1.0, 0.5, 0.5 + 1e-12) == pytest.approx(math.pi * 0.25, rel=1e-5)


def test_lens_of_unequal_disks_matches_a_grid_count():
    r1, r2, d = 1.0, 0.6, 1.2
    box = (-1.0, -1.0, 2.0, 1.0)
    union = grid_area([(0.0, 0.0), (d, 0.0)], [r1, r2], box, n=3000)
    lens = math.pi * (r1 * r1 + r2 * r2) - union
    assert float(lens_area(r1, r2, d)) == pytest.approx(lens, rel=2e-3)


def test_two_overlapping_disks_porosities():
    r = np.array([1.0e-3, 1.0e-3])
    xy = np.array([[1.0e-3, 1.0e-3], [2.8e-3, 1.0e-3]])  # 0.2 mm overlap
    box = (0.0, 0.0, 3.8e-3, 2.0e-3)
    area = 3.8e-3 * 2.0e-3
    lens = 2 * 1e-6 * math.acos(0.9) - 0.5 * 1.8e-3 * math.sqrt(4e-6 - 1.8e-3**2)
    assert nominal_porosity(r, area) == pytest.approx(1 - 2 * math.pi * 1e-6 / area, rel=1e-14)
    assert overlap_corrected_porosity(xy, r, box) == pytest.approx(1 - (2 * math.pi * 1e-6 - lens) / area, rel=1e-13)


def test_disks_clipped_at_edges_and_corners():
    box = (0.0, 0.0, 10.0, 6.0)
    r = np.array([1.0, 1.0, 2.0, 1.5])
    xy = np.array([[0.0, 3.0], [10.0, 6.0], [1.0, 5.5], [5.0, 0.4]])
    got = disk_area_in_box(xy, r, box)
    assert got[0] == pytest.approx(math.pi / 2, rel=1e-14)  # centre on an edge: half inside
    assert got[1] == pytest.approx(math.pi / 4, rel=1e-14)  # centre on a corner: a quarter
    # a disk crossing two edges near a corner, and one crossing one edge: against a grid count
    for k in (2, 3):
        assert got[k] == pytest.approx(grid_area([xy[k]], [r[k]], box, n=3000), rel=2e-3)


def test_overlap_corrected_matches_a_grid_count_on_a_random_packing():
    rng = np.random.default_rng(5)
    box = (0.0, 0.0, 10.0, 10.0)
    r = rng.uniform(0.4, 0.8, 60)
    xy = rng.uniform(0.3, 9.7, (60, 2))
    # keep it free of triple overlaps so the pairwise formula is exact
    from scipy.spatial.distance import cdist

    dist = cdist(xy, xy)
    over = (dist < r[:, None] + r[None, :]) & ~np.eye(60, dtype=bool)
    single = over.sum(axis=1) <= 1
    xy, r = xy[single], r[single]
    expected = 1 - grid_area(xy, r, box, n=3000) / 100.0
    assert overlap_corrected_porosity(xy, r, box) == pytest.approx(expected, abs=1e-3)


def test_periodic_overlap_across_the_cell_side():
    r = np.array([1.0, 1.0])
    xy = np.array([[0.2, 2.0], [9.0, 2.0]])  # 1.2 apart through the x = 0 side
    box = (0.0, 0.0, 10.0, 4.0)
    lens = float(lens_area(1.0, 1.0, 1.2))
    assert overlap_corrected_porosity(xy, r, box, periodic=True) == pytest.approx(1 - (2 * math.pi - lens) / 40.0)
    # with walls the disk at x = 0.2 is clipped instead and the pair does not overlap
    assert overlap_corrected_porosity(xy, r, box) > 1 - 2 * math.pi / 40.0


def test_particle_count_formula():
    area = 0.075 * 0.15
    assert particle_count(area, 0.12, PAPER_GRADING) == round(0.88 * area / (math.pi / 4 * 3.5833333e-6))
    assert particle_count(area, 0.12, PAPER_GRADING) == 3518
    g = UniformByMass(0.5e-3, 3e-3)  # mean d^2 = d_min d_max
    assert particle_count(area, 0.12, g) == round(0.88 * area / (math.pi / 4 * 1.5e-6))


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: particle_count(1.0, 1.2, PAPER_GRADING), "porosity"),
        (lambda: particle_count(-1.0, 0.2, PAPER_GRADING), "box_area"),
        (lambda: nominal_porosity([1e-3, -1e-3], 1.0), r"radii\[1\]"),
        (lambda: nominal_porosity([1e-3], 0.0), "area"),
        (lambda: overlap_corrected_porosity([[0, 0]], [1e-3], (1, 0, 0, 1)), "box"),
        (lambda: overlap_corrected_porosity([[0, 0], [1, 1]], [1e-3], (0, 0, 1, 1)), "positions"),
    ],
)
def test_bad_input_names_the_field(call, field):
    with pytest.raises(ValueError, match=field):
        call()
