"""measurement_circle_porosity: exact cases, a lattice of known porosity, validation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.samples import lens_area, measurement_circle_porosity


def _lens_textbook(r: float, big_r: float, d: float) -> float:
    """The textbook circle-circle intersection area (not lens_area's segment form)."""
    k = math.sqrt((-d + r + big_r) * (d + r - big_r) * (d - r + big_r) * (d + r + big_r))
    return (r * r * math.acos((d * d + r * r - big_r * big_r) / (2 * d * r))
            + big_r * big_r * math.acos((d * d + big_r * big_r - r * r) / (2 * d * big_r)) - 0.5 * k)


def _square_lattice(n: int, r: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """n x n touching disks of radius r on a square lattice of spacing 2r, lower corner at 0."""
    x, y = np.meshgrid((np.arange(n) + 0.5) * 2 * r, (np.arange(n) + 0.5) * 2 * r)
    return np.c_[x.ravel(), y.ravel()], np.full(n * n, r)


def test_disk_wholly_inside() -> None:
    n = measurement_circle_porosity([[0.3, -0.2]], [0.5], (0.0, 0.0), 2.0)
    assert n == pytest.approx(1.0 - 0.5**2 / 2.0**2, rel=1e-14)


def test_disk_wholly_outside_and_disk_covering_the_circle() -> None:
    assert measurement_circle_porosity([[5.0, 0.0]], [1.0], (0.0, 0.0), 2.0) == 1.0
    assert measurement_circle_porosity([[0.1, 0.0]], [3.0], (0.0, 0.0), 2.0) == pytest.approx(0.0, abs=1e-15)


def test_disk_cut_by_the_circle_edge() -> None:
    """A disk centred on the edge: exactly the textbook lens; about half the disk."""
    r, big_r = 1.0, 10.0
    n = measurement_circle_porosity([[0.0, big_r]], [r], (0.0, 0.0), big_r)
    inside = (1.0 - n) * math.pi * big_r**2
    assert inside == pytest.approx(_lens_textbook(r, big_r, big_r), rel=1e-12)
    # the circle bends away from the disk: less than half, by less than the chord's sagitta
    # band (the disk's diameter times the sagitta r^2 / (2 R))
    assert 0.5 * math.pi * r * r - 2 * r * r * r / (2 * big_r) < inside < 0.5 * math.pi * r * r


def test_square_lattice_large_circle() -> None:
    """1 - pi/4 within the bound 2 sqrt(2) pi r / R.

    Every lattice cell (side 2r) wholly inside the circle holds exactly pi/4 of
    its area in disk; only cells meeting the circle's edge can be off, each by at
    most pi r^2 (a disk's area). They lie within a cell diagonal, 2 sqrt(2) r, of
    the edge: at most 2 pi R 2 (2 sqrt(2) r) / (2r)^2 = 2 sqrt(2) pi R / r cells,
    so |n - (1 - pi/4)| <= 2 sqrt(2) pi R / r pi r^2 / (pi R^2) = 2 sqrt(2) pi r / R.
    """
    pos, rad = _square_lattice(200)
    big_r = 80.0
    n = measurement_circle_porosity(pos, rad, (100.0, 100.0), big_r)
    assert abs(n - (1.0 - math.pi / 4.0)) <= 2 * math.sqrt(2) * math.pi * 0.5 / big_r
    # the bound is loose: the cut cells' errors cancel nearly all
    assert n == pytest.approx(1.0 - math.pi / 4.0, abs=2e-3)


def test_square_lattice_mean_over_circle_positions_is_exact() -> None:
    """Averaged over circle centres uniform on one lattice cell the covered area is exactly
    pi/4 of the circle's (the lattice is periodic); the tolerance is 4 standard errors
    of the mean of the sampled centres."""
    pos, rad = _square_lattice(40)
    rng = np.random.default_rng(3)
    offsets = rng.uniform(0.0, 1.0, (64, 2))
    values = np.array([measurement_circle_porosity(pos, rad, (20.0 + dx, 20.0 + dy), 7.0)
                       for dx, dy in offsets])
    se = values.std(ddof=1) / math.sqrt(values.size)
    assert abs(values.mean() - (1.0 - math.pi / 4.0)) < 4 * se + 1e-12


def test_overlap_corrected_subtracts_the_lenses_inside() -> None:
    r, d = 1.0, 1.6  # two overlapping disks
    pos = np.array([[0.0, 0.0], [d, 0.0]])
    lens = float(lens_area(r, r, d))
    big_r = 5.0
    area = math.pi * big_r**2
    nominal = measurement_circle_porosity(pos, [r, r], (0.8, 0.0), big_r)
    corrected = measurement_circle_porosity(pos, [r, r], (0.8, 0.0), big_r, overlap_corrected=True)
    assert nominal == pytest.approx(1.0 - 2 * math.pi * r * r / area, rel=1e-14)
    assert corrected == pytest.approx(1.0 - (2 * math.pi * r * r - lens) / area, rel=1e-14)
    # the pair's chord midpoint (0.8, 0) outside a circle that still cuts both disks: no lens
    far = measurement_circle_porosity(pos, [r, r], (0.8, 4.0), 3.5, overlap_corrected=True)
    assert far == measurement_circle_porosity(pos, [r, r], (0.8, 4.0), 3.5)
    # touching disks have no lens: the two readings agree
    touching = np.array([[0.0, 0.0], [2.0, 0.0]])
    assert measurement_circle_porosity(touching, [r, r], (1.0, 0.0), big_r, overlap_corrected=True) == \
        measurement_circle_porosity(touching, [r, r], (1.0, 0.0), big_r)


@pytest.mark.parametrize(
    ("positions", "radii", "centre", "radius", "match"),
    [
        ([[0.0, 0.0]], [1.0], (0.0, 0.0), 0.0, "radius"),
        ([[0.0, 0.0]], [1.0], (0.0, 0.0), math.nan, "radius"),
        ([[0.0, 0.0]], [1.0], (0.0,), 1.0, "centre"),
        ([[0.0, 0.0]], [1.0], (0.0, math.inf), 1.0, "centre"),
        ([[0.0, 0.0]], [-1.0], (0.0, 0.0), 1.0, "radii"),
        ([[0.0, 0.0], [1.0, 1.0]], [1.0], (0.0, 0.0), 1.0, "positions"),
        ([[0.0, math.nan]], [1.0], (0.0, 0.0), 1.0, "positions"),
    ],
)
def test_validation(positions, radii, centre, radius, match) -> None:
    with pytest.raises(ValueError, match=match):
        measurement_circle_porosity(positions, radii, centre, radius)
