"""Regular packings of equal disks: hexagonal and square lattices at a given
porosity, vacancies above the contact porosity and a uniform compression below
it, in a periodic cell or a walled box (docs/samples.md, "Lattices");
:attr:`Lattice.note` says what was done.

Example
-------
>>> from grainlab.samples import hexagonal_lattice
>>> lat = hexagonal_lattice(1e-3, n_rows=4, n_cols=3)
>>> round(lat.porosity, 6), round(lat.porosity_overlap_corrected, 6)
(0.0931, 0.0931)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.samples._checks import in_range
from grainlab.samples.porosity import check_box, nominal_porosity, overlap_corrected_porosity

__all__ = [
    "HEXAGONAL_CONTACT_POROSITY",
    "SQUARE_CONTACT_POROSITY",
    "Lattice",
    "hexagonal_lattice",
    "square_lattice",
]

#: ``1 - pi / (2 sqrt 3)``: porosity of the hexagonal lattice of touching equal disks.
HEXAGONAL_CONTACT_POROSITY = 1.0 - math.pi / (2.0 * math.sqrt(3.0))
#: ``1 - pi / 4``: porosity of the square lattice of touching equal disks.
SQUARE_CONTACT_POROSITY = 1.0 - math.pi / 4.0

_GEOMETRY = {
    # row spacing over a, x offset of odd rows over a, contact porosity of the infinite lattice
    "hexagonal": (math.sqrt(3.0) / 2.0, 0.5, HEXAGONAL_CONTACT_POROSITY),
    "square": (1.0, 0.0, SQUARE_CONTACT_POROSITY),
}


@dataclass(frozen=True, eq=False)
class Lattice:
    """A lattice packing and where it really is."""

    kind: str
    """``"hexagonal"`` or ``"square"``."""
    boundary: str
    """``"periodic"`` (the box is a periodic cell) or ``"walls"``."""
    positions: NDArray[np.float64]
    """(N, 2) centres, m."""
    radii: NDArray[np.float64]
    """(N,) radii, all ``diameter / 2``, m."""
    box: tuple[float, float, float, float]
    """``(xmin, ymin, xmax, ymax)`` used, m."""
    diameter: float
    spacing: float
    """Centre distance of lattice neighbours ``a``, m (``< diameter``: compressed)."""
    porosity_target: float | None
    porosity: float
    """Nominal porosity ``1 - N pi r^2 / A``."""
    porosity_overlap_corrected: float
    """``1 - |union of disks| / A``."""
    contact_porosity: float
    """Porosity of the full lattice at contact in this box (the infinite lattice's value when periodic)."""
    n_sites: int
    n_vacancies: int
    note: str
    """What was done to reach the target."""

    @property
    def n_particles(self) -> int:
        return len(self.radii)


def _sites_in_box(
    kind: str, spacing: float, radius: float, box: tuple[float, float, float, float]
) -> NDArray[np.float64]:
    """Lattice sites inside a walled box, first row and column touching the bottom and left walls."""
    row, offset, _ = _GEOMETRY[kind]
    x0, y0, x1, y1 = box
    tol = 1e-12 * spacing
    n_rows = math.floor((y1 - y0 - 2.0 * radius + tol) / (row * spacing)) + 1
    n_cols = math.floor((x1 - x0 - 2.0 * radius + tol) / spacing) + 1
    if y1 - y0 < 2.0 * radius - tol or x1 - x0 < 2.0 * radius - tol:
        return np.zeros((0, 2))
    j, i = np.meshgrid(np.arange(n_rows), np.arange(n_cols), indexing="ij")
    x = x0 + radius + (i + offset * (j % 2)) * spacing
    y = y0 + radius + j * row * spacing
    keep = x <= x1 - radius + tol
    return np.column_stack([x[keep], y[keep]])


def _check_rng(rng: np.random.Generator | int | None) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    return np.random.default_rng(0 if rng is None else rng)


def _checked(
    diameter: float,
    porosity: float | None,
    box: ArrayLike | None,
    n_rows: int | None,
    n_cols: int | None,
    boundary: str,
    offset: float,
) -> tuple[float, float | None, int | None, int | None]:
    """The diameter, porosity and row and column counts, checked (bad input names its field)."""
    d = in_range("diameter", diameter, "(0, inf)", "a diameter (m)")
    porosity = None if porosity is None else in_range("porosity", porosity, "(0, 1)")
    if boundary not in ("periodic", "walls"):
        raise ValueError(f"boundary: must be 'periodic' or 'walls', got {boundary!r}")
    if (box is None) == (n_rows is None and n_cols is None):
        raise ValueError("box: give either box or n_rows and n_cols")
    if box is None:
        if n_rows is None or n_cols is None:
            raise ValueError("n_rows: give both n_rows and n_cols")
        n_rows, n_cols = int(n_rows), int(n_cols)
        if n_rows < 1 or n_cols < 1:
            raise ValueError(f"n_rows, n_cols: must be >= 1, got {n_rows}, {n_cols}")
        if boundary == "periodic" and offset and n_rows % 2:
            raise ValueError(f"n_rows: a periodic hexagonal lattice needs an even number of rows, got {n_rows}")
    return d, porosity, n_rows, n_cols


#: A lattice's sites before vacancies: sites, cell, spacing, note, contact porosity.
_Sites = tuple[NDArray[np.float64], tuple[float, float, float, float], float, str, float]


def _periodic_sites(
    kind: str, d: float, porosity: float | None, box: ArrayLike | None, n_rows: int | None, n_cols: int | None
) -> _Sites:
    """The sites of a periodic cell of whole lattice periods (compressed to the porosity)."""
    row, offset, contact = _GEOMETRY[kind]
    if porosity is None or porosity >= contact:
        a = d
    else:
        a = d * math.sqrt((1.0 - contact) / (1.0 - porosity))
    if box is None:
        x0 = y0 = 0.0
    else:
        bx = check_box(box)
        x0, y0 = bx[0], bx[1]
        n_cols = max(1, round((bx[2] - bx[0]) / a))
        periods = (bx[3] - bx[1]) / (row * a)
        # hexagonal rows repeat every two rows
        n_rows = max(2, 2 * round(periods / 2)) if offset else max(1, round(periods))
    assert n_rows is not None and n_cols is not None
    cell = (x0, y0, x0 + n_cols * a, y0 + n_rows * row * a)
    j, i = np.meshgrid(np.arange(n_rows), np.arange(n_cols), indexing="ij")
    sites = np.column_stack(
        [(x0 + (i + 0.5 + offset * (j % 2)) * a).ravel(), (y0 + (j + 0.5) * row * a).ravel()]
    )
    note = f"{kind} lattice of {d * 1e3:g} mm disks, periodic cell of {n_cols} x {n_rows} sites"
    note += f" ({cell[2] - x0:.6g} x {cell[3] - y0:.6g} m)"
    if box is not None and not np.allclose(cell, check_box(box), rtol=0.0, atol=1e-12 * d):
        note += ", the box rounded to whole lattice periods"
    return sites, cell, a, note, contact


def _walled_sites(
    kind: str, d: float, porosity: float | None, box: ArrayLike | None, n_rows: int | None, n_cols: int | None
) -> _Sites:
    """The sites in a walled box, given or fitted around the rows (compressed to the porosity)."""
    row, offset, contact = _GEOMETRY[kind]
    r = 0.5 * d
    disk = math.pi * r * r
    what = f"{kind} lattice of {d * 1e3:g} mm disks"
    if box is None:
        assert n_rows is not None and n_cols is not None
        nr, nc = n_rows, n_cols
        n_sites = nc * nr - (nr // 2 if offset else 0)

        def box_porosity(a: float) -> float:
            return 1.0 - n_sites * disk / (((nc - 1) * a + d) * ((nr - 1) * row * a + d))

        full_contact = box_porosity(d)
        a = d if porosity is None or porosity >= full_contact else _largest_spacing_at_most(
            box_porosity, porosity, d, nearest=True)
        cell = (0.0, 0.0, (nc - 1) * a + d, (nr - 1) * row * a + d)
        note = f"{what} in a walled box fitted around {nc} x {nr} rows"
    else:
        cell = check_box(box)
        area = (cell[2] - cell[0]) * (cell[3] - cell[1])

        def fitted_porosity(a: float) -> float:
            return 1.0 - len(_sites_in_box(kind, a, r, cell)) * disk / area

        full_contact = fitted_porosity(d)
        if len(_sites_in_box(kind, d, r, cell)) == 0:
            raise ValueError(f"box: a {d:g} m disk does not fit in {cell}")
        if porosity is None or porosity >= full_contact:
            a = d
        else:
            a = _largest_spacing_at_most(fitted_porosity, porosity, d)
        note = f"{what} in a walled box"
    if kind == "hexagonal":
        note += f"; this box's contact porosity is {full_contact:.4f} (the infinite lattice's {contact:.4f})"
    return _sites_in_box(kind, a, r, cell), cell, a, note, full_contact


def _make(
    kind: str,
    diameter: float,
    porosity: float | None,
    box: ArrayLike | None,
    n_rows: int | None,
    n_cols: int | None,
    boundary: str,
    rng: np.random.Generator | int | None,
) -> Lattice:
    d, porosity, n_rows, n_cols = _checked(diameter, porosity, box, n_rows, n_cols, boundary, _GEOMETRY[kind][1])
    r = 0.5 * d
    disk = math.pi * r * r
    rng = _check_rng(rng)
    layout = _periodic_sites if boundary == "periodic" else _walled_sites
    sites, cell, a, note, full_contact = layout(kind, d, porosity, box, n_rows, n_cols)
    area = (cell[2] - cell[0]) * (cell[3] - cell[1])
    n_sites = len(sites)
    n_vac = 0
    if a < d:
        note += (
            f"; compressed uniformly to spacing {a / d:.6f} d (overlap {100 * (d - a) / d:.3g}% of d per "
            "neighbour pair)"
        )
    if porosity is not None:
        keep = round((1.0 - porosity) * area / disk)
        n_vac = max(0, n_sites - keep)
        if n_vac:
            chosen = np.sort(rng.choice(n_sites, n_sites - n_vac, replace=False))
            sites = sites[chosen]
            note += f"; {n_vac} of {n_sites} sites left vacant at random to reach porosity {porosity:g}"
    if len(sites) == 0:
        raise ValueError(f"porosity: {porosity} leaves no disk in the box")
    radii = np.full(len(sites), r)
    periodic = boundary == "periodic"
    n_nom = nominal_porosity(radii, area)
    n_cor = overlap_corrected_porosity(sites, radii, cell, periodic=periodic)
    note += f"; porosity {n_nom:.4f} nominal, {n_cor:.4f} overlap-corrected"
    for array in (sites, radii):
        array.flags.writeable = False
    return Lattice(
        kind=kind,
        boundary=boundary,
        positions=sites,
        radii=radii,
        box=(float(cell[0]), float(cell[1]), float(cell[2]), float(cell[3])),
        diameter=d,
        spacing=a,
        porosity_target=porosity,
        porosity=n_nom,
        porosity_overlap_corrected=n_cor,
        contact_porosity=full_contact,
        n_sites=n_sites,
        n_vacancies=n_vac,
        note=note,
    )


def _largest_spacing_at_most(f, target: float, d: float, nearest: bool = False) -> float:  # type: ignore[no-untyped-def]
    """Largest spacing ``a <= d`` whose porosity ``f(a) <= target`` (``f`` non-decreasing in
    ``a``, maybe stepwise), by bisection; with ``nearest``, of the two spacings that end
    the bisection the one whose ``f`` is nearer ``target`` (for a continuous ``f``)."""
    lo, hi = 0.5 * d, d
    if f(lo) > target:
        raise ValueError(f"porosity: {target} needs a lattice compressed beyond half its contact spacing")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if f(mid) <= target:
            lo = mid
        else:
            hi = mid
    return hi if nearest and abs(f(hi) - target) < abs(f(lo) - target) else lo


def hexagonal_lattice(
    diameter: float,
    porosity: float | None = None,
    *,
    box: ArrayLike | None = None,
    n_rows: int | None = None,
    n_cols: int | None = None,
    boundary: str = "periodic",
    rng: np.random.Generator | int | None = None,
) -> Lattice:
    """Equal disks on a hexagonal (triangular) lattice, rows along x, odd rows shifted by ``a/2``.

    Parameters
    ----------
    diameter : m (the paper's Table 3 prints 0.875 mm; see docs/samples.md)
    porosity : target nominal porosity in (0, 1); ``None``: the lattice at contact.
        Above the contact porosity (0.0931 periodic) random vacancies, below it a
        uniform compression (docs/samples.md, "Lattices").
    box : ``(xmin, ymin, xmax, ymax)``, m; or ``n_rows`` and ``n_cols`` (even
        ``n_rows`` when periodic)
    boundary : ``"periodic"`` or ``"walls"``
    rng : a Generator or a seed for the vacancies (None: seed 0)
    """
    return _make("hexagonal", diameter, porosity, box, n_rows, n_cols, boundary, rng)


def square_lattice(
    diameter: float,
    porosity: float | None = None,
    *,
    box: ArrayLike | None = None,
    n_rows: int | None = None,
    n_cols: int | None = None,
    boundary: str = "periodic",
    rng: np.random.Generator | int | None = None,
) -> Lattice:
    """Equal disks on a square lattice; contact porosity ``1 - pi/4 = 0.2146``.

    Parameters as :func:`hexagonal_lattice`.
    """
    return _make("square", diameter, porosity, box, n_rows, n_cols, boundary, rng)
