"""The crushing test's configuration: the seed (``sample.seed``), the grains' material (``material.*``), their
bonds (``cement.*`` but the pairs' choice: every lattice neighbour is bonded), how an
agglomerate is made (``agglomerate.*``), the test's own keys (``crushing.*``) and the
runner's."""

from __future__ import annotations

import dataclasses
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, ClassVar

from grainlab.protocols.agglomerates import AgglomerateSection
from grainlab.protocols.config import (
    POSITIVE,
    RUN_FIELDS,
    CementSection,
    Config,
    ConfigError,
    ConfigSchema,
    MaterialSection,
    SampleSection,
    Section,
    SectionOf,
    check_bonds,
    key,
    register_schema,
)
from grainlab.samples.agglomerate import MIN_DISKS_ACROSS

__all__ = ["CRUSHING_FIELDS", "CRUSHING_SCHEMA", "CrushingConfig", "CrushingSection"]


@dataclass(frozen=True)
class CrushingSection(Section):
    """The crushing test's own keys: the agglomerates, their loading and its end."""

    prefix: ClassVar[str] = "crushing"
    agglomerates: int = key("integer", 30, "agglomerates crushed one after the other (the Weibull fit's N)",
                            minimum=3)
    d_min: float = key("length", 2.0e-3, "smallest agglomerate diameter d (uniform by number up to d_max)",
                       **POSITIVE)
    d_max: float = key("length", 2.0e-3, "largest agglomerate diameter d", **POSITIVE)
    strain_rate: float = key("strain_rate", "50 %/min", "the top platen's speed over the agglomerate's diameter",
                             **POSITIVE)
    final_strain: float = key("strain", 0.2, "an agglomerate's loading ends at this platen displacement over d",
                              minimum=0.0, maximum=0.5, exclusive_minimum=True)
    residual_fraction: float = key(
        "number", 0.5, "an agglomerate has failed at the first record where it has split (two fragments of at "
        "least 0.1 of its solid area) and its force is below this fraction of the peak",
        minimum=0.0, maximum=1.0, exclusive_maximum=True,
    )
    records: int = key("integer", 400, "records over crushing.final_strain (one every final_strain / records)",
                       minimum=1)


#: The cement keys the crushing test reads (the pairs are the lattice's: no cement.bonds
#: or cement.gap), with strengths of 1 MPa scattered by 0.2 by default.
_CEMENT = {name: field for name, field in CementSection.keys().items() if name not in ("cement.bonds", "cement.gap")}
_CEMENT["cement.tensile_strength"] = dataclasses.replace(_CEMENT["cement.tensile_strength"], default=1.0e6)
_CEMENT["cement.cohesion"] = dataclasses.replace(_CEMENT["cement.cohesion"], default=1.0e6)
_CEMENT["cement.strength_scatter"] = dataclasses.replace(_CEMENT["cement.strength_scatter"], default=0.2)

#: Platens with friction: frictionless ones let an agglomerate roll on the disks that
#: first touch them until a face of its lattice meets them.
_MATERIAL = MaterialSection.keys()
_MATERIAL["material.platen_friction"] = dataclasses.replace(_MATERIAL["material.platen_friction"], default=0.5)

#: Every test's seed key: agglomerate k draws from its own stream of it.
_SEED = {"sample.seed": dataclasses.replace(SampleSection.keys()["sample.seed"], help=(
    "random seed: agglomerate k draws its diameter, lattice and bonds' strengths from its own stream of it"))}

CRUSHING_FIELDS = {**_SEED, **_MATERIAL, **_CEMENT, **AgglomerateSection.keys(), **CrushingSection.keys()}


@dataclass(frozen=True)
class CrushingConfig(Config):
    """The crushing test's configuration: the material, the bonds, the agglomerates and their loading."""

    agglomerate = SectionOf(AgglomerateSection)
    crushing = SectionOf(CrushingSection)


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    d_min, d_max, disk = values["crushing.d_min"], values["crushing.d_max"], values["agglomerate.disk_diameter"]
    if d_min > d_max:
        raise ConfigError(f"crushing.d_min: {d_min:g} m exceeds crushing.d_max {d_max:g} m")
    if d_min < MIN_DISKS_ACROSS * disk:
        raise ConfigError(f"agglomerate.disk_diameter: an agglomerate is at least {MIN_DISKS_ACROSS:g} disks across; "
                          f"{disk:g} m disks in a {d_min:g} m agglomerate (crushing.d_min)")
    check_bonds(values)


#: The crushing test's configuration schema (registered as ``"crushing"``); ``--quick``
#: crushes 10 agglomerates.
CRUSHING_SCHEMA = register_schema(ConfigSchema("crushing", {**CRUSHING_FIELDS, **RUN_FIELDS},
                                               {"crushing.agglomerates": 10}, _check, CrushingConfig))
