"""The periodic simple-shear test's configuration: the shared sample,
material and consolidation keys, its own (``simple_shear.*``) and the runner's.

The sample is made as every test's (radius expansion in four walls, the
``sample.*`` keys); its walls then give way to a periodic cell of the same
box, in which it is consolidated and sheared (docs/protocols.md, "Periodic
simple shear")."""

from __future__ import annotations

from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, ClassVar

from grainlab.protocols.config import (
    POSITIVE,
    SQUARE,
    Config,
    ConfigError,
    Section,
    SectionOf,
    check_sample,
    key,
    register_test,
)

__all__ = ["SIMPLE_SHEAR_FIELDS", "SIMPLE_SHEAR_QUICK", "SIMPLE_SHEAR_SCHEMA", "SimpleShearConfig", "SimpleShearSection"]

@dataclass(frozen=True)
class SimpleShearSection(Section):
    """The simple-shear test's own keys: the cell's loading."""

    prefix: ClassVar[str] = "simple_shear"
    volume: str = key(
        "choice", "free",
        "free: the cell's height is servo-controlled to hold the normal stress sigma_yy (constant normal "
        "stress); constant: the cell's area is held (constant volume)",
        choices=("free", "constant"),
    )
    normal_stress: float | str = key(
        "stress", "auto", "normal stress sigma_yy held at free volume (auto: consolidation.pressure)",
        **POSITIVE, allow_auto=True,
    )
    inertial_number: float = key(
        "number", 1e-3,
        "inertial number I = gamma_dot d / sqrt(sigma_n / rho) that sets the shear rate gamma_dot (d the mean "
        "grain diameter, sigma_n the normal stress at the start of shearing, rho material.density)",
        minimum=0.0, maximum=1.0, exclusive_minimum=True,
    )
    local_damping: float | str = key(
        "number", "auto",
        "local damping alpha while shearing (auto: material.local_damping, which makes and consolidates the "
        "sample); 0 leaves the grains' inertia undamped, as a rate sweep needs", minimum=0.0, maximum=1.0,
        exclusive_maximum=True, allow_auto=True,
    )
    final_strain: float = key(
        "strain", 1.0, "shear strain gamma at which shearing stops (1 = 100 %)", minimum=0.0, maximum=100.0,
        exclusive_minimum=True,
    )
    record_interval: float = key("strain", 0.01, "shear strain between records", **POSITIVE)
    snapshot_strains: list[float] = key(
        "shear_strain_list", [0.0, 0.1, 0.25, 0.5, 1.0], "shear strains at which a snapshot is stored",
    )


SIMPLE_SHEAR_FIELDS = SimpleShearSection.keys()


@dataclass(frozen=True)
class SimpleShearConfig(Config):
    """The simple-shear test's configuration: the shared sections and its shearing."""

    simple_shear = SectionOf(SimpleShearSection)

#: ``--quick``: a square cell of a few hundred disks sheared to 100 %.
SIMPLE_SHEAR_QUICK: dict[str, Any] = {"sample.width": 0.03, "sample.height": 0.03}


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    check_sample(values, given)
    final, interval = values["simple_shear.final_strain"], values["simple_shear.record_interval"]
    if interval > final:
        raise ConfigError(
            f"simple_shear.record_interval: {interval:g} exceeds simple_shear.final_strain {final:g}: no record "
            "would be made"
        )
    if values["simple_shear.volume"] == "constant" and values["simple_shear.normal_stress"] != "auto":
        raise ConfigError(
            "simple_shear.normal_stress: a constant-volume run holds the cell's area, not a normal stress; "
            "leave it out or set simple_shear.volume = 'free'"
        )
    beyond = [s for s in values["simple_shear.snapshot_strains"] if not 0.0 <= s <= final]
    default = SIMPLE_SHEAR_FIELDS["simple_shear.snapshot_strains"].default
    if beyond and values["simple_shear.snapshot_strains"] != default:  # the default's beyond a shorter run are left out
        raise ConfigError(
            f"simple_shear.snapshot_strains: {beyond[0]:g} lies outside 0 .. simple_shear.final_strain ({final:g})"
        )


#: The simple-shear test's configuration schema (registered as ``"simple_shear"``): a square
#: cell by default, Table 1's width on both sides (about 1,700 grains).
SIMPLE_SHEAR_SCHEMA = register_test("simple_shear", {**SQUARE, **SIMPLE_SHEAR_FIELDS}, _check, SimpleShearConfig,
                                    SIMPLE_SHEAR_QUICK)
