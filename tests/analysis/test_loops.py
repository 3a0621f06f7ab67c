"""Loops of the contact network: cyclomatic number and minimal loops (docs/fabric.md, "Loops")."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import hex_lattice, square_lattice

from grainlab.analysis.loops import ContactLoops
from grainlab.snapshot import Snapshot

D = 1e-3


def test_hexagonal_lattice_has_triangles_only():
    loops = ContactLoops().compute(hex_lattice(8, 8))
    assert loops.n_loops == 128 and set(loops.loop_sizes.tolist()) == {3}
    assert loops.cyclomatic_number == 3 * 64 - 64 + 1  # periodic: one loop more than faces
    np.testing.assert_allclose(loops.grain_loop_size, 3.0)
    np.testing.assert_allclose(loops.size_distribution, [0, 0, 0, 1])


def test_square_lattice_has_squares_only():
    loops = ContactLoops().compute(square_lattice(6, 5))
    assert loops.n_loops == 30 and set(loops.loop_sizes.tolist()) == {4}
    assert loops.cyclomatic_number == 31


def test_bounded_patch_loops_number_the_independent_cycles():
    """A bounded hexagonal patch (no periodic box): the outer face is not a loop and
    the loops number E - V + 1."""
    x, y = np.meshgrid(np.arange(7.0), np.arange(6.0))
    pos = np.c_[(x + 0.5 * (y % 2)).ravel(), (y * np.sqrt(3) / 2).ravel()] * D
    snap = Snapshot.from_geometry(pos, np.full(len(pos), D / 2), tolerance=1e-9)
    loops = ContactLoops().compute(snap)
    assert loops.n_components == 1
    assert loops.n_loops == loops.cyclomatic_number == loops.n_edges - 42 + 1
    assert set(loops.loop_sizes.tolist()) == {3}


def test_a_missing_grain_makes_a_hexagon():
    snap = hex_lattice(8, 8)
    keep = np.arange(64) != 27
    edge = keep[snap.contact_i] & keep[snap.contact_j]
    idx = np.cumsum(keep) - 1
    holed = Snapshot(snap.positions[keep], snap.radii[keep], contact_i=idx[snap.contact_i[edge]],
                     contact_j=idx[snap.contact_j[edge]], box=snap.box, periodic=snap.periodic)
    loops = ContactLoops().compute(holed)
    assert sorted(np.bincount(loops.loop_sizes).tolist()) == sorted([0, 0, 0, 122, 0, 0, 1])
    assert loops.cyclomatic_number == loops.n_loops + 1


def test_rattlers_and_dangling_grains_are_left_out():
    """Triangle 0-1-2, grain 3 hanging on grain 2, grain 4 alone, a wall contact on 1."""
    pos = np.array([[0, 0], [1, 0], [0.5, np.sqrt(3) / 2], [0.5, np.sqrt(3) / 2 + 1], [5, 5]]) * D
    snap = Snapshot(pos, np.full(5, D / 2), contact_i=[0, 1, 2, 2, 1], contact_j=[1, 2, 0, 3, -1],
                    contact_point=np.zeros((5, 2)) + [[0, 0], [0, 0], [0, 0], [0, 0], [1.5e-3, 0]])
    loops = ContactLoops().compute(snap)
    assert loops.loop_sizes.tolist() == [3]
    np.testing.assert_array_equal(loops.in_graph, [True, True, True, False, False])
    assert loops.cyclomatic_number == 1
    kept = ContactLoops(remove_rattlers=False).compute(snap)
    assert kept.loop_sizes.tolist() == [3]  # the dangling branch lies in the outer face
    assert kept.cyclomatic_number == 4 - 5 + 2
    assert np.isnan(loops.grain_loop_size[3])


@pytest.mark.parametrize("rotation", [0.0, 33.0])
def test_square_with_a_diagonal(rotation):
    c, s = np.cos(np.radians(rotation)), np.sin(np.radians(rotation))
    pos = np.array([[0, 0], [1, 0], [1, 1], [0, 1]]) @ np.array([[c, s], [-s, c]])
    snap = Snapshot(pos, np.full(4, 0.75), contact_i=[0, 1, 2, 3, 0], contact_j=[1, 2, 3, 0, 2])
    loops = ContactLoops().compute(snap)
    assert sorted(loops.loop_sizes.tolist()) == [3, 3]
    np.testing.assert_allclose(loops.grain_loop_size, 3.0)
