"""Hexagonal and square lattices: exact porosities at contact, compressed and with vacancies."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.distance import pdist

from grainlab.samples import (
    HEXAGONAL_CONTACT_POROSITY,
    SQUARE_CONTACT_POROSITY,
    hexagonal_lattice,
    lens_area,
    square_lattice,
)

D = 0.875e-3


def test_contact_porosity_constants():
    assert HEXAGONAL_CONTACT_POROSITY == pytest.approx(0.0931, abs=5e-5)
    assert HEXAGONAL_CONTACT_POROSITY == 1 - math.pi / (2 * math.sqrt(3))
    assert SQUARE_CONTACT_POROSITY == pytest.approx(0.2146, abs=5e-5)


@pytest.mark.parametrize(
    ("make", "expected"),
    [(hexagonal_lattice, HEXAGONAL_CONTACT_POROSITY), (square_lattice, SQUARE_CONTACT_POROSITY)],
)
def test_periodic_lattice_at_contact_has_the_textbook_porosity(make, expected):
    lat = make(D, n_rows=8, n_cols=6)
    assert lat.porosity == pytest.approx(expected, abs=1e-13)
    assert lat.porosity_overlap_corrected == pytest.approx(expected, abs=1e-13)
    assert lat.n_particles == 48 and lat.n_vacancies == 0
    assert lat.spacing == D
    # nearest neighbours touch, nobody overlaps
    assert pdist(lat.positions).min() == pytest.approx(D, rel=1e-12)


def test_hexagonal_neighbours_in_the_periodic_cell():
    lat = hexagonal_lattice(D, n_rows=6, n_cols=5)
    x0, y0, x1, y1 = lat.box
    size = np.array([x1 - x0, y1 - y0])
    delta = lat.positions[:, None, :] - lat.positions[None, :, :]
    delta -= size * np.round(delta / size)
    dist = np.hypot(delta[..., 0], delta[..., 1])
    # every disk touches exactly six others through the periodic sides
    assert np.all(np.sum(np.abs(dist - D) < 1e-9 * D, axis=1) == 6)


def test_compressed_hexagonal_lattice_porosities_are_exact():
    lat = hexagonal_lattice(D, 0.08, n_rows=10, n_cols=8)
    a = D * math.sqrt((1 - HEXAGONAL_CONTACT_POROSITY) / 0.92)
    assert lat.spacing == pytest.approx(a, rel=1e-15)
    assert lat.porosity == pytest.approx(0.08, abs=1e-13)
    area = (lat.box[2] - lat.box[0]) * (lat.box[3] - lat.box[1])
    # each disk overlaps six neighbours: per disk, three lenses
    covered = lat.n_particles * (math.pi * D * D / 4 - 3 * float(lens_area(D / 2, D / 2, a)))
    assert lat.porosity_overlap_corrected == pytest.approx(1 - covered / area, abs=1e-13)
    assert lat.porosity_overlap_corrected > lat.porosity
    assert "compressed" in lat.note and "0.0800 nominal" in lat.note


def test_compressed_square_lattice_porosities_are_exact():
    lat = square_lattice(D, 0.10, n_rows=7, n_cols=9)
    a = D * math.sqrt((1 - SQUARE_CONTACT_POROSITY) / 0.90)
    assert lat.porosity == pytest.approx(0.10, abs=1e-13)
    area = (lat.box[2] - lat.box[0]) * (lat.box[3] - lat.box[1])
    covered = lat.n_particles * (math.pi * D * D / 4 - 2 * float(lens_area(D / 2, D / 2, a)))
    assert lat.porosity_overlap_corrected == pytest.approx(1 - covered / area, abs=1e-13)


def test_vacancies_above_the_contact_porosity():
    lat = hexagonal_lattice(D, 0.15, n_rows=40, n_cols=30, rng=3)
    area = (lat.box[2] - lat.box[0]) * (lat.box[3] - lat.box[1])
    disk = math.pi * D * D / 4
    assert lat.spacing == D
    assert lat.n_sites == 1200
    assert lat.n_vacancies == 1200 - round(0.85 * area / disk)
    assert abs(lat.porosity - 0.15) <= 0.5 * disk / area
    assert lat.porosity_overlap_corrected == pytest.approx(lat.porosity, abs=1e-13)
    assert "vacant" in lat.note
    again = hexagonal_lattice(D, 0.15, n_rows=40, n_cols=30, rng=3)
    other = hexagonal_lattice(D, 0.15, n_rows=40, n_cols=30, rng=4)
    assert np.array_equal(lat.positions, again.positions)
    assert not np.array_equal(lat.positions, other.positions)


def test_periodic_box_is_rounded_to_whole_periods():
    lat = hexagonal_lattice(D, box=(0.0, 0.0, 0.075, 0.15))
    x0, y0, x1, y1 = lat.box
    assert (x1 - x0) == pytest.approx(round(0.075 / D) * D)
    rows = round((y1 - y0) / (D * math.sqrt(3) / 2))
    assert rows % 2 == 0
    assert lat.porosity == pytest.approx(HEXAGONAL_CONTACT_POROSITY, abs=1e-12)


def test_walled_box_lattice_stays_inside_and_reaches_targets():
    box = (0.0, 0.0, 0.02, 0.03)
    for target in (0.08, 0.12, 0.15):
        lat = hexagonal_lattice(D, target, box=box, boundary="walls", rng=0)
        p, r = lat.positions, lat.radii
        assert np.all(p - r[:, None] >= -1e-15) and np.all(p[:, 0] + r <= 0.02 + 1e-15)
        assert np.all(p[:, 1] + r <= 0.03 + 1e-15)
        disk = math.pi * D * D / 4
        assert abs(lat.porosity - target) <= 0.5 * disk / (0.02 * 0.03) + 1e-12
        assert lat.porosity_overlap_corrected >= lat.porosity - 1e-12
    assert lat.contact_porosity > HEXAGONAL_CONTACT_POROSITY  # gaps along the walls


def test_walled_lattice_fitted_around_rows_and_columns():
    lat = hexagonal_lattice(D, n_rows=6, n_cols=5, boundary="walls")
    assert lat.n_particles == 6 * 5 - 3  # odd rows hold one disk fewer
    assert lat.box == pytest.approx((0.0, 0.0, 5 * D, 5 * D * math.sqrt(3) / 2 + D))
    dense = hexagonal_lattice(D, lat.porosity - 0.05, n_rows=6, n_cols=5, boundary="walls")
    assert dense.porosity == pytest.approx(lat.porosity - 0.05, abs=1e-12)
    assert dense.spacing < D


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"diameter": -1e-3, "n_rows": 2, "n_cols": 2}, "diameter"),
        ({"diameter": 1e-3, "porosity": 1.5, "n_rows": 2, "n_cols": 2}, "porosity"),
        ({"diameter": 1e-3, "n_rows": 3, "n_cols": 2}, "n_rows"),
        ({"diameter": 1e-3}, "box"),
        ({"diameter": 1e-3, "n_rows": 2, "n_cols": 2, "boundary": "open"}, "boundary"),
        ({"diameter": 1e-3, "box": (0, 0, 1, 1), "n_rows": 2, "n_cols": 2}, "box"),
    ],
)
def test_bad_input_names_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        hexagonal_lattice(**kwargs)
