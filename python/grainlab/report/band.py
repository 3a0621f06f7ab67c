"""The shear band of a biaxial run at one snapshot, as the report measures it.

The grains' local strain since the first snapshot
(:class:`grainlab.analysis.LocalStrain`, grains only, matched by id; its
``excess_shear_strain``, the strain less the sample's median strain) goes to
:class:`grainlab.analysis.ShearBand`, whose public results are used as they
are: ``found`` / ``reason`` (its acceptance test), ``angle_degrees``,
``thickness``, ``thickness_diameters``, ``contrast``, the members and the mean
lambda inside and outside. The inclination to the sigma_3 (horizontal)
direction is ``min(angle, 180 deg - angle)``.

Where the installed ShearBand has no acceptance test (no ``found``), a band
counts as found when its strain profile stands above the background
(``contrast > 0``) and it is at least one mean diameter thick, and the result
says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from grainlab.analysis import LocalStrain, ShearBand, StabilityIndex
from grainlab.io.hdf5 import Results
from grainlab.snapshot import Snapshot

__all__ = ["BandResult", "measure_band", "peak_snapshot"]


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


def _grains(snap: Snapshot) -> Snapshot:
    g = snap.is_sample
    return Snapshot(snap.positions[g], snap.radii[g], snap.ids[g], kind=snap.kind[g], box=snap.box,
                    periodic=snap.periodic)


def _strain(info_strain: float | None) -> float:
    return float(info_strain) if info_strain is not None and math.isfinite(info_strain) else math.nan


def peak_snapshot(results: Results, peak_strain: float) -> str | None:
    """The snapshot other than the first whose axial strain is closest to ``peak_strain``."""
    infos = list(results.snapshots)[1:]
    known = [s for s in infos if math.isfinite(_strain(s.axial_strain))]
    if not known:
        return infos[-1].name if infos else None
    return min(known, key=lambda s: abs(_strain(s.axial_strain) - peak_strain)).name


def measure_band(results: Results, snapshot: str, reference: str | None = None) -> BandResult:
    """The band at ``snapshot`` against ``reference`` (default: the first snapshot)."""
    reference = reference if reference is not None else results.snapshot_names[0]
    info = {s.name: s for s in results.snapshots}[snapshot]
    current, first = results.snapshot(snapshot), results.snapshot(reference)
    g = current.is_sample
    nan = math.nan

    def missing(reason: str, acceptance: str = "") -> BandResult:
        return BandResult(snapshot, reference, _strain(info.axial_strain), False, reason, nan, nan, nan, nan,
                          nan, 0, nan, nan, acceptance)

    gamma = LocalStrain().compute(_grains(first), _grains(current)).excess_shear_strain
    if int(np.isfinite(gamma).sum()) < 10:
        return missing(f"only {int(np.isfinite(gamma).sum())} grains have a local strain (10 are needed)")
    lam = StabilityIndex().compute(current)
    try:
        band = ShearBand().compute(
            current.positions[g],
            gamma,
            current.radii[g],
            stability_index=lam.stability_index[g],
            n_contacts=lam.n_contacts[g],
        )
    except ValueError as error:
        return missing(f"ShearBand: {error}")
    if hasattr(type(band), "found"):
        found, reason = bool(band.found), str(getattr(band, "reason", ""))
        acceptance = "ShearBand's own acceptance test"
    else:
        problems = []
        if not band.contrast > 0:
            problems.append("no part of the strain profile stands above the background")
        if not band.thickness_diameters >= 1.0:
            problems.append(f"thinner ({band.thickness_diameters:.2f}) than one mean diameter")
        found, reason = not problems, "; ".join(problems)
        acceptance = "contrast > 0 and at least one mean diameter thick (this ShearBand has no test of its own)"
    angle = float(band.angle_degrees)
    if not found and not reason:
        reason = "not accepted by ShearBand"
    return BandResult(
        snapshot=snapshot,
        reference=reference,
        axial_strain=_strain(info.axial_strain),
        found=found,
        reason="" if found else reason,
        angle=math.radians(angle),
        inclination=math.radians(min(angle, 180.0 - angle)),
        thickness_m=float(band.thickness),
        thickness_diameters=float(band.thickness_diameters),
        contrast=float(band.contrast),
        n_grains=int(np.count_nonzero(band.members)),
        mean_lambda_inside=float(band.mean_lambda_inside),
        mean_lambda_outside=float(band.mean_lambda_outside),
        acceptance=acceptance,
    )
