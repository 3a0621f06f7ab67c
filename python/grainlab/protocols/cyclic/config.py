"""The cyclic biaxial test's configuration: the biaxial test's keys but the
monotonic loading's end and snapshots (``shear.final_strain``,
``shear.snapshot_strains``), and its own (``cyclic.*``)."""

from __future__ import annotations

from collections.abc import Set as AbstractSet
from typing import Any

from grainlab.protocols.config import (
    BIAXIAL_FIELDS,
    QUICK,
    RUN_FIELDS,
    SHARED_FIELDS,
    ConfigError,
    ConfigSchema,
    Field,
    check_boundary,
    check_sample,
    register_schema,
)

__all__ = ["CYCLIC_FIELDS", "CYCLIC_SCHEMA"]

#: The cyclic test's own keys.
CYCLIC_FIELDS: dict[str, Field] = {
    "cyclic.strain_amplitude": Field(
        "strain", 0.005, "axial strain amplitude: each cycle goes 0 -> +amplitude -> -amplitude -> 0 "
        "(compression positive); at most 5 %", minimum=0.0, maximum=0.05, exclusive_minimum=True,
    ),
    "cyclic.cycles": Field("integer", 5, "number of cycles", minimum=1, maximum=1000),
}

_MONOTONIC_ONLY = ("shear.final_strain", "shear.snapshot_strains")


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    check_sample(values, given)
    check_boundary(values, given)
    amplitude, interval = values["cyclic.strain_amplitude"], values["shear.record_interval"]
    if amplitude < 4 * interval:
        raise ConfigError(
            f"cyclic.strain_amplitude: {amplitude:g} is less than four record intervals "
            f"(shear.record_interval {interval:g}): a cycle's loops would have too few points; "
            "raise it or record more often"
        )


#: The cyclic test's configuration schema (registered as ``"cyclic"``).
CYCLIC_SCHEMA = register_schema(ConfigSchema(
    "cyclic",
    {**SHARED_FIELDS, **{k: f for k, f in BIAXIAL_FIELDS.items() if k not in _MONOTONIC_ONLY},
     **CYCLIC_FIELDS, **RUN_FIELDS},
    QUICK,
    _check,
))
