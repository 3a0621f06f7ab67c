r"""The power diagram (radical Voronoi tessellation) of a disk packing and local porosity
(docs/fabric.md, "Local porosity").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import sample_bounds
from grainlab.snapshot import Snapshot

__all__ = ["LocalPorosity", "PowerCells", "power_cell_areas", "power_cells"]


@dataclass(frozen=True, eq=False)
class PowerCells:
    """The power cells of a snapshot's particles.

    ``vertices`` (M, 2) m are the cells' corners, cell p's counter-clockwise
    from ``offsets[p]`` to ``offsets[p + 1]``; ``area`` (N,) m^2 (0 for a
    particle without a cell, which only a disk covered by others can be);
    ``bounds`` (2, 2) the region tessellated.
    """

    vertices: NDArray[np.float64]
    offsets: NDArray[np.int64]
    area: NDArray[np.float64]
    bounds: NDArray[np.float64]


def _region(snapshot: Snapshot) -> NDArray[np.float64]:
    """The region tessellated: :func:`sample_bounds`, widened in bounded directions
    to hold every disk."""
    bounds = sample_bounds(snapshot)
    x = np.asarray(snapshot.positions)
    r = np.asarray(snapshot.radii)[:, None]
    for axis in (0, 1):
        if not snapshot.periodic[axis]:
            bounds[axis, 0] = min(bounds[axis, 0], float((x - r)[:, axis].min()))
            bounds[axis, 1] = max(bounds[axis, 1], float((x + r)[:, axis].max()))
    return bounds


def _images(
    x: NDArray[np.float64],
    bounds: NDArray[np.float64],
    periodic: tuple[bool, bool],
    margin: float,
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The points and their images within ``margin`` of the region's edges:
    (K,) source index and (K, 2) position, the N originals first."""
    source = np.arange(x.shape[0], dtype=np.int64)
    points = x.copy()
    for axis in (0, 1):
        lo, hi = bounds[axis]
        span = hi - lo
        c = points[:, axis]
        near_lo = c - lo < margin
        near_hi = hi - c < margin
        low, high = points[near_lo].copy(), points[near_hi].copy()
        if periodic[axis]:
            low[:, axis] += span
            high[:, axis] -= span
        else:
            # a mirror image on the edge would be the point itself
            keep_lo = c[near_lo] - lo > 1e-12 * span
            keep_hi = hi - c[near_hi] > 1e-12 * span
            low[:, axis] = 2.0 * lo - low[:, axis]
            high[:, axis] = 2.0 * hi - high[:, axis]
            low, high = low[keep_lo], high[keep_hi]
            near_lo[near_lo] = keep_lo
            near_hi[near_hi] = keep_hi
        source = np.concatenate([source, source[near_lo], source[near_hi]])
        points = np.concatenate([points, low, high])
    return source, points


def _lattice_images(x: NDArray[np.float64], span: NDArray[np.float64],
                    tilt: float) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The points and their images in the eight cells around a leaning periodic cell
    (vectors ``(span_x, 0)`` and ``(tilt, span_y)``): (9N,) source and (9N, 2), the
    originals first."""
    shifts = [(i, j) for i in (0, -1, 1) for j in (0, -1, 1)]
    offsets = np.array([[i * span[0] + j * tilt, j * span[1]] for i, j in shifts])
    n = x.shape[0]
    source = np.tile(np.arange(n, dtype=np.int64), len(shifts))
    return source, np.concatenate([x + o for o in offsets])


def _rim_sites(faces: NDArray[np.int64], n_points: int) -> NDArray[np.int64]:
    """The sorted points on an edge that only one of the triangles ``faces`` (K, 3) has."""
    ends = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64)
    low, high = ends.min(axis=1), ends.max(axis=1)
    # one integer per edge: a 1D unique is far faster than np.unique(axis=0) on rows
    keys, counts = np.unique(low * n_points + high, return_counts=True)
    once = keys[counts == 1]
    return np.unique(np.concatenate([once // n_points, once % n_points]))


def power_cells(snapshot: Snapshot) -> PowerCells:
    """The power cells (radical Voronoi tessellation) of every particle of
    ``snapshot`` over its region (docs/fabric.md)."""
    from scipy.spatial import ConvexHull

    tilt = float(snapshot.tilt)
    if tilt != 0.0 and not all(snapshot.periodic):
        raise ValueError(f"tilt: a leaning cell (tilt {tilt!r} m) is tessellated only when periodic in x and y")
    n = snapshot.n_particles
    bounds = _region(snapshot)
    span = bounds[:, 1] - bounds[:, 0]
    x = np.array(snapshot.positions, dtype=np.float64)
    if tilt != 0.0:  # into the parallelogram spanned by (span_x, 0) and (tilt, span_y)
        rows = np.floor((x[:, 1] - bounds[1, 0]) / span[1])
        x[:, 1] -= rows * span[1]
        x[:, 0] -= rows * tilt
        lean = (x[:, 1] - bounds[1, 0]) / span[1] * tilt
        x[:, 0] = bounds[0, 0] + lean + np.mod(x[:, 0] - bounds[0, 0] - lean, span[0])
    else:
        for axis in (0, 1):
            if snapshot.periodic[axis]:
                x[:, axis] = bounds[axis, 0] + np.mod(x[:, axis] - bounds[axis, 0], span[axis])
    r = np.asarray(snapshot.radii, dtype=np.float64)
    if n < 3:
        raise ValueError(f"positions: a tessellation needs at least 3 particles, got {n}")
    # scaled about the region's centre: Qhull works to a relative precision
    centre = bounds.mean(axis=1)
    scale = float(np.mean(2.0 * r))
    margin = 3.0 * float(2.0 * r.max())
    if tilt != 0.0:  # every image of the eight neighbouring cells: one period all round
        margin = float(span.max())
    while True:
        source, points = (_images(x, bounds, snapshot.periodic, margin) if tilt == 0.0
                          else _lattice_images(x, span, tilt))
        u = (points - centre) / scale
        ru = r[source] / scale
        lifted = np.column_stack([u, (u**2).sum(axis=1) - ru**2])
        hull = ConvexHull(lifted)
        lower = hull.equations[:, 2] < 0.0
        faces = hull.simplices[lower]
        eq = hull.equations[lower]
        corner = np.column_stack([-eq[:, 0] / eq[:, 2], -eq[:, 1] / eq[:, 2]]) / 2.0
        # a closed cell: every edge of the original's fan shared by two lower faces
        open_sites = _rim_sites(faces, points.shape[0])
        site = faces.reshape(-1)
        vertex = np.repeat(corner, 3, axis=0)
        mine = site < n
        site, vertex = site[mine], vertex[mine]
        reach = np.hypot(*(vertex - u[site]).T)
        reach_max = float(reach.max(initial=0.0)) * scale
        closed = not np.any(open_sites < n)
        # every image that could cut a cell is there (or all images of one period are)
        wide = margin >= min(reach_max + float(np.hypot(reach_max, r.max())), float(span.max()))
        if closed and wide:
            break
        if margin >= float(span.max()):
            raise ValueError("power cells: the tessellation did not close (degenerate input)")
        margin *= 2.0
    # each cell's corners counter-clockwise about their mean (a cell is convex)
    count = np.bincount(site, minlength=n)
    mean = np.column_stack(
        [np.bincount(site, weights=vertex[:, k], minlength=n) for k in (0, 1)]
    ) / np.maximum(count, 1)[:, None]
    angle = np.arctan2(vertex[:, 1] - mean[site, 1], vertex[:, 0] - mean[site, 0])
    order = np.lexsort((angle, site))
    site, vertex = site[order], vertex[order]
    offsets = np.concatenate([[0], np.cumsum(count)]).astype(np.int64)
    nxt = np.arange(site.size) + 1
    last = offsets[1:][count > 0] - 1
    nxt[last] = offsets[:-1][count > 0]
    cross = vertex[:, 0] * vertex[nxt, 1] - vertex[nxt, 0] * vertex[:, 1]
    area = np.asarray(0.5 * np.bincount(site, weights=cross, minlength=n) * scale**2, np.float64)
    return PowerCells(vertex * scale + centre, offsets, area, bounds)


def power_cell_areas(snapshot: Snapshot) -> NDArray[np.float64]:
    """(N,) area of each particle's power cell, m^2 (:func:`power_cells`)."""
    return power_cells(snapshot).area


class LocalPorosity(Compute):
    """Local porosity of each grain from its power (radical Voronoi) cell, and the sample
    grains' porosity over their cells: docs/fabric.md, "Local porosity".

    Example
    -------
    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(4.0), np.arange(4.0))
    >>> snap = Snapshot(np.c_[x.ravel(), y.ravel()], np.full(16, 0.5), box=[[0, 4], [0, 4]],
    ...                 periodic=(True, True))  # a square lattice: unit square cells
    >>> np.round(LocalPorosity().compute(snap).cell_area, 12).tolist() == [1.0] * 16
    True
    """

    def compute(self, snapshot: Snapshot) -> LocalPorosity:
        """Tessellate ``snapshot`` and compute the local porosities; returns ``self``."""
        cells = power_cells(snapshot)
        solid = np.pi * np.asarray(snapshot.radii) ** 2
        sample = snapshot.is_sample
        with np.errstate(divide="ignore", invalid="ignore"):
            local = np.where(sample & (cells.area > 0.0), 1.0 - solid / cells.area, np.nan)
        total = float(cells.area[sample].sum())
        porosity = 1.0 - float(solid[sample].sum()) / total if total > 0 else float("nan")
        self._store(_snapshot=snapshot, cells=cells, local_porosity=local, porosity=porosity)
        return self

    _snapshot = Computed[Snapshot]("The snapshot measured (drawn by plot).")
    cells = Computed["PowerCells"]("The power cells (:class:`PowerCells`).")

    @property
    def cell_area(self) -> NDArray[np.float64]:
        """(N,) area of each particle's power cell, m^2."""
        return self.cells.area

    local_porosity = Computed[NDArray[np.float64]](
        "(N,) 1 - pi r^2 / A_p of each sample grain (NaN for membrane disks and a particle "
        "without a cell)."
    )
    porosity = Computed[float]("1 - (grains' disk area) / (their cells' area).")

    def plot(self, ax: Any = None) -> Any:
        """The power cells coloured by local porosity, the disks on top; returns the axes."""
        from grainlab.plot import networks

        snap = self._snapshot
        cells = self.cells
        return networks.cell_map(
            cells.vertices,
            cells.offsets,
            self.local_porosity,
            snap.positions,
            snap.radii,
            ax=ax,
            label="local porosity",
        )
