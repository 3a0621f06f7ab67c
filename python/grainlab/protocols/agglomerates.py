"""Crushable grains in the tests: the agglomerates' keys (``agglomerate.*``), the
bonds' strengths from ``cement.*`` and the bonds put into a simulation
(docs/cemented.md, "Crushable grains"; the builder is
:mod:`grainlab.samples.agglomerate`)."""

from __future__ import annotations

from collections.abc import Mapping
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from grainlab.cement import pairs_within_gap
from grainlab.protocols.config import POSITIVE, Config, ConfigError, Section, key
from grainlab.protocols.specimen import SpecimenRun, add_cement
from grainlab.samples.agglomerate import (
    MAX_SIZE_SCATTER,
    MAX_VACANCIES,
    MIN_DISKS_ACROSS,
    Agglomerates,
    BondStrengths,
    build_agglomerates,
)
from grainlab.simulation import Simulation

__all__ = ["AgglomerateSection", "GrainsSection", "agglomerate_labels", "agglomerate_sample", "bond_agglomerates",
           "bond_strengths", "check_agglomerates", "free_radii"]


@dataclass(frozen=True)
class AgglomerateSection(Section):
    """How a crushable grain is made (:func:`grainlab.samples.agglomerate.build_agglomerate`)."""

    prefix: ClassVar[str] = "agglomerate"
    disk_diameter: float = key("length", 0.2e-3, "diameter of the grains' disks: the hexagonal lattice's spacing",
                               **POSITIVE)
    vacancies: float = key("number", 0.05, "fraction of the lattice's sites left empty at random (the flaws)",
                           minimum=0.0, maximum=MAX_VACANCIES)
    size_scatter: float = key("number", 0.1, "each disk's radius shrunk at random by up to this fraction",
                              minimum=0.0, maximum=MAX_SIZE_SCATTER)


@dataclass(frozen=True)
class GrainsSection(Section):
    """What a sample's grains are (the oedometer's ``sample.grains``)."""

    prefix: ClassVar[str] = "sample"
    grains: str = key("choice", "disk", "'disk', or 'agglomerate': each grain of the radius expansion replaced by an "
                      "agglomerate of bonded disks of its diameter (agglomerate.*, cement.*)",
                      choices=("disk", "agglomerate"))


def check_agglomerates(v: Mapping[str, Any], given: AbstractSet[str]) -> None:
    """``agglomerate.*`` keys without agglomerates; agglomerates without bonds, of another
    shape than disks, or fewer than 3 disks across the smallest grain."""
    if v["sample.grains"] != "agglomerate":
        defaults = AgglomerateSection.keys()
        stray = sorted(k for k in given if k in defaults and v[k] != defaults[k].default)
        if stray:
            raise ConfigError(f"{stray[0]}: given, but sample.grains is 'disk' (give sample.grains=agglomerate)")
        return
    if v["cement.bonds"] != "parallel":
        raise ConfigError("sample.grains: agglomerates are bonded disks; give cement.bonds=parallel and the bonds' "
                          "strengths (cement.tensile_strength, cement.cohesion)")
    if v["sample.shape"] != "disk":
        raise ConfigError(f"sample.shape: agglomerates replace disks, got {v['sample.shape']!r}")
    if v["sample.d_min"] < MIN_DISKS_ACROSS * v["agglomerate.disk_diameter"]:
        raise ConfigError(f"agglomerate.disk_diameter: an agglomerate is at least {MIN_DISKS_ACROSS:g} disks "
                          f"across; {v['agglomerate.disk_diameter']:g} m disks in a {v['sample.d_min']:g} m grain "
                          "(sample.d_min)")


def free_radii(positions: NDArray[np.float64], radii: NDArray[np.float64],
               box: tuple[float, float, float, float]) -> NDArray[np.float64]:
    """Each disk's radius less its overlaps: with each overlapping neighbour the overlap
    shared in proportion to their radii, with each side of ``box`` (xmin, ymin, xmax,
    ymax) taken whole; the circles of these radii overlap nothing."""
    i, j = pairs_within_gap(positions, radii, 0.0)
    distance = np.hypot(*(positions[j] - positions[i]).T)
    free = radii.copy()
    for a, b in ((i, j), (j, i)):
        np.minimum.at(free, a, distance * radii[a] / (radii[a] + radii[b]))
    x, y = positions.T
    sides = np.column_stack([x - box[0], y - box[1], box[2] - x, box[3] - y])
    shrunk: NDArray[np.float64] = np.minimum(free, sides.min(axis=1))
    return shrunk


def agglomerate_sample(sim: Simulation, run: SpecimenRun, config: Config) -> Simulation:
    """The sample of ``sim`` (disks in four walls) with each grain replaced by an
    agglomerate about its centre (grain ``k`` from its own stream of ``sample.seed``),
    bonded, in the same walls: a new simulation. An agglomerate fills its grain's circle
    less the grain's overlaps (:func:`free_radii`), so that no two agglomerates' disks
    overlap; the run's grain count becomes the disks', ``run.sample`` gets the
    agglomerates' count, each one's disks and the largest shrinkage of a grain."""
    n = run.n_grains
    a = config.agglomerate  # type: ignore[attr-defined]  # a configuration with agglomerate.* keys
    left, right = (float(sim.wall(run.walls[w]).points[0, 0]) for w in ("left", "right"))
    bottom, top = (float(sim.wall(run.walls[w]).points[0, 1]) for w in ("bottom", "top"))
    radii = sim.radii[:n]
    free = free_radii(sim.positions[:n], radii, (left, bottom, right, top))
    grains = build_agglomerates(sim.positions[:n], 2.0 * free, a.disk_diameter, config.sample.seed,
                                vacancies=a.vacancies, size_scatter=a.size_scatter, strengths=bond_strengths(config))
    new = Simulation(grains.positions, grains.radii, density=config.material.density, threads=sim.threads)
    for wall in sim.walls:
        new.add_segment_wall(*wall.points)
    bond_agglomerates(new, grains, config)
    run.n_grains = grains.n_disks
    run.sample.update(agglomerates=grains.n_agglomerates, agglomerate_bonds=grains.n_bonds,
                      agglomerate_disks=np.bincount(grains.agglomerate).tolist(),
                      agglomerate_largest_shrinkage=float(np.max(1.0 - free / radii)))
    return new


def agglomerate_labels(run: SpecimenRun) -> NDArray[np.int64]:
    """Each disk's agglomerate in a sample of agglomerates (their disks one after the other)."""
    counts = run.sample["agglomerate_disks"]
    return np.repeat(np.arange(len(counts)), counts)


def bond_strengths(config: Config) -> BondStrengths:
    """The bonds' strengths of ``cement.*``: the means, their scatter and its law."""
    c = config.cement
    law: Any = c.strength_distribution
    return BondStrengths(c.tensile_strength, c.cohesion, c.strength_scatter, law)


def bond_agglomerates(sim: Simulation, grains: Agglomerates, config: Config, first: int = 0) -> None:
    """The grains' bonds put into ``sim``, whose particle ``first`` is the grains' first
    disk (:func:`grainlab.protocols.specimen.add_cement`)."""
    add_cement(sim, config, grains.bond_i + first, grains.bond_j + first,
                       np.asarray(grains.tensile_strength), np.asarray(grains.cohesion))
