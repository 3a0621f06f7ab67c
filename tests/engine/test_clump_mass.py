"""grainlab.clump_mass_properties: the exact properties of a union of disks
against a NumPy raster with a rigorous error bracket, and bad input refused."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import grainlab
from grainlab import clump_mass_properties

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "13_clump_mass.py"


def _classify(x, y, size, centres, radii):
    """Cells of side ``size`` at ``(x, y)``: wholly in some disk, undecided
    (neither wholly in one nor wholly out of all), and the weights of
    ``1, x, y, x^2 + y^2`` integrated over each cell."""
    dist = np.hypot(x[:, None] - centres[:, 0], y[:, None] - centres[:, 1])
    reach = size / np.sqrt(2)
    inside = (dist + reach <= radii).any(1)
    undecided = ~inside & ~(dist - reach >= radii).all(1)
    weights = size**2 * np.stack([np.ones_like(x), x, y, x * x + y * y + size**2 / 6])
    return inside, undecided, (dist < radii).any(1), weights


def raster(centres, radii, cells=1000, sub=16):
    """Area, first moments and polar moment about the origin, each with the
    bound of its error.

    A cell of side ``h`` whose centre is more than ``h / sqrt 2`` inside some
    disk, or outside every disk, is wholly in or out and counts exactly; each
    other cell is split into ``sub x sub`` subcells, decided the same way, and
    the subcells still undecided count by their centres: each may be wrong by
    at most the integral of ``|f|`` over it, which the bound sums (about
    ``1.3 L h / sub`` for the area, ``L`` the boundary's length).
    """
    centres, radii = np.asarray(centres, float), np.asarray(radii, float)
    lo, hi = (centres - radii[:, None]).min(0), (centres + radii[:, None]).max(0)
    h = (hi - lo).max() / cells
    axis = lo[:, None] + (np.arange(cells) + 0.5) * h
    x, y = (a.ravel() for a in np.meshgrid(axis[0], axis[1], indexing="ij"))
    inside, undecided, _, weights = _classify(x, y, h, centres, radii)
    totals = weights[:, inside].sum(1)
    k = ((np.arange(sub) + 0.5) / sub - 0.5) * h
    x = (x[undecided][:, None, None] + k[None, :, None] + 0 * k[None, None, :]).ravel()
    y = (y[undecided][:, None, None] + 0 * k[None, :, None] + k[None, None, :]).ravel()
    size = h / sub
    inside, undecided, centre_in, weights = _classify(x, y, size, centres, radii)
    totals += weights[:, inside | (undecided & centre_in)].sum(1)
    far = np.abs(x) + np.abs(y) + size
    bounds = size**2 * np.stack([np.ones_like(x), far, far, far * far])[:, undecided].sum(1)
    return totals, bounds


def about_origin(props):
    c = props.centroid_m
    a = props.area_m2
    return np.array([a, a * c[0], a * c[1], props.moment_of_inertia_kg_m2 + a * (c @ c)])


CASES = {
    "pair": ([[0.0, 0.0], [1.1e-3, 0.4e-3]], [1e-3, 0.6e-3]),
    "trio": ([[0.0, 0.5e-3], [0.45e-3, -0.3e-3], [-0.5e-3, -0.35e-3]], [0.8e-3, 0.7e-3, 0.9e-3]),
    "ring": (
        [[2e-3 * np.cos(t), 2e-3 * np.sin(t)] for t in np.arange(8) * np.pi / 4 + 0.1],
        [1e-3] * 8,
    ),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_union_against_a_raster(name):
    centres, radii = CASES[name]
    exact = about_origin(clump_mass_properties(centres, radii, density=1.0))
    counted, bound = raster(centres, radii)
    assert (np.abs(exact - counted) <= bound).all(), (exact, counted, bound)
    # the bracket is narrow: a lens counted twice or a hole counted as material would fail it
    assert bound[0] < 2e-3 * exact[0]


def test_ring_leaves_its_hole_out_and_mass_is_density_times_area():
    centres, radii = CASES["ring"]
    props = clump_mass_properties(centres, radii, density=2650.0)
    d = 4e-3 * np.sin(np.pi / 8)
    lens = 2e-6 * np.arccos(d / 2e-3) - d / 2 * np.sqrt(4e-6 - d * d)
    assert props.area_m2 == pytest.approx(8 * (np.pi * 1e-6 - lens), rel=1e-13)
    assert props.mass_kg == 2650.0 * props.area_m2
    assert np.abs(props.centroid_m).max() < 1e-17
    assert props.body_offsets_m == pytest.approx(np.asarray(centres), abs=1e-18)


def test_one_pebble_is_the_simulations_disk():
    props = clump_mass_properties([[0.3, 0.1]], [1e-3], density=2650.0)
    sim = grainlab.Simulation(positions=[[0.3, 0.1]], radii=[1e-3], density=2650.0)
    assert props.mass_kg == sim.masses[0]
    assert props.moment_of_inertia_kg_m2 == sim.inertias[0]
    with pytest.raises(ValueError, match="read-only"):
        props.centroid_m[0] = 1.0


@pytest.mark.parametrize(
    ("offsets", "radii", "density", "field"),
    [
        (np.zeros((0, 2)), [], 1.0, "radii"),
        ([[0.0, 0.0]], [-1.0], 1.0, r"radii\[0\]"),
        ([[0.0, 0.0], [1.0, 0.0]], [1.0, np.nan], 1.0, r"radii\[1\]"),
        ([[0.0, np.inf]], [1.0], 1.0, "offsets"),
        ([0.0, 0.0], [1.0], 1.0, "offsets"),
        ([[0.0, 0.0]], [1.0, 2.0], 1.0, "radii"),
        ([[0.0, 0.0]], [1.0], 0.0, "density"),
    ],
)
def test_bad_input_is_refused_in_one_line_naming_it(offsets, radii, density, field):
    with pytest.raises(ValueError, match=f"^{field}") as error:
        clump_mass_properties(offsets, radii, density=density)
    assert "\n" not in str(error.value)


def test_example_prints_a_trimer_beside_its_raster():
    out = subprocess.run(
        [sys.executable, str(EXAMPLE)], capture_output=True, text=True, check=True
    ).stdout
    exact, counted = (
        float(v) for v in re.search(r"area .*?: exact (\S+) m\^2, raster (\S+)", out).groups()
    )
    assert abs(exact - counted) < 1e-3 * exact, out
