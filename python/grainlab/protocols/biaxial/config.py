"""The biaxial test's configuration: the shared sample, material and
consolidation keys (:data:`~grainlab.protocols.config.SHARED_FIELDS`), its own
sections (:class:`BoundarySection`: ``boundary.*``; :class:`ShearSection`:
``shear.*``) and the runner's; :func:`resolve` resolves it."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from grainlab import paper
from grainlab.protocols.config import (
    POSITIVE,
    RUN_FIELDS,
    SHARED_FIELDS,
    Config,
    ConfigError,
    Field,
    Section,
    SectionOf,
    check_sample,
    coerce_field,
    grain_shape,
    key,
    register_test,
)

__all__ = ["BIAXIAL_FIELDS", "BIAXIAL_SCHEMA", "FIELDS", "BiaxialConfig", "BoundarySection", "ShearSection",
           "check_boundary", "coerce", "resolve"]


@dataclass(frozen=True)
class BoundarySection(Section):
    """The biaxial test's lateral boundary (docs/boundary.md)."""

    prefix: ClassVar[str] = "boundary"
    kind: str = key(
        "choice", "membrane",
        "lateral boundary (docs/boundary.md): a bonded membrane (A), the outermost grains (B), or the "
        "consolidation box's rigid side walls (C; the one of shear.volume = constant)",
        choices=("membrane", "outer_particles", "walls"),
    )
    membrane_diameter: float = key("length", 0.5e-3, "diameter of the membrane disks", **POSITIVE)
    membrane_overlap: float = key(
        "strain", 0.5, "rest overlap of neighbouring membrane disks, fraction of their diameter",
        minimum=0.0, maximum=0.9,
    )
    membrane_stiffness: float = key(
        "stiffness", 8.45e5, "normal and shear stiffness of the membrane bonds", **POSITIVE
    )
    membrane_friction: float = key("number", 0.0, "friction between grains and membrane disks", minimum=0.0)


@dataclass(frozen=True)
class ShearSection(Section):
    """The biaxial test's shearing (the cyclic test's but its end and snapshots)."""

    prefix: ClassVar[str] = "shear"
    strain_rate: float | str = key(
        "strain_rate", paper.STRAIN_RATE_PER_S,
        "axial strain rate (Table 1: 2 %/min); auto = the fastest with the heaviest grain's inertial "
        "number <= shear.inertial_number (2 %/min with Table 1: no faster rate passed the rate study)",
        **POSITIVE, allow_auto=True,
    )
    volume: str = key(
        "choice", "free",
        "free: the confining pressure held (drained); constant: the sample's area held by the rigid side walls, "
        "the undrained test's analogue (needs boundary.kind = walls, its default then)",
        choices=("free", "constant"),
    )
    final_strain: float = key("strain", 0.10, "final axial strain", minimum=0.0, maximum=0.5, exclusive_minimum=True)
    record_interval: float = key(
        "strain", 0.0005, "axial strain between two records (<= 0.05 %)", minimum=0.0, maximum=0.0005,
        exclusive_minimum=True,
    )
    snapshot_strains: list[float] = key(
        "strain_list", list(paper.SNAPSHOT_STRAINS),
        "axial strains of the full snapshots (the paper's 0, 0.5, 0.7, 0.9, 1.5 and 10 %)",
    )
    inertial_number: float = key(
        "number", 1.0e-4,
        "bound on the inertial number (and Eq. 16 factor) for the auto strain rate: its value at the rate study's "
        "fastest converged rate, 2 %/min with Table 1", **POSITIVE
    )


#: The biaxial test's own keys: the lateral boundary and the shearing.
BIAXIAL_FIELDS: dict[str, Field] = {**BoundarySection.keys(), **ShearSection.keys()}
#: Every key of the biaxial test, in the order files and tables list them.
FIELDS: dict[str, Field] = {**SHARED_FIELDS, **BIAXIAL_FIELDS, **RUN_FIELDS}


@dataclass(frozen=True)
class BiaxialConfig(Config):
    """The biaxial (and cyclic) test's configuration: the shared sections, its
    lateral boundary and its shearing."""

    boundary = SectionOf(BoundarySection)
    shear = SectionOf(ShearSection)


def coerce(key: str, value: Any) -> Any:
    """Converts ``value`` for the biaxial key ``key`` to SI and checks its range."""
    return coerce_field(FIELDS, key, value)


def check_boundary(v: dict[str, Any], given: AbstractSet[str] = frozenset()) -> None:
    """A constant-volume test needs the rigid side walls: they are its boundary unless
    another was asked for, which is refused; clumps cannot form the outermost grains'
    chain."""
    if v["boundary.kind"] == "outer_particles" and v["sample.shape"] != "disk" and grain_shape(v) is not None:
        raise ConfigError(
            f"boundary.kind: 'outer_particles' bonds the outermost grains into a chain, which the pebbles of "
            f"sample.shape = {v['sample.shape']!r} cannot join (they move with their clump); use 'membrane' or 'walls'"
        )
    if v["shear.volume"] != "constant":
        return
    if "boundary.kind" not in given:
        v["boundary.kind"] = "walls"
    elif v["boundary.kind"] != "walls":
        raise ConfigError(
            f"shear.volume: 'constant' holds the sample's area with the rigid side walls, not with "
            f"boundary.kind = {v['boundary.kind']!r} (whose area follows the grains); set boundary.kind = "
            "'walls' or leave it out"
        )


def _check(v: dict[str, Any], given: AbstractSet[str] = frozenset()) -> None:
    check_sample(v, given)
    check_boundary(v, given)
    if 0.0 not in v["shear.snapshot_strains"]:
        raise ConfigError(
            "shear.snapshot_strains: must include 0, the state at the start of shearing that "
            f"displacements, local strains and the shear band are measured from; got {v['shear.snapshot_strains']}"
        )
    positive = [s for s in v["shear.snapshot_strains"] if s > 0]
    if positive and positive[0] > v["shear.final_strain"] + 1e-12:
        raise ConfigError(
            f"shear.final_strain: {v['shear.final_strain']:g} is below the first snapshot strain "
            f"{positive[0]:g} (shear.snapshot_strains); raise it or change the snapshots"
        )
    if v["shear.final_strain"] < v["shear.record_interval"]:
        raise ConfigError(
            f"shear.final_strain: {v['shear.final_strain']:g} is below one record interval "
            f"({v['shear.record_interval']:g})"
        )


#: The biaxial test's configuration schema (registered as ``"biaxial"``).
BIAXIAL_SCHEMA = register_test("biaxial", BIAXIAL_FIELDS, _check, BiaxialConfig)


def resolve(
    config_file: str | Path | None = None,
    overrides: Mapping[str, Any] | Iterable[str] | None = None,
    *,
    quick: bool = False,
) -> BiaxialConfig:
    """The biaxial test's configuration: defaults (Table 1), then ``--quick``, then the
    TOML file, then overrides (a mapping, or ``key=value`` strings), all validated
    before anything runs (:meth:`ConfigSchema.resolve` of :data:`BIAXIAL_SCHEMA`)."""
    return BIAXIAL_SCHEMA.resolve(config_file, overrides, quick=quick)
