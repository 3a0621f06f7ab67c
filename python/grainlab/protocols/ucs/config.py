"""The unconfined compression test's configuration: the shared sample, material,
consolidation and cement keys, its own loading (``ucs.*``) and the runner's keys."""

from __future__ import annotations

from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, ClassVar

from grainlab.protocols.config import (
    POSITIVE,
    Config,
    PlatenSection,
    SectionOf,
    check_cemented_sample,
    key,
    register_test,
)

__all__ = ["UCS_FIELDS", "UCS_SCHEMA", "UcsConfig", "UcsSection"]

@dataclass(frozen=True)
class UcsSection(PlatenSection):
    """The unconfined compression test's own keys: its loading and its end (the axial
    strain and the axial stress)."""

    prefix: ClassVar[str] = "ucs"
    seating_stress: float = key(
        "stress", 1.0e3, "the seating: after the release the top platen is servo-controlled to this axial stress "
        "in equilibrium (within a tenth of it) before the compression; the strains count from there", **POSITIVE,
    )


UCS_FIELDS = UcsSection.keys()


@dataclass(frozen=True)
class UcsConfig(Config):
    """The unconfined compression test's configuration: the shared sections and its loading."""

    ucs = SectionOf(UcsSection)


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    check_cemented_sample(values, given, "ucs", "unconfined strength")


#: The unconfined compression test's configuration schema (registered as ``"ucs"``).
UCS_SCHEMA = register_test("ucs", UCS_FIELDS, _check, UcsConfig)
