"""Crushable grains in the tests: the agglomerates' keys (``agglomerate.*``), the
bonds' strengths from ``cement.*`` and the bonds put into a simulation
(docs/cemented.md, "Crushable grains"; the builder is
:mod:`grainlab.samples.agglomerate`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from grainlab.protocols.config import POSITIVE, Config, Section, key
from grainlab.protocols.specimen import add_parallel_bonds
from grainlab.samples.agglomerate import (
    MAX_SIZE_SCATTER,
    MAX_VACANCIES,
    Agglomerates,
    BondStrengths,
)
from grainlab.simulation import Simulation

__all__ = ["AgglomerateSection", "bond_agglomerates", "bond_strengths"]


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


def bond_strengths(config: Config) -> BondStrengths:
    """The bonds' strengths of ``cement.*``: the means, their scatter and its law."""
    c = config.cement
    law: Any = c.strength_distribution
    return BondStrengths(c.tensile_strength, c.cohesion, c.strength_scatter, law)


def bond_agglomerates(sim: Simulation, grains: Agglomerates, config: Config, first: int = 0) -> None:
    """The grains' bonds put into ``sim``, whose particle ``first`` is the grains' first
    disk (:func:`grainlab.protocols.specimen.add_parallel_bonds`)."""
    add_parallel_bonds(sim, config, grains.bond_i + first, grains.bond_j + first,
                       np.asarray(grains.tensile_strength), np.asarray(grains.cohesion))
