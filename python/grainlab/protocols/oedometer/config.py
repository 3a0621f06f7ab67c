"""The oedometer's configuration: the shared sample, material and consolidation
keys, its own load path (``oedometer.*``) and the runner's keys."""

from __future__ import annotations

from collections.abc import Set as AbstractSet
from typing import Any

from grainlab.protocols.config import (
    QUICK,
    RUN_FIELDS,
    SHARED_FIELDS,
    ConfigError,
    ConfigSchema,
    Field,
    check_sample,
    register_schema,
)

__all__ = ["OEDOMETER_FIELDS", "OEDOMETER_SCHEMA"]

_KPA = 1e3

#: The oedometer's own keys.
OEDOMETER_FIELDS: dict[str, Field] = {
    "oedometer.vertical_stresses": Field(
        "stress_list", [v * _KPA for v in (200, 400, 800, 1600, 800, 400, 200, 100)],
        "vertical stresses of the load steps, in order (loading, then unloading: any path)",
    ),
    "oedometer.tolerance": Field(
        "strain", 0.01, "a load step ends with sigma_v within this fraction of its target", minimum=0.0,
        exclusive_minimum=True,
    ),
    "oedometer.max_steps": Field("integer", 2_000_000, "give up a load step after this many steps", minimum=1),
    "oedometer.friction_angle": Field(
        "angle", "auto",
        "phi' of Jaky's K0 = 1 - sin phi' and Mayne-Kulhawy's K0 OCR^sin phi' in the report (e.g. the "
        "peak friction angle of a biaxial run of the same material); auto: no comparison",
        minimum=0.0, maximum=90.0 * 3.141592653589793 / 180.0, exclusive_minimum=True, exclusive_maximum=True,
        allow_auto=True,
    ),
}


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    check_sample(values, given)
    if not values["oedometer.vertical_stresses"]:
        raise ConfigError("oedometer.vertical_stresses: give at least one vertical stress")


#: The oedometer's configuration schema (registered as ``"oedometer"``).
OEDOMETER_SCHEMA = register_schema(
    ConfigSchema("oedometer", {**SHARED_FIELDS, **OEDOMETER_FIELDS, **RUN_FIELDS}, QUICK, _check)
)
