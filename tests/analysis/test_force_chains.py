"""Force chains by Peters et al.'s criterion on constructed loads (docs/fabric.md, "Force chains")."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import hex_lattice

from grainlab.analysis.force_chains import ForceChains
from grainlab.snapshot import Snapshot

D = 1e-3


def square_patch(nx: int, ny: int) -> Snapshot:
    """A bounded square lattice of touching disks of diameter D."""
    x, y = np.meshgrid(np.arange(nx) * D, np.arange(ny) * D)
    return Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(nx * ny, D / 2), tolerance=1e-9)


def test_a_loaded_column_is_one_vertical_chain_of_its_length():
    snap = square_patch(9, 7)
    n = snap.contact_normals()
    column = (np.abs(n[:, 1]) > 0.99) & np.isclose(snap.positions[snap.contact_i, 0], 4 * D)
    loaded = snap.with_contacts(snap.contact_i, snap.contact_j,
                                normal_force=np.where(column, 50.0, 1.0))
    chains = ForceChains().compute(loaded)
    assert chains.n_chains == 1
    assert chains.lengths.tolist() == [7]
    assert np.degrees(chains.orientations[0]) == pytest.approx(90.0)
    in_column = np.isclose(snap.positions[:, 0], 4 * D)
    np.testing.assert_array_equal(chains.chain >= 0, in_column)
    np.testing.assert_array_equal(chains.links, column)
    assert chains.fraction_in_chains == pytest.approx(7 / 63)
    assert chains.summary()["max_length"] == 7


def test_a_uniform_load_has_no_chain():
    snap = hex_lattice(8, 8)
    uniform = snap.with_contacts(snap.contact_i, snap.contact_j,
                                 normal_force=np.ones(snap.n_contacts))
    chains = ForceChains().compute(uniform)
    assert chains.n_chains == 0 and not chains.highly_stressed.any()
    assert np.isnan(chains.mean_length)


def test_an_inclined_chain_and_the_angle_criterion():
    """One line of 60 deg contacts loaded in a periodic hexagonal lattice: one chain
    of that line's grains along 60 deg, found with a 10 deg cone too (the grains'
    major directions are 60 deg exactly); a stronger load along x turns the major
    directions away and links nothing along the line."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    snap = hex_lattice(8, 8)
    n = snap.contact_normals()
    along = np.isclose(np.mod(np.degrees(np.arctan2(n[:, 1], n[:, 0])), 180.0), 60.0)
    graph = coo_matrix((np.ones(along.sum()), (snap.contact_i[along], snap.contact_j[along])),
                       shape=(64, 64))
    label = connected_components(graph, directed=False)[1]
    line = along & (label[snap.contact_i] == label[0])
    grains = label == label[0]
    assert 3 <= grains.sum() < 64
    loaded = snap.with_contacts(snap.contact_i, snap.contact_j,
                                normal_force=np.where(line, 20.0, 1.0))
    for cone in (45.0, 10.0):
        chains = ForceChains(angle=cone).compute(loaded)
        assert chains.lengths.tolist() == [int(grains.sum())]
        np.testing.assert_array_equal(chains.chain >= 0, grains)
        assert np.degrees(chains.orientations[0]) == pytest.approx(60.0)
    flat = np.isclose(np.mod(np.degrees(np.arctan2(n[:, 1], n[:, 0])), 180.0), 0.0)
    across = snap.with_contacts(
        snap.contact_i, snap.contact_j,
        normal_force=np.where(line, 20.0, 1.0)
        + np.where(flat & (grains[snap.contact_i] | grains[snap.contact_j]), 200.0, 0.0),
    )
    assert ForceChains(angle=45.0).compute(across).links[line].sum() == 0


def test_minimum_length():
    snap = square_patch(5, 5)
    n = snap.contact_normals()
    pair = (np.abs(n[:, 1]) > 0.99) & np.isclose(snap.positions[snap.contact_i, 0], 2 * D) & (
        snap.positions[snap.contact_i, 1] < 0.5 * D
    )
    assert pair.sum() == 1
    loaded = snap.with_contacts(snap.contact_i, snap.contact_j, normal_force=np.where(pair, 50.0, 1.0))
    assert ForceChains().compute(loaded).n_chains == 0  # two grains are not a chain
    assert ForceChains(min_grains=2).compute(loaded).lengths.tolist() == [2]


def test_bad_parameters():
    with pytest.raises(ValueError, match="angle"):
        ForceChains(angle=120.0)
    with pytest.raises(ValueError, match="min_grains"):
        ForceChains(min_grains=1)
