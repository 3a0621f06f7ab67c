"""The Brazilian test's configuration: the shared sample, material, consolidation
and cement keys (a square sample by default), its own disc and loading
(``brazilian.*``) and the runner's keys."""

from __future__ import annotations

from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, ClassVar

from grainlab.protocols.config import (
    SQUARE,
    Config,
    ConfigError,
    PlatenSection,
    SectionOf,
    check_cemented_sample,
    key,
    register_test,
)

__all__ = ["BRAZILIAN_FIELDS", "BRAZILIAN_QUICK", "BRAZILIAN_SCHEMA", "BrazilianConfig", "BrazilianSection"]

#: The disc's least size, in largest grain diameters across.
DISC_GRAINS_ACROSS = 10


@dataclass(frozen=True)
class BrazilianSection(PlatenSection):
    """The Brazilian test's own keys: its loading and its end (the strain the platens'
    displacement over D, the stress 2F / (pi D t)), its disc and its platens."""

    prefix: ClassVar[str] = "brazilian"
    residual_fraction: float = key(
        "number", 0.2, "the loading ends once the platen force after the peak falls below this fraction of the "
        "peak (the split leaves the halves bearing almost nothing)", minimum=0.0, maximum=1.0, exclusive_maximum=True,
    )
    diameter_fraction: float = key(
        "number", 0.9, "the disc's grains are those whose centre lies in the circle at the consolidated sample's "
        "centre whose diameter is this fraction of its smaller side", minimum=0.0, maximum=1.0, exclusive_minimum=True,
    )
    platen_friction: float = key(
        "number", 0.5, "friction between the grains and the two platens that load the disc (the box's walls "
        "keep material.platen_friction while the sample is consolidated)", minimum=0.0,
    )


BRAZILIAN_FIELDS = BrazilianSection.keys()


@dataclass(frozen=True)
class BrazilianConfig(Config):
    """The Brazilian test's configuration: the shared sections, its disc and its loading."""

    brazilian = SectionOf(BrazilianSection)


#: ``--quick``: a square sample 40 mm wide, its disc of about 300 grains.
BRAZILIAN_QUICK: dict[str, Any] = {"sample.width": 0.04, "sample.height": 0.04}


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    check_cemented_sample(values, given, "brazilian", "tensile strength")
    diameter = values["brazilian.diameter_fraction"] * min(values["sample.width"], values["sample.height"])
    if diameter < DISC_GRAINS_ACROSS * values["sample.d_max"]:
        raise ConfigError(
            f"brazilian.diameter_fraction: a disc {diameter:g} m across holds fewer than {DISC_GRAINS_ACROSS} of the "
            f"largest grains ({DISC_GRAINS_ACROSS * values['sample.d_max']:g} m); raise it or the sample's size"
        )


#: The Brazilian test's configuration schema (registered as ``"brazilian"``).
BRAZILIAN_SCHEMA = register_test("brazilian", {**SQUARE, **BRAZILIAN_FIELDS}, _check, BrazilianConfig,
                                 BRAZILIAN_QUICK)
