"""The shear band of a biaxial run, as the report shows it.

The report shows the bands that the run's figures show: those of
:func:`grainlab.analysis.biaxial_figures.fabric_numbers` (``band``, at the
snapshot nearest the peak, and ``band_final``, at the end of shearing; the
detector :class:`grainlab.analysis.ShearBand` on the grains' excess local
strain since the first snapshot, grains away from the boundary, with its own
acceptance test). :func:`band_from_numbers` turns one of them (the JSON form
of ``summary.json``) into a :class:`BandResult`. The inclination to the
sigma_3 (horizontal) direction is ``min(angle, 180 deg - angle)``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["BandResult", "band_from_numbers"]


@dataclass(frozen=True)
class BandResult:
    """The band at ``snapshot`` against ``reference`` (angles in rad, NaN when unknown)."""

    snapshot: str
    reference: str
    axial_strain: float
    found: bool
    #: Why no band was accepted ("" when found).
    reason: str
    #: Direction, CCW from +x, in [0, pi).
    angle: float
    #: Acute angle to the horizontal (the sigma_3 direction), in [0, pi/2].
    inclination: float
    thickness_m: float
    thickness_diameters: float
    contrast: float
    n_grains: int
    mean_lambda_inside: float
    mean_lambda_outside: float
    #: How "found" was decided.
    acceptance: str

    @property
    def inclination_degrees(self) -> float:
        return math.degrees(self.inclination)

    @property
    def angle_degrees(self) -> float:
        return math.degrees(self.angle)


def _number(value: Any) -> float:
    return float(value) if isinstance(value, int | float) and math.isfinite(value) else math.nan


def band_from_numbers(numbers: Mapping[str, Any] | None) -> BandResult | None:
    """A :class:`BandResult` from the JSON form of a
    :class:`~grainlab.analysis.biaxial_figures.BandNumbers` (None stays None)."""
    if not numbers:
        return None
    found = bool(numbers.get("found"))
    angle = _number(numbers.get("angle_deg"))
    inclination = _number(numbers.get("inclination_deg"))
    if math.isfinite(angle) and not math.isfinite(inclination):
        inclination = min(angle, 180.0 - angle)
    reason = str(numbers.get("reason") or "")
    return BandResult(
        snapshot=str(numbers.get("snapshot", "")),
        reference=str(numbers.get("reference", "")),
        axial_strain=_number(numbers.get("axial_strain")),
        found=found,
        reason="" if found else (reason or "not accepted by ShearBand"),
        angle=math.radians(angle),
        inclination=math.radians(inclination),
        thickness_m=_number(numbers.get("thickness_m")),
        thickness_diameters=_number(numbers.get("thickness_diameters")),
        contrast=_number(numbers.get("contrast")),
        n_grains=int(numbers.get("n_grains") or 0),
        mean_lambda_inside=_number(numbers.get("mean_lambda_inside")),
        mean_lambda_outside=_number(numbers.get("mean_lambda_outside")),
        acceptance="ShearBand's own acceptance test (thickness, prominence), grains away from the boundary",
    )
