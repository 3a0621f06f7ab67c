"""Power cells (radical Voronoi) and local porosity (docs/fabric.md, "Local porosity")."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import hex_lattice, jittered_packing, square_lattice

from grainlab.analysis.tessellation import LocalPorosity, _rim_sites, power_cells
from grainlab.snapshot import ParticleKind, Snapshot

D = 1e-3


@pytest.mark.parametrize("size", [(8, 8), (5, 6)])
def test_periodic_hexagonal_lattice_cells_are_hexagons(size):
    snap = hex_lattice(*size)
    porosity = LocalPorosity().compute(snap)
    np.testing.assert_allclose(porosity.cell_area, np.sqrt(3) / 2 * D**2, rtol=1e-10)
    np.testing.assert_allclose(porosity.local_porosity, 1 - np.pi / (2 * np.sqrt(3)), rtol=1e-9)
    assert porosity.porosity == pytest.approx(1 - np.pi / (2 * np.sqrt(3)))
    corners = porosity.cells.vertices
    for p in (0, snap.n_particles - 1):  # six distinct corners at d / sqrt(3) from the centre
        mine = corners[porosity.cells.offsets[p] : porosity.cells.offsets[p + 1]]
        distinct = np.unique(np.round(mine / D, 9), axis=0)
        assert len(distinct) == 6
        d = snap.minimum_image(distinct * D - snap.positions[p])
        np.testing.assert_allclose(np.hypot(*d.T), D / np.sqrt(3), rtol=1e-9)


def test_square_lattice_cells_are_squares():
    np.testing.assert_allclose(LocalPorosity().compute(square_lattice(6, 5)).cell_area, D**2, rtol=1e-10)


def polydisperse_periodic(seed: int, n: int = 300) -> Snapshot:
    """Random non-overlapping polydisperse disks in a periodic box (drawn with rejection)."""
    rng = np.random.default_rng(seed)
    box = np.array([[0.0, 30 * D], [0.0, 20 * D]])
    pos, rad = [], []
    while len(pos) < n:
        x = rng.uniform(box[:, 0], box[:, 1])
        r = rng.uniform(0.3, 0.7) * D
        if pos:
            d = np.asarray(pos) - x
            d -= (box[:, 1] - box[:, 0]) * np.round(d / (box[:, 1] - box[:, 0]))
            if np.any(np.hypot(*d.T) < np.asarray(rad) + r):
                continue
        pos.append(x)
        rad.append(r)
    return Snapshot(np.asarray(pos), np.asarray(rad), box=box, periodic=(True, True))


def test_cells_tile_the_region():
    periodic = polydisperse_periodic(1)
    cells = power_cells(periodic)
    assert cells.area.sum() == pytest.approx(600 * D**2, rel=1e-10)
    assert np.all(cells.area > np.pi * periodic.radii**2)  # each disk inside its cell
    bounded = jittered_packing(15, 12, seed=3)
    cells = power_cells(bounded)
    x, r = bounded.positions, bounded.radii[:, None]
    expected = np.prod((x + r).max(axis=0) - (x - r).min(axis=0))
    assert cells.area.sum() == pytest.approx(expected, rel=1e-10)
    np.testing.assert_allclose(cells.bounds[:, 0], (x - r).min(axis=0))
    # periodic along x only: the region widened along y to hold the disks across its edges
    half = Snapshot(periodic.positions, periodic.radii, box=periodic.box, periodic=(True, False))
    y, r = half.positions[:, 1], half.radii
    height = max(20 * D, (y + r).max()) - min(0.0, (y - r).min())
    assert height > 20 * D
    assert power_cells(half).area.sum() == pytest.approx(30 * D * height, rel=1e-10)


def test_the_cell_boundary_of_two_touching_disks_runs_through_their_contact():
    """Power cells, not Voronoi cells: the wall between disks of radii 1 and 2 mm that
    touch at x = 1 mm is at x = 1 mm (the plain bisector would be at 1.5 mm)."""
    snap = Snapshot([[0, 0], [3 * D, 0], [0, 10 * D], [3 * D, 10 * D]], np.r_[1, 2, 1, 2] * D,
                    box=[[-5 * D, 5 * D], [-5 * D, 15 * D]])
    cells = power_cells(snap)
    mine = cells.vertices[cells.offsets[0] : cells.offsets[1]]
    assert mine[:, 0].max() == pytest.approx(1 * D)
    assert cells.area[0] == pytest.approx(6 * D * 10 * D)  # x in [-5, 1] mm, y in [-5, 5] mm


def test_membrane_disks_get_cells_but_no_porosity():
    snap = hex_lattice(6, 6)
    kind = np.zeros(snap.n_particles, int)
    kind[:6] = ParticleKind.MEMBRANE
    marked = Snapshot(snap.positions, snap.radii, kind=kind, box=snap.box, periodic=snap.periodic)
    porosity = LocalPorosity().compute(marked)
    assert np.isnan(porosity.local_porosity[:6]).all()
    assert np.isfinite(porosity.local_porosity[6:]).all()
    assert porosity.cell_area[:6] == pytest.approx(np.sqrt(3) / 2 * D**2)


def test_too_few_disks():
    with pytest.raises(ValueError, match="at least 3"):
        power_cells(Snapshot([[0, 0], [1, 0]], [0.5, 0.5]))


def test_a_leaning_periodic_cell_is_tiled_and_the_same_lattice_gives_the_same_cells():
    """A cell sheared along x (tilt t) repeats on the lattice (L, 0), (t, L); the cells of its
    disks tile it (their areas sum to L^2), and the same disks described with tilt t - L (the
    same lattice, after the engine's remap) have the same cells."""
    from grainlab.analysis.tessellation import power_cells
    from grainlab.snapshot import Snapshot

    rng = np.random.default_rng(3)
    side, n = 10.0, 60
    y = rng.uniform(0.0, side, n)
    x = rng.uniform(0.0, side, n) + 0.3 * y  # inside the parallelogram of tilt 3
    radii = rng.uniform(0.2, 0.4, n)

    def cells(tilt: float) -> np.ndarray:
        snap = Snapshot(np.column_stack([x, y]), radii, box=[[0.0, side], [0.0, side]], periodic=(True, True), tilt=tilt)
        return power_cells(snap).area

    areas = cells(3.0)
    assert areas.sum() == pytest.approx(side * side, rel=1e-9)
    assert np.all(areas > 0)
    np.testing.assert_allclose(cells(3.0 - side), areas, rtol=1e-8)


def test_the_rim_of_a_triangle_fan_leaves_out_its_inner_points():
    """The closed-cell test reads the rim: the points on an edge of one triangle only.
    A hexagon fanned about its centre 0 (points 1-6) has its centre inside; two
    triangles sharing the edge 7-8 have all four of their corners on the rim."""
    fan = np.array([[0, k, k % 6 + 1] for k in range(1, 7)])
    pair = np.array([[7, 8, 9], [8, 7, 10]])
    assert _rim_sites(fan, 11).tolist() == [1, 2, 3, 4, 5, 6]
    assert _rim_sites(pair, 11).tolist() == [7, 8, 9, 10]
    both = _rim_sites(np.concatenate([fan, pair]).astype(np.int32), 11)
    assert both.tolist() == [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]
