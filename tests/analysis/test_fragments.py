"""Fragments (grainlab.analysis.fragments): the connected components of a bond graph,
their areas conserving the solid area, their equivalent-area diameters and grading."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.analysis.fragments import fragment_labels, fragment_sizes, percent_passing


def test_the_fragments_are_the_connected_components_and_conserve_the_solid_area():
    rng = np.random.default_rng(4)
    n = 200
    i = rng.integers(0, n, 150)
    j = rng.integers(0, n, 150)
    keep = i != j
    labels = fragment_labels(n, i[keep], j[keep])
    assert np.all(labels[i[keep]] == labels[j[keep]])  # each bond within one fragment
    assert labels[0] == 0 and set(labels.tolist()) == set(range(labels.max() + 1))
    radii = rng.uniform(0.5, 1.5, n)
    area, size = fragment_sizes(radii, labels)
    np.testing.assert_allclose(area.sum(), np.pi * np.sum(radii**2), rtol=1e-12)
    np.testing.assert_allclose(np.pi * size**2 / 4, area, rtol=1e-12)
    alone = np.setdiff1d(np.arange(n), np.r_[i[keep], j[keep]])
    np.testing.assert_allclose(size[labels[alone]], 2 * radii[alone])  # an unbonded disk is its own fragment


def test_percent_passing_counts_the_area_at_most_each_size():
    sizes, areas = np.array([3.0, 1.0, 2.0]), np.array([1.0, 2.0, 1.0])
    assert percent_passing(sizes, areas, [0.5, 1.0, 2.5, 3.0]).tolist() == [0.0, 50.0, 75.0, 100.0]


def test_a_bond_outside_the_disks_is_refused():
    with pytest.raises(ValueError, match="outside 0 .. 2"):
        fragment_labels(3, [0], [3])
