"""The oedometer's configuration: the shared sample, material and consolidation
keys, its own load path (``oedometer.*``) and the runner's keys."""

from __future__ import annotations

from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, ClassVar

from grainlab.protocols.agglomerates import AgglomerateSection, GrainsSection, check_agglomerates
from grainlab.protocols.config import (
    POSITIVE,
    Config,
    ConfigError,
    Section,
    SectionOf,
    check_sample,
    key,
    register_test,
)

__all__ = ["OEDOMETER_FIELDS", "OEDOMETER_SCHEMA", "OedometerConfig", "OedometerSection"]

_KPA = 1e3

@dataclass(frozen=True)
class OedometerSection(Section):
    """The oedometer's own keys: its load path."""

    prefix: ClassVar[str] = "oedometer"
    vertical_stresses: list[float] = key(
        "stress_list", [v * _KPA for v in (200, 400, 800, 1600, 800, 400, 200, 100)],
        "vertical stresses of the load steps, in order (loading, then unloading: any path)",
    )
    tolerance: float = key("strain", 0.01, "a load step ends with sigma_v within this fraction of its target",
                           **POSITIVE)
    max_steps: int = key("integer", 2_000_000, "give up a load step after this many steps", minimum=1)
    friction_angle: float | str = key(
        "angle", "auto",
        "phi' of Jaky's K0 = 1 - sin phi' and Mayne-Kulhawy's K0 OCR^sin phi' in the report (e.g. the "
        "peak friction angle of a biaxial run of the same material); auto: no comparison",
        minimum=0.0, maximum=90.0 * 3.141592653589793 / 180.0, exclusive_minimum=True, exclusive_maximum=True,
        allow_auto=True,
    )


OEDOMETER_FIELDS = {**OedometerSection.keys(), **GrainsSection.keys(), **AgglomerateSection.keys()}


@dataclass(frozen=True)
class OedometerConfig(Config):
    """The oedometer's configuration: the shared sections, its load path and its grains
    (disks, or crushable agglomerates)."""

    oedometer = SectionOf(OedometerSection)
    grain_kind = SectionOf(GrainsSection)
    agglomerate = SectionOf(AgglomerateSection)


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    check_sample(values, given)
    check_agglomerates(values, given)
    if not values["oedometer.vertical_stresses"]:
        raise ConfigError("oedometer.vertical_stresses: give at least one vertical stress")


#: The oedometer's configuration schema (registered as ``"oedometer"``).
OEDOMETER_SCHEMA = register_test("oedometer", OEDOMETER_FIELDS, _check, OedometerConfig)
