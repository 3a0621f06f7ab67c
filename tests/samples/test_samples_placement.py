"""Random placement: no overlaps, inside the box, seeded, and a clear error when too dense."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.distance import pdist

from grainlab.samples import PAPER_GRADING, PlacementError, particle_count, random_placement

BOX = (0.01, -0.02, 0.04, 0.04)


def place(seed, n=600, scale=0.5):
    rng = np.random.default_rng(seed)
    area = (BOX[2] - BOX[0]) * (BOX[3] - BOX[1])
    d = PAPER_GRADING.sample(min(n, particle_count(area, 0.12, PAPER_GRADING)), rng)
    return d, *random_placement(BOX, d, rng, scale=scale)


def test_no_overlaps_inside_the_box_in_input_order():
    d, xy, r = place(0)
    assert np.array_equal(r, 0.25 * d)
    assert np.all(xy[:, 0] - r >= BOX[0]) and np.all(xy[:, 0] + r <= BOX[2])
    assert np.all(xy[:, 1] - r >= BOX[1]) and np.all(xy[:, 1] + r <= BOX[3])
    gaps = pdist(xy) - (r[:, None] + r[None, :])[np.triu_indices(len(r), 1)]
    assert gaps.min() >= 0.0


def test_dense_placement_still_has_no_overlaps():
    _d, xy, r = place(1, scale=0.7)  # solid fraction 0.88 * 0.49 = 0.43
    gaps = pdist(xy) - (r[:, None] + r[None, :])[np.triu_indices(len(r), 1)]
    assert gaps.min() >= 0.0


def test_same_seed_same_positions():
    a = place(42)
    b = place(42)
    c = place(43)
    assert np.array_equal(a[1], b[1])
    assert not np.array_equal(a[1], c[1])


def test_too_dense_says_how_far_it_got():
    rng = np.random.default_rng(0)
    d = np.full(400, 2e-3)  # 400 disks of 2 mm in 30 x 30 mm: solid fraction 1.4 at full size
    with pytest.raises(PlacementError, match=r"placed \d+ of 400 disks \(solid fraction 0\.\d+"):
        random_placement((0, 0, 0.03, 0.03), d, rng, scale=1.0, max_rounds_without_progress=5)


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (((0, 0, 1, 1), [1e-3, -1e-3]), r"diameters\[1\]"),
        (((0, 0, 1, 1), [1e-3], 0.0), "scale"),
        (((0, 0, 1, 1), [1e-3], 1.5), "scale"),
        (((1, 0, 0, 1), [1e-3]), "box"),
        (((0, 0, 1e-3, 1e-3), [3e-3], 1.0), "does not fit"),
    ],
)
def test_bad_input_names_the_field(args, field):
    with pytest.raises(ValueError, match=field):
        random_placement(args[0], args[1], np.random.default_rng(0), *args[2:])
