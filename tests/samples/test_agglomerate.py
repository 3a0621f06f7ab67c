"""The agglomerate builder (grainlab.samples.agglomerate): every disk inside the grain's
circle and none overlapping, every bond between lattice neighbours of one grain, each
grain's bond graph connected, the draws seeded and each grain's stream its own, and bad
input refused in one line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.analysis.fragments import fragment_labels
from grainlab.samples.agglomerate import (
    BondStrengths,
    agglomerate_stream,
    build_agglomerate,
    build_agglomerates,
)

STRENGTHS = BondStrengths(1e6, 2e6, 0.2)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize(("d", "a", "vacancies", "scatter"), [(2e-3, 0.2e-3, 0.05, 0.1), (1e-3, 0.15e-3, 0.2, 0.3),
                                                               (3e-3, 0.3e-3, 0.0, 0.0)])
def test_every_disk_lies_inside_the_circle_no_two_overlap_and_the_bonds_join_lattice_neighbours(seed, d, a, vacancies,
                                                                                                scatter):
    centre = np.array([0.3, -0.1])
    grain = build_agglomerate(d, a, np.random.default_rng(seed), vacancies=vacancies, size_scatter=scatter,
                              strengths=STRENGTHS, centre=centre)
    x, r = grain.positions - centre, grain.radii
    assert np.all(np.hypot(x[:, 0], x[:, 1]) + r <= 0.5 * d * (1 + 1e-12))
    assert np.all((r <= 0.5 * a) & (r >= 0.5 * a * (1 - scatter)))
    gaps = np.hypot(*(x[:, None, :] - x[None, :, :]).transpose(2, 0, 1)) - r[:, None] - r[None, :]
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() >= -1e-12 * a  # no overlap
    i, j = grain.bond_i, grain.bond_j
    assert np.all(i < j) and len(set(zip(i.tolist(), j.tolist(), strict=True))) == grain.n_bonds
    np.testing.assert_allclose(np.hypot(*(x[j] - x[i]).T), a, rtol=1e-9)  # one lattice spacing apart
    # every pair of lattice neighbours is bonded (the pairs one spacing apart)
    near = np.argwhere(np.triu(np.isclose(gaps + r[:, None] + r[None, :], a, rtol=1e-9), 1))
    assert len(near) == grain.n_bonds
    # the bond graph is connected at creation
    assert np.all(fragment_labels(grain.n_disks, i, j) == 0)


def test_a_full_lattice_fills_the_circle_and_the_draws_are_seeded_per_grain():
    d, a = 2e-3, 0.2e-3
    full = build_agglomerate(d, a, np.random.default_rng(0), vacancies=0.0, size_scatter=0.0, strengths=STRENGTHS)
    assert np.all(full.radii == 0.5 * a)
    # about the circle's area over a lattice cell's, less the sites whose disk crosses the rim
    cells = math.pi * (0.5 * (d - a)) ** 2 / (math.sqrt(3) / 2 * a * a)
    assert 0.85 * cells < full.n_disks < 1.1 * cells
    one = build_agglomerate(d, a, agglomerate_stream(5, 2), strengths=STRENGTHS, centre=(2.0, 0.0))
    again = build_agglomerates([[0, 0], [1, 0], [2, 0]], [d, d, d], a, 5, strengths=STRENGTHS)
    rows = again.agglomerate == 2
    np.testing.assert_array_equal(again.positions[rows], one.positions)
    np.testing.assert_array_equal(again.tensile_strength[-one.n_bonds:], one.tensile_strength)
    assert not np.array_equal(again.positions[again.agglomerate == 0], one.positions)
    assert np.bincount(again.agglomerate).tolist() == [int(np.sum(again.agglomerate == k)) for k in range(3)]
    # the joined bonds stay within each grain
    assert np.all(again.agglomerate[again.bond_i] == again.agglomerate[again.bond_j])
    np.testing.assert_allclose(again.solid_areas()[2], np.pi * np.sum(one.radii**2))


def test_the_strengths_are_drawn_with_the_scatter_asked():
    grains = build_agglomerates(np.zeros((40, 2)), np.full(40, 2e-3), 0.2e-3, 1, strengths=STRENGTHS)
    sigma, c = grains.tensile_strength, grains.cohesion
    assert abs(sigma.mean() / 1e6 - 1) < 0.02 and abs(sigma.std() / sigma.mean() - 0.2) < 0.02
    assert abs(c.mean() / 2e6 - 1) < 0.02
    even = build_agglomerate(2e-3, 0.2e-3, np.random.default_rng(1), strengths=BondStrengths(1e6, 1e6))
    assert np.all(even.tensile_strength == 1e6) and np.all(even.cohesion == 1e6)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"diameter": -1.0}, "diameter: must be a diameter (m) in (0, inf), got -1.0"),
    ({"disk_diameter": 1e-3}, "disk_diameter: a grain is at least 3 disks across"),
    ({"vacancies": 0.6}, "vacancies: must be a fraction in [0, 0.5], got 0.6"),
    ({"size_scatter": -0.1}, "size_scatter: must be a fraction in [0, 0.5]"),
])
def test_bad_input_is_refused_in_one_line(kwargs, message):
    args = {"diameter": 2e-3, "disk_diameter": 0.2e-3, **kwargs}
    with pytest.raises(ValueError) as error:
        build_agglomerate(args.pop("diameter"), args.pop("disk_diameter"), np.random.default_rng(0),
                          strengths=STRENGTHS, **args)
    assert message in str(error.value) and "\n" not in str(error.value)
    with pytest.raises(ValueError, match="diameters: 1 for 2 centres"):
        build_agglomerates([[0, 0], [1, 1]], [2e-3], 0.2e-3, 0, strengths=STRENGTHS)
