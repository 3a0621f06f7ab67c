"""Crushable grains: agglomerates of small disks bonded together (docs/cemented.md,
"Crushable grains").

A grain of diameter ``d`` is filled with disks on a hexagonal lattice of spacing
``disk_diameter`` (the largest disk's diameter), turned by a random angle and shifted
by a random fraction of a lattice cell, so that no two grains show the platens the
same lattice; each disk's radius is shrunk at random by up to ``size_scatter`` of
itself, a fraction ``vacancies`` of the sites is left empty at random (the flaws of
McDowell and Harireche 2002, which give the grains' strengths their Weibull scatter),
and the disks whose whole circle lies inside the grain's circle are kept. Every two
lattice neighbours (centres one spacing apart: touching, or apart by at most the
shrinkage) are bonded; the disks the vacancies cut off from the rest are dropped, so
that the bond graph of every grain is connected. Each bond's tensile strength and
cohesion are drawn from the grain's own random stream
(:func:`grainlab.cement.draw_strengths`), after its geometry.

A hexagonal lattice rather than disks packed at random by radius expansion: the
lattice fills the circle at once and without overlaps, each grain's scatter comes
from three seeded draws that one can turn off one by one (orientation, flaws, sizes),
and it is the agglomerate of the crushing studies this follows (Robertson 2000,
McDowell and Harireche 2002, Cheng, Nakata and Bolton 2003).

Example
-------
>>> import numpy as np
>>> from grainlab.samples.agglomerate import BondStrengths, build_agglomerate
>>> grain = build_agglomerate(2e-3, 0.2e-3, np.random.default_rng(1), strengths=BondStrengths(1e6, 1e6))
>>> grain.n_disks, grain.n_bonds
(69, 159)
>>> bool(np.all(np.hypot(*grain.positions.T) + grain.radii <= 1e-3))
True
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.analysis.fragments import fragment_labels
from grainlab.cement import draw_strengths, pairs_within_gap
from grainlab.samples._checks import in_range

__all__ = ["Agglomerates", "BondStrengths", "agglomerate_stream", "build_agglomerate", "build_agglomerates"]

#: The largest fraction of vacant sites, and of a disk's radius that the size scatter takes off.
MAX_VACANCIES = 0.5
MAX_SIZE_SCATTER = 0.5
#: A grain is at least this many lattice spacings across.
MIN_DISKS_ACROSS = 3.0


@dataclass(frozen=True)
class BondStrengths:
    """The bonds' strengths: the means of the tensile strength sigma_c and of the
    cohesion c (Pa), their coefficient of variation and its law
    (:func:`grainlab.cement.draw_strengths`)."""

    tensile: float
    cohesion: float
    scatter: float = 0.0
    distribution: Literal["normal", "weibull"] = "normal"


@dataclass(frozen=True, eq=False)
class Agglomerates:
    """Grains made of bonded disks: every disk's centre, radius and grain, every bond
    (``bond_i < bond_j``, two disks of one grain) and its strengths, every grain's
    centre and diameter."""

    positions: NDArray[np.float64]
    """(N, 2) disk centres, m."""
    radii: NDArray[np.float64]
    """(N,) disk radii, m."""
    agglomerate: NDArray[np.int64]
    """(N,) the grain of each disk, 0 .. K-1, the disks of a grain one after the other."""
    bond_i: NDArray[np.int64]
    bond_j: NDArray[np.int64]
    tensile_strength: NDArray[np.float64]
    """(B,) sigma_c of each bond, Pa."""
    cohesion: NDArray[np.float64]
    """(B,) c of each bond, Pa."""
    centres: NDArray[np.float64]
    """(K, 2) grain centres, m."""
    diameters: NDArray[np.float64]
    """(K,) grain diameters d, m."""

    @property
    def n_disks(self) -> int:
        return int(self.radii.size)

    @property
    def n_bonds(self) -> int:
        return int(self.bond_i.size)

    @property
    def n_agglomerates(self) -> int:
        return int(self.diameters.size)

    def solid_areas(self) -> NDArray[np.float64]:
        """(K,) the disks' area of each grain, m^2 per m of thickness."""
        areas = np.bincount(self.agglomerate, weights=np.pi * self.radii**2, minlength=self.n_agglomerates)
        return areas.astype(np.float64)


def agglomerate_stream(seed: int, k: int) -> np.random.Generator:
    """The random stream of grain ``k`` of a set seeded by ``seed``: its own, the same
    whatever the number of grains (``SeedSequence(seed, spawn_key=(k,))``)."""
    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(int(k),)))


def _checked(diameter: float, disk_diameter: float, vacancies: float, size_scatter: float) -> tuple[float, float]:
    d = in_range("diameter", diameter, "(0, inf)", "a diameter (m)")
    a = in_range("disk_diameter", disk_diameter, "(0, inf)", "a diameter (m)")
    if d < MIN_DISKS_ACROSS * a:
        raise ValueError(f"disk_diameter: a grain is at least {MIN_DISKS_ACROSS:g} disks across, got "
                         f"{a:g} m disks in a {d:g} m grain")
    in_range("vacancies", vacancies, f"[0, {MAX_VACANCIES:g}]", "a fraction")
    in_range("size_scatter", size_scatter, f"[0, {MAX_SIZE_SCATTER:g}]", "a fraction")
    return d, a


def _lattice_in_circle(radius: float, spacing: float, rng: np.random.Generator) -> NDArray[np.float64]:
    """Sites of a hexagonal lattice of ``spacing`` covering the circle of ``radius`` about
    the origin, shifted by a random fraction of a cell and turned by a random angle."""
    n = int(math.ceil(radius / spacing)) + 2
    row, col = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
    x = (col + 0.5 * (row % 2)) * spacing
    y = row * spacing * math.sqrt(3.0) / 2.0
    sites = np.column_stack([x.ravel(), y.ravel()]) - rng.random(2) * spacing
    angle = rng.random() * math.pi / 3.0  # the lattice's symmetry: every orientation once
    c, s = math.cos(angle), math.sin(angle)
    turned: NDArray[np.float64] = sites @ np.array([[c, s], [-s, c]])
    return turned


def build_agglomerate(diameter: float, disk_diameter: float, rng: np.random.Generator, *,
                      vacancies: float = 0.05, size_scatter: float = 0.1, strengths: BondStrengths,
                      centre: ArrayLike = (0.0, 0.0)) -> Agglomerates:
    """One grain of ``diameter`` (m) about ``centre``, of disks on a lattice of spacing
    ``disk_diameter`` (m), by the module's rule, every draw from ``rng``; bad input is
    refused in one line naming its field."""
    d, a = _checked(diameter, disk_diameter, vacancies, size_scatter)
    sites = _lattice_in_circle(0.5 * d, a, rng)
    radii = 0.5 * a * (1.0 - size_scatter * rng.random(len(sites)))
    inside = np.hypot(sites[:, 0], sites[:, 1]) + radii <= 0.5 * d
    sites, radii = sites[inside], radii[inside]
    kept = rng.random(len(sites)) >= vacancies
    sites, radii = sites[kept], radii[kept]
    i, j = pairs_within_gap(sites, np.full(len(sites), 0.5 * a), 1e-9 * a)  # the lattice neighbours
    labels = fragment_labels(len(sites), i, j)
    largest = int(np.argmax(np.bincount(labels))) if len(sites) else 0
    keep = np.flatnonzero(labels == largest)
    if len(keep) < 2:
        raise ValueError(f"vacancies: {vacancies:g} leaves no two bonded disks in a {d:g} m grain")
    new = np.full(len(sites), -1, dtype=np.int64)
    new[keep] = np.arange(len(keep))
    bonded = labels[i] == largest
    s = strengths
    n = int(np.count_nonzero(bonded))
    return Agglomerates(
        positions=sites[keep] + np.asarray(centre, dtype=np.float64), radii=radii[keep],
        agglomerate=np.zeros(len(keep), dtype=np.int64), bond_i=new[i[bonded]], bond_j=new[j[bonded]],
        tensile_strength=draw_strengths(rng, s.tensile, s.scatter * s.tensile, n, s.distribution),
        cohesion=draw_strengths(rng, s.cohesion, s.scatter * s.cohesion, n, s.distribution),
        centres=np.asarray(centre, dtype=np.float64).reshape(1, 2), diameters=np.array([d]),
    )


def build_agglomerates(centres: ArrayLike, diameters: ArrayLike, disk_diameter: float, seed: int, *,
                       vacancies: float = 0.05, size_scatter: float = 0.1,
                       strengths: BondStrengths) -> Agglomerates:
    """Grains of ``diameters`` about ``centres``, grain ``k`` from
    :func:`agglomerate_stream` ``(seed, k)``, their disks and bonds numbered one grain
    after the other."""
    c = np.asarray(centres, dtype=np.float64).reshape(-1, 2)
    d = np.asarray(diameters, dtype=np.float64).reshape(-1)
    if len(c) != len(d):
        raise ValueError(f"diameters: {len(d)} for {len(c)} centres")
    grains = [build_agglomerate(float(d[k]), disk_diameter, agglomerate_stream(seed, k), vacancies=vacancies,
                                size_scatter=size_scatter, strengths=strengths, centre=c[k]) for k in range(len(d))]
    return join(grains)


def join(grains: Sequence[Agglomerates]) -> Agglomerates:
    """The grains as one set, their disks and bonds numbered one grain after the other."""
    first = np.cumsum([0, *(g.n_disks for g in grains)])[:-1]
    labels = np.cumsum([0, *(g.n_agglomerates for g in grains)])[:-1]

    def cat(name: str, shift: Sequence[int] | None = None, empty: tuple[int, ...] = (0,)) -> NDArray[np.float64]:
        parts = [getattr(g, name) + (0 if shift is None else shift[k]) for k, g in enumerate(grains)]
        joined: NDArray[np.float64] = np.concatenate(parts) if parts else np.zeros(empty)
        return joined

    return Agglomerates(
        positions=cat("positions", empty=(0, 2)), radii=cat("radii"),
        agglomerate=cat("agglomerate", list(labels)).astype(np.int64),
        bond_i=cat("bond_i", list(first)).astype(np.int64), bond_j=cat("bond_j", list(first)).astype(np.int64),
        tensile_strength=cat("tensile_strength"), cohesion=cat("cohesion"),
        centres=cat("centres", empty=(0, 2)), diameters=cat("diameters"),
    )
