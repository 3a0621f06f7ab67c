"""The measures per body of a snapshot of clumps, as ``grainlab analyze`` reports them
(``fabric.json``'s ``body_*`` entries, ``bodies.csv``; docs/analysis.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._util import json_number
from grainlab.analysis.fabric import ContactAnisotropy, CoordinationNumber
from grainlab.analysis.per_body import (
    BodyCoordination,
    BodyOrientation,
    BodyStabilityIndex,
    BodyView,
    body_view,
    has_clumps,
)
from grainlab.analysis.stability import StabilityIndex
from grainlab.analysis.strain import LocalStrain
from grainlab.analysis.stress import GrainStress, LoveWeberStress
from grainlab.snapshot import Snapshot

__all__ = ["BodyAnalysis", "analyze_bodies"]


@dataclass
class BodyAnalysis:
    """The measures per body (:func:`analyze_bodies`)."""

    view: BodyView
    coordination: BodyCoordination
    anisotropy: ContactAnisotropy
    force_anisotropy: ContactAnisotropy | None
    stability: BodyStabilityIndex
    orientation: BodyOrientation
    stress: LoveWeberStress | None = None
    grain_stress: GrainStress | None = None
    strain: LocalStrain | None = None

    def summary(self) -> dict[str, Any]:
        """The scalars, as ``fabric.json`` writes them (angles in degrees)."""
        num = json_number
        z, a, fa = self.coordination, self.anisotropy, self.force_anisotropy
        lam, o, sigma = self.stability, self.orientation, self.stress
        return {
            "n_bodies": z.n_bodies,
            "n_clumps": int((self.view.n_pebbles[self.view.snapshot.is_sample] > 1).sum()),
            "body_n_pairs": z.n_pairs_total,
            "body_n_contacts": z.n_contacts_total,
            "body_Z": num(z.coordination_number),
            "body_Z_c": num(z.contact_coordination_number),
            "body_mechanical_Z": num(z.mechanical_coordination_number),
            "body_mechanical_Z_c": num(z.mechanical_contact_coordination_number),
            "body_n_rattlers": int(z.rattlers.sum()),
            "body_rattler_rule": f"iteratively remove bodies with < {z.min_contacts} touching bodies",
            "body_a": num(a.anisotropy),
            "body_theta_a_deg": num(np.degrees(a.direction)),
            "body_a_n": num(fa.anisotropy) if fa else None,
            "body_theta_n_deg": num(np.degrees(fa.direction)) if fa else None,
            "body_mean_lambda": num(lam.mean),
            "body_mean_lambda_all": num(lam.mean_all),
            "body_lambda_direction": lam.direction,
            "body_orientation_a": num(o.anisotropy),
            "body_orientation_deg": num(np.degrees(o.direction)),
            "body_n_oriented": o.n_oriented,
            "body_stress_pa": sigma.stress.tolist() if sigma is not None else None,
        }

    def table(self) -> dict[str, NDArray[Any]]:
        """Per-body columns for ``bodies.csv`` (beyond id, x, y, radius, rotation, kind)."""
        view = self.view
        n = view.n_bodies
        nan = np.full(n, np.nan)
        label = np.empty(n, dtype=np.int64)
        label[view.body[::-1]] = view.pebbles.grains()[::-1]  # each body's first pebble's
        s = self.strain
        return {
            "grain": label,
            "n_pebbles": view.n_pebbles,
            "area": view.area,
            "n_neighbours": self.coordination.n_neighbours,
            "n_contacts": self.stability.n_contacts,
            "rattler": self.coordination.rattlers.astype(np.int64),
            "stability_index": self.stability.stability_index,
            "axis": self.orientation.axis,
            "major_stress_pa": self.grain_stress.major if self.grain_stress is not None else nan,
            "displacement": s.displacement_magnitude if s else nan,
            "displacement_x": s.displacement[:, 0] if s else nan,
            "displacement_y": s.displacement[:, 1] if s else nan,
            "angle_change": s.rotation if s else nan,
        }


def analyze_bodies(
    snapshot: Snapshot,
    reference: Snapshot | None = None,
    *,
    like: tuple[CoordinationNumber, ContactAnisotropy, StabilityIndex] | None = None,
    strain: LocalStrain | None = None,
    notes: list[str] | None = None,
) -> BodyAnalysis:
    """The measures per body of ``snapshot``: coordination numbers, the anisotropies,
    lambda, the orientation fabric, with forces the stress of the whole and of each
    body, and with a ``reference`` of clumps the bodies' displacements and angle
    changes. Each measure takes the parameters of the pebbles' measure in ``like``
    (default: the defaults), ``strain`` the neighbourhood (default
    :class:`LocalStrain`'s); ``notes`` gets what could not be measured."""
    coordination, anisotropy, stability = like or (
        CoordinationNumber(), ContactAnisotropy(), StabilityIndex()
    )
    view = body_view(snapshot)
    bodies = view.snapshot
    force = bodies.normal_force
    fabric = (anisotropy.include_boundary, anisotropy.edge_tolerance)
    reading = {"slots": stability.slots, "anchor": stability.anchor, "deviation": stability.deviation}
    rule = (coordination.min_contacts, coordination.include_boundary, coordination.boundary)
    weighted = ContactAnisotropy(anisotropy.bins, "normal_force", *fabric)
    result = BodyAnalysis(
        view,
        BodyCoordination(*rule).compute(view),
        ContactAnisotropy(anisotropy.bins, "count", *fabric).compute(bodies),
        None if force is None else weighted.compute(bodies),
        BodyStabilityIndex(stability.include_boundary, stability.boundary, **reading).compute(view),
        BodyOrientation().compute(view),
    )
    if force is not None and float(np.sum(force)) > 0.0:
        result.stress = LoveWeberStress().compute(bodies)
        result.grain_stress = GrainStress().compute(bodies)
    if reference is not None:
        if has_clumps(reference):
            result.strain = (strain or LocalStrain()).compute(body_view(reference).snapshot, bodies)
        elif notes is not None:
            notes.append("the reference snapshot has no clumps: the bodies' displacements not computed")
    return result
