"""Porosity of a 2D disk packing, nominal (``1 - sum(pi r^2) / A``, PFC's) and
overlap-corrected (``1 - |union of disks ∩ box| / A``), in a box or inside a
measurement circle, and the particle count for a target (docs/samples.md,
"Porosity: two readings"). Areas per unit thickness (m^2); boxes
``(xmin, ymin, xmax, ymax)`` in m.

Example
-------
>>> import numpy as np
>>> from grainlab.samples import nominal_porosity, overlap_corrected_porosity
>>> r = np.array([1.0, 1.0])
>>> xy = np.array([[1.0, 1.0], [2.8, 1.0]])  # overlap 0.2
>>> round(nominal_porosity(r, 3.8 * 2.0), 6)
0.173265
>>> bool(overlap_corrected_porosity(xy, r, (0.0, 0.0, 3.8, 2.0)) > nominal_porosity(r, 7.6))
True
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from grainlab.samples._checks import in_range, positive_lengths
from grainlab.samples.grading import Grading

__all__ = [
    "box_area",
    "check_box",
    "disk_area_in_box",
    "grain_overlap_area",
    "lens_area",
    "measurement_circle_porosity",
    "nominal_porosity",
    "overlap_corrected_porosity",
    "overlapping_pairs",
    "particle_count",
]

Box = tuple[float, float, float, float]


def check_box(box: ArrayLike, name: str = "box") -> Box:
    """Validates ``(xmin, ymin, xmax, ymax)`` (finite, ``xmax > xmin``, ``ymax > ymin``)."""
    try:
        b = np.asarray(box, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected (xmin, ymin, xmax, ymax) in m, got {box!r}") from None
    if b.shape != (4,) or not np.all(np.isfinite(b)):
        raise ValueError(f"{name}: expected four finite numbers (xmin, ymin, xmax, ymax) in m, got {box!r}")
    if not (b[2] > b[0] and b[3] > b[1]):
        raise ValueError(f"{name}: needs xmax > xmin and ymax > ymin, got {tuple(b.tolist())}")
    return float(b[0]), float(b[1]), float(b[2]), float(b[3])


def box_area(box: ArrayLike) -> float:
    """Area (m^2) of ``(xmin, ymin, xmax, ymax)``."""
    x0, y0, x1, y1 = check_box(box)
    return (x1 - x0) * (y1 - y0)


def _radii(radii: ArrayLike) -> NDArray[np.float64]:
    return positive_lengths("radii", radii, "radius")


def nominal_porosity(radii: ArrayLike, area: float, *, positions: ArrayLike | None = None,
                     grain: ArrayLike | None = None) -> float:
    """``1 - sum(pi r^2) / area``: PFC's porosity, overlaps counted twice. With
    ``grain`` (each disk's grain, as :attr:`grainlab.Snapshot.grain`) and the
    disks' ``positions``, a grain of several disks (a clump) counts the area of
    their union, its own overlaps once (:func:`grain_overlap_area`)."""
    r = _radii(radii)
    area = in_range("area", area, "(0, inf)", "an area (m^2)")
    covered = math.pi * np.sum(r * r)
    if grain is not None:
        covered -= grain_overlap_area(_positions(positions, r), r, grain)
    return float(1.0 - covered / area)


def _positions(positions: ArrayLike | None, r: NDArray[np.float64]) -> NDArray[np.float64]:
    """The disks' centres (N, 2), checked against their radii."""
    if positions is None:
        raise ValueError("positions: a porosity by grain needs the disks' positions")
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 2 or p.shape != (len(r), 2):
        raise ValueError(f"positions: expected shape ({len(r)}, 2), got {p.shape}")
    return p


def _grain_ids(grain: ArrayLike, n: int) -> NDArray[np.int64]:
    g = np.asarray(grain)
    if g.shape != (n,) or g.dtype.kind not in "iu":
        raise ValueError(f"grain: expected {n} integers, one per disk, got {g.dtype} {g.shape}")
    return g.astype(np.int64)


def grain_overlap_area(positions: ArrayLike, radii: ArrayLike, grain: ArrayLike, *,
                       cell: tuple[float, float] | None = None) -> float:
    """``sum_g (sum_{i in g} pi r_i^2 - |union of g's disks|)`` (m^2): what the
    disks' areas count twice inside grains of several disks (clumps), each
    union exact (:func:`grainlab.bodies.clump_mass_properties`); 0 for grains of
    one disk. In a periodic ``cell`` (its side lengths) a grain's disks are
    taken at their nearest images of its first one."""
    from grainlab.bodies import clump_mass_properties

    r = _radii(radii)
    p = _positions(positions, r)
    g = _grain_ids(grain, len(r))
    order = np.argsort(g, kind="stable")
    _, starts, counts = np.unique(g[order], return_index=True, return_counts=True)
    extra = 0.0
    for start, count in zip(starts[counts > 1], counts[counts > 1], strict=True):
        members = order[start:start + count]
        centres = p[members]
        if cell is not None:
            side = np.asarray(cell, dtype=np.float64)
            centres = centres[0] + (centres - centres[0]) - side * np.round((centres - centres[0]) / side)
        union = clump_mass_properties(centres, r[members], density=1.0).area_m2
        extra += math.pi * float(np.sum(r[members] ** 2)) - union
    return extra


def _chord_segment(theta: NDArray[np.float64]) -> NDArray[np.float64]:
    """``theta - sin(theta) cos(theta) = (2 theta - sin 2 theta) / 2``: a circular segment of
    half-angle ``theta`` over ``r^2``, by its series for small angles (no cancellation)."""
    x = 2.0 * theta
    small = x < 1e-2
    out = np.empty_like(x)
    xs = x[small]
    out[small] = xs**3 / 6.0 - xs**5 / 120.0 + xs**7 / 5040.0
    xl = x[~small]
    out[~small] = xl - np.sin(xl)
    return 0.5 * out


def lens_area(r1: ArrayLike, r2: ArrayLike, distance: ArrayLike) -> NDArray[np.float64]:
    """Area shared by two disks of radii ``r1``, ``r2`` with centres ``distance`` apart (vectorised).

    ``0`` when ``distance >= r1 + r2``; ``pi min(r1, r2)^2`` when one disk lies in
    the other; otherwise the two circular segments cut off by the common chord, in
    the form that keeps its accuracy for tiny overlaps (docs/samples.md, "Porosity:
    two readings").
    """
    r1, r2, d = np.broadcast_arrays(
        np.asarray(r1, dtype=np.float64), np.asarray(r2, dtype=np.float64), np.asarray(distance, dtype=np.float64)
    )
    out = np.zeros(r1.shape)
    inside = d <= np.abs(r1 - r2)
    out[inside] = math.pi * np.minimum(r1, r2)[inside] ** 2
    partial = ~inside & (d < r1 + r2)
    a, b, e = r1[partial], r2[partial], d[partial]
    t1 = np.arccos(np.clip((e * e + a * a - b * b) / (2.0 * e * a), -1.0, 1.0))
    t2 = np.arccos(np.clip((e * e + b * b - a * a) / (2.0 * e * b), -1.0, 1.0))
    out[partial] = a * a * _chord_segment(t1) + b * b * _chord_segment(t2)
    return out


def _segment_beyond(r: NDArray[np.float64], h: NDArray[np.float64]) -> NDArray[np.float64]:
    """Area of a disk beyond a line at signed distance ``h`` from its centre (``h > 0``: centre inside)."""
    return r * r * _chord_segment(np.arccos(np.clip(h / r, -1.0, 1.0)))


def _corner_beyond(r: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Area of a disk in the quadrant beyond two perpendicular lines at distances ``a, b >= 0`` from its centre.

    ``Q = S(sqrt(r^2 - b^2)) - S(a) - b (sqrt(r^2 - b^2) - a)`` with
    ``S(x) = (x sqrt(r^2 - x^2) + r^2 asin(x / r)) / 2``; zero when ``a^2 + b^2 >= r^2``.
    """
    a = np.maximum(a, 0.0)
    b = np.maximum(b, 0.0)
    out = np.zeros(r.shape)
    hit = a * a + b * b < r * r
    r, a, b = r[hit], a[hit], b[hit]
    top = np.sqrt(r * r - b * b)

    def s(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return 0.5 * (x * np.sqrt(np.clip(r * r - x * x, 0.0, None)) + r * r * np.arcsin(np.clip(x / r, -1.0, 1.0)))

    out[hit] = s(top) - s(a) - b * (top - a)
    return out


def disk_area_in_box(positions: ArrayLike, radii: ArrayLike, box: ArrayLike) -> NDArray[np.float64]:
    """Area of each disk inside the box (m^2): ``pi r^2`` minus the circular segments
    beyond each edge, plus back the pieces beyond two edges at a corner (counted twice).

    Exact for disks whose centres lie in the box and whose diameters are below the
    box's width and height (no disk crosses two opposite edges).
    """
    x0, y0, x1, y1 = check_box(box)
    r = _radii(radii)
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    if len(p) != len(r):
        raise ValueError(f"positions: has {len(p)} rows but there are {len(r)} radii")
    dl, dr = p[:, 0] - x0, x1 - p[:, 0]
    db, dt = p[:, 1] - y0, y1 - p[:, 1]
    area = math.pi * r * r
    if not np.any(np.minimum(np.minimum(dl, dr), np.minimum(db, dt)) < r):
        return area
    out = area - sum(_segment_beyond(r, h) for h in (dl, dr, db, dt))
    out += sum(_corner_beyond(r, a, b) for a, b in ((dl, db), (dr, db), (dl, dt), (dr, dt)))
    return out


def overlapping_pairs(
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
    cell: tuple[float, float] | None = None,
) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.float64]]:
    """Pairs ``i < j`` of overlapping disks and their centre distances (a cKDTree query).

    With ``cell = (width, height)`` positions are taken in a periodic cell whose
    lower corner is the origin, and distances are minimum-image ones.
    """
    if len(radii) < 2:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty, np.zeros(0)
    if cell is None:
        tree = cKDTree(positions)
    else:
        wrapped = np.mod(positions, cell)
        wrapped[wrapped >= np.asarray(cell)] = 0.0  # mod can round up to the cell size
        tree = cKDTree(wrapped, boxsize=cell)
        positions = wrapped
    pairs = tree.query_pairs(2.0 * float(radii.max()), output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    delta = positions[j] - positions[i]
    if cell is not None:
        size = np.asarray(cell)
        delta -= size * np.round(delta / size)
    d = np.hypot(delta[:, 0], delta[:, 1])
    keep = d < radii[i] + radii[j]
    return i[keep], j[keep], d[keep]


def overlap_corrected_porosity(
    positions: ArrayLike, radii: ArrayLike, box: ArrayLike, *, periodic: bool = False,
    grain: ArrayLike | None = None,
) -> float:
    """``1 - |union of the disks ∩ box| / box area``: the void fraction really left.

    The union by inclusion-exclusion to pairs, disks clipped exactly at the box edges
    (none across the sides of a periodic cell, ``periodic=True``); with ``grain``
    (each disk's grain) each clump's union counts once. When it is exact:
    docs/samples.md, "Porosity: two readings".
    """
    x0, y0, x1, y1 = check_box(box)
    r = _radii(radii)
    p = _positions(positions, r)
    if periodic:
        i, j, d = overlapping_pairs(p - np.array([x0, y0]), r, cell=(x1 - x0, y1 - y0))
        disks = math.pi * np.sum(r * r)
    else:
        i, j, d = overlapping_pairs(p, r)
        disks = disk_area_in_box(p, r, (x0, y0, x1, y1)).sum()
    if grain is None:
        covered = disks - lens_area(r[i], r[j], d).sum()
    else:
        g = _grain_ids(grain, len(r))
        apart = g[i] != g[j]
        cell = (x1 - x0, y1 - y0) if periodic else None
        covered = disks - grain_overlap_area(p, r, g, cell=cell) - lens_area(r[i][apart], r[j][apart], d[apart]).sum()
    return float(1.0 - covered / ((x1 - x0) * (y1 - y0)))


def measurement_circle_porosity(
    positions: ArrayLike,
    radii: ArrayLike,
    centre: ArrayLike,
    radius: float,
    *,
    overlap_corrected: bool = False,
) -> float:
    """Porosity inside a measurement circle of centre ``c`` and radius ``R`` (m), each
    disk clipped exactly by the circle: the nominal reading, or with
    ``overlap_corrected=True`` the pairs' lenses inside it subtracted
    (docs/samples.md, "Porosity: two readings").

    Example
    -------
    A disk of radius 1 centred on the edge of a circle of radius 10 (about
    half of it inside):

    >>> import numpy as np
    >>> n = measurement_circle_porosity([[10.0, 0.0]], [1.0], (0.0, 0.0), 10.0)
    >>> round(n, 6)  # a little less than half of it: the circle bends away
    0.995106
    >>> 1 - 0.5 / 10**2  # exactly half the disk, pi / 2 over pi 10^2
    0.995
    """
    r = _radii(radii)
    p = _positions(positions, r)
    if not np.all(np.isfinite(p)):
        raise ValueError("positions: must be finite (m)")
    c = np.asarray(centre, dtype=np.float64)
    if c.shape != (2,) or not np.all(np.isfinite(c)):
        raise ValueError(f"centre: expected two finite coordinates (x, y) in m, got {centre!r}")
    big_r = in_range("radius", radius, "(0, inf)", "a radius (m)")
    d = np.hypot(p[:, 0] - c[0], p[:, 1] - c[1])
    near = d < big_r + r
    covered = float(lens_area(r[near], big_r, d[near]).sum())
    if overlap_corrected and np.count_nonzero(near) >= 2:
        pn, rn = p[near], r[near]
        i, j, dij = overlapping_pairs(pn, rn)
        # the chord's midpoint lies on the centre line, x_i + (d^2 + r_i^2 - r_j^2) / (2 d) along it
        along = (dij * dij + rn[i] ** 2 - rn[j] ** 2) / (2.0 * dij)
        mid = pn[i] + (pn[j] - pn[i]) * (along / dij)[:, None]
        inside = np.hypot(mid[:, 0] - c[0], mid[:, 1] - c[1]) < big_r
        covered -= float(lens_area(rn[i][inside], rn[j][inside], dij[inside]).sum())
    return float(1.0 - covered / (math.pi * big_r * big_r))


def particle_count(box_area: float, porosity: float, grading: Grading) -> int:
    """``round((1 - n) A / mean disk area)``: the number of disks of ``grading``
    that fill ``box_area`` (m^2) to nominal porosity ``porosity`` on average."""
    box_area = in_range("box_area", box_area, "(0, inf)", "an area (m^2)")
    porosity = in_range("porosity", porosity, "(0, 1)")
    return round((1.0 - porosity) * box_area / grading.mean_disk_area())
