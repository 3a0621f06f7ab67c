"""The outer contour of variant B's boundary (docs/boundary.md): the grains along
each side of the sample, each touching the next, from platen to platen."""

import numpy as np
import pytest

from grainlab.protocols.boundary import outer_contour


def lattice(columns: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit disks touching in a square lattice between y = 0 and y = 2 rows; index
    ``row * columns + column``."""
    i, j = np.meshgrid(np.arange(columns), np.arange(rows))
    positions = np.column_stack([1.0 + 2.0 * i.ravel(), 1.0 + 2.0 * j.ravel()]).astype(float)
    return positions, np.ones(len(positions))


def contour(positions, radii, side, height):
    return outer_contour(positions, radii, np.arange(len(radii)), 0.0, height, side, gap=0.1)


def test_the_contour_of_a_lattice_is_its_outer_columns():
    x, r = lattice(5, 8)
    assert contour(x, r, "left", 16.0) == [5 * row for row in range(8)]
    assert contour(x, r, "right", 16.0) == [5 * row + 4 for row in range(8)][::-1]


def test_a_grain_hanging_by_one_contact_is_cut_off_and_one_in_a_notch_taken():
    x, r = lattice(5, 8)
    hanging = [-1.0, 9.0]  # touches only the left column's grain of row 4
    notch = [1.0 - np.sqrt(3.0), 4.0]  # touches the left column's grains of rows 1 and 2
    x = np.vstack([x, hanging, notch])
    r = np.ones(len(x))
    left = contour(x, r, "left", 16.0)
    column = [5 * row for row in range(8)]
    assert left == column[:2] + [41] + column[2:]
    # each grain touches the next one: the chain is continuous
    steps = np.linalg.norm(np.diff(x[left], axis=0), axis=1)
    assert np.all(steps <= 2.0 + 0.1)


def test_the_right_contour_walks_down_with_the_sample_on_its_right():
    x, r = lattice(3, 4)
    x[[2, 8], 0] += 0.05  # open contacts within the gap still count
    right = contour(x, r, "right", 8.0)
    assert right == [11, 8, 5, 2]
    # walking down, the sample (the other grains) lies on the walker's right: -x
    walk = np.diff(x[right], axis=0)
    assert np.all(walk[:, 1] < 0)


def test_no_path_from_platen_to_platen_is_an_error():
    x, r = lattice(4, 6)
    x[12:, 1] += 1.0  # rows 3 to 5 lifted by one radius: the sample is cut in two
    with pytest.raises(ValueError, match="did not reach the other platen"):
        contour(x, r, "left", 13.0)
    with pytest.raises(ValueError, match="side"):
        contour(x, r, "top", 13.0)
