"""Run every measure on a snapshot (``grainlab analyze``; the files are written by
:func:`grainlab.postprocess.write_analysis`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._util import json_number
from grainlab.analysis.body_analysis import BodyAnalysis, analyze_bodies
from grainlab.analysis.fabric import ContactAnisotropy, CoordinationNumber
from grainlab.analysis.force_chains import ForceChains
from grainlab.analysis.loops import ContactLoops
from grainlab.analysis.networks import ForceNetworks
from grainlab.analysis.per_body import BodyCoordination, BodyStabilityIndex, body_view, has_clumps
from grainlab.analysis.shear_band import ShearBand
from grainlab.analysis.stability import DEFAULT_READING, StabilityIndex
from grainlab.analysis.strain import LocalStrain
from grainlab.analysis.stress import GrainStress
from grainlab.analysis.stress_fabric import FabricTensor, StressForceFabric
from grainlab.analysis.tessellation import LocalPorosity
from grainlab.snapshot import Snapshot

__all__ = ["AnalysisResult", "analyze_snapshot", "fabric_summary"]


@dataclass
class AnalysisResult:
    """Everything :func:`analyze_snapshot` computed (the files of ``grainlab analyze``
    are written from it by :func:`grainlab.postprocess.write_analysis`)."""

    snapshot: Snapshot
    coordination: CoordinationNumber
    anisotropy: ContactAnisotropy
    force_anisotropy: ContactAnisotropy | None
    stability: StabilityIndex
    strain: LocalStrain | None = None
    band: ShearBand | None = None
    notes: list[str] = field(default_factory=list)
    fabric_tensor: FabricTensor | None = None
    loops: ContactLoops | None = None
    porosity: LocalPorosity | None = None
    networks: ForceNetworks | None = None
    stress_force_fabric: StressForceFabric | None = None
    grain_stress: GrainStress | None = None
    chains: ForceChains | None = None
    #: The measures per body, for a snapshot of clumps (None for disks).
    bodies: BodyAnalysis | None = None

    def summary(self) -> dict[str, Any]:
        """The scalar results, as written to ``fabric.json`` (angles in degrees)."""
        num = json_number

        a = self.anisotropy
        fa = self.force_anisotropy
        candidate = self.band
        b = self.found_band
        b2 = b.second if b is not None and b.second is not None and b.second.found else None
        out: dict[str, Any] = {
            "n_particles": self.coordination.n_particles,
            "n_contacts": self.coordination.n_contacts_total,
            "Z": num(self.coordination.coordination_number),
            "mechanical_Z": num(self.coordination.mechanical_coordination_number),
            "n_rattlers": int(self.coordination.rattlers.sum()),
            "rattler_rule": (
                f"iteratively remove particles with < {self.coordination.min_contacts} contacts"
            ),
            "contact_count_distribution": [float(v) for v in self.coordination.count_distribution],
            "bins": a.bins,
            "a": num(a.anisotropy),
            "theta_a_deg": num(np.degrees(a.direction)),
            "a_binned": num(a.anisotropy_binned),
            "theta_a_binned_deg": num(np.degrees(a.direction_binned)),
            "a_fourier": num(a.anisotropy_fourier),
            "theta_a_fourier_deg": num(np.degrees(a.direction)),
            "fabric_tensor": a.fabric_tensor.tolist()
            if np.all(np.isfinite(a.fabric_tensor))
            else None,
            "a_n": num(fa.anisotropy) if fa else None,
            "theta_n_deg": num(np.degrees(fa.direction)) if fa else None,
            "a_n_binned": num(fa.anisotropy_binned) if fa else None,
            "theta_n_binned_deg": num(np.degrees(fa.direction_binned)) if fa else None,
            "a_n_fourier": num(fa.anisotropy_fourier) if fa else None,
            "theta_n_fourier_deg": num(np.degrees(fa.direction)) if fa else None,
            "mean_lambda": num(self.stability.mean),
            "mean_lambda_all": num(self.stability.mean_all),
            "lambda_includes_boundary_contacts": self.stability.include_boundary,
            "lambda_boundary_counting": self.stability.boundary,
            # only under a reading of Eq. 9-11 other than the default (the file is unchanged then)
            **(
                {"lambda_reading": self.stability.reading}
                if self.stability.reading != DEFAULT_READING
                else {}
            ),
            "band_found": b is not None,
            "band_reason": (
                candidate.reason
                if candidate is not None
                else "no shear band searched (no reference or too few strains)"
            ),
            "band_angle_deg": num(b.angle_degrees) if b else None,
            "band_inclination_deg": num(b.inclination_degrees) if b else None,
            "band_thickness_m": num(b.thickness) if b else None,
            "band_thickness_diameters": num(b.thickness_diameters) if b else None,
            "band_n_particles": int(b.members.sum()) if b else None,
            "band_contrast": num(b.contrast) if b else None,
            "band_prominence": num(b.prominence) if b else None,
            "mean_lambda_in_band": num(b.mean_lambda_inside) if b else None,
            "mean_lambda_outside_band": num(b.mean_lambda_outside) if b else None,
            "band2_found": b2 is not None,
            "band2_angle_deg": num(b2.angle_degrees) if b2 else None,
            "band2_inclination_deg": num(b2.inclination_degrees) if b2 else None,
            "band2_thickness_diameters": num(b2.thickness_diameters) if b2 else None,
            "band2_contrast": num(b2.contrast) if b2 else None,
            **self.network_summary(),
            "has_reference": self.strain is not None,
            "time": self.snapshot.time,
            "axial_strain": self.snapshot.axial_strain,
            "source": self.snapshot.metadata.get("source"),
            "timestep": self.snapshot.metadata.get("timestep"),
            "contacts": self.snapshot.metadata.get("contacts"),
            "notes": list(self.notes),
            **(self.bodies.summary() if self.bodies is not None else {}),
        }
        return out

    def network_summary(self) -> dict[str, Any]:
        """The fabric tensor, loops, porosity, force networks, stress-force-fabric
        and force chains' scalars (``fabric.json``; None where not computed)."""
        num = json_number

        def nums(values: dict[str, Any]) -> dict[str, Any]:
            return {
                k: num(v) if isinstance(v, float) else v for k, v in values.items()
            }

        out: dict[str, Any] = {}
        ft = self.fabric_tensor
        out["satake_fabric_tensor"] = (
            ft.tensor.tolist() if ft is not None and np.all(np.isfinite(ft.tensor)) else None
        )
        out["fabric_fourth_harmonic"] = num(ft.fourth_harmonic) if ft is not None else None
        out["satake_strong_part"] = (
            ft.strong_part.tolist() if ft is not None and ft.strong_part is not None else None
        )
        out["satake_weak_part"] = (
            ft.weak_part.tolist() if ft is not None and ft.weak_part is not None else None
        )
        lp = self.loops
        out.update(
            nums(lp.summary())
            if lp is not None
            else dict.fromkeys(
                ("cyclomatic_number", "n_loops", "mean_loop_size", "loop_size_distribution")
            )
        )
        po = self.porosity
        out["porosity_power_cells"] = num(po.porosity) if po is not None else None
        out["mean_local_porosity"] = (
            num(float(np.nanmean(po.local_porosity)))
            if po is not None and np.isfinite(po.local_porosity).any()
            else None
        )
        nets = self.networks
        if nets is not None:
            out.update(nums(nets.summary()))
        rb = self.stress_force_fabric
        out["rb_a"] = num(rb.anisotropies.a) if rb else None
        out["rb_a_n"] = num(rb.anisotropies.a_n) if rb else None
        out["rb_a_t"] = num(rb.anisotropies.a_t) if rb else None
        out["rb_stress_ratio"] = num(rb.stress_ratio) if rb else None
        out["rb_predicted_stress_ratio"] = num(rb.predicted_stress_ratio) if rb else None
        out["rb_residual"] = num(rb.residual) if rb else None
        out["rb_a_l"] = num(rb.anisotropies.a_l) if rb else None
        out["rb_predicted_with_branch_length"] = num(rb.predicted_with_branch_length) if rb else None
        out["rb_residual_with_branch_length"] = num(rb.residual_with_branch_length) if rb else None
        ch = self.chains
        out.update(
            {f"chains_{k}": v for k, v in nums(ch.summary()).items()}
            if ch is not None
            else {}
        )
        return out

    @property
    def found_band(self) -> ShearBand | None:
        """The detected band when it passed ShearBand's acceptance test, else None.

        :attr:`band` keeps the candidate either way (its ``reason`` says why it
        was not accepted).
        """
        return self.band if self.band is not None and self.band.found else None

    def particle_table(self) -> dict[str, NDArray[Any]]:
        """Per-particle columns for ``particles.csv`` (beyond id,x,y,radius)."""
        n = self.snapshot.n_particles
        nan = np.full(n, np.nan)
        s = self.strain
        cols: dict[str, NDArray[Any]] = {
            "n_contacts": self.stability.n_contacts,
            "stability_index": self.stability.stability_index,
            "displacement": s.displacement_magnitude if s else nan,
            "local_shear_strain": s.shear_strain if s else nan,
            "in_shear_band": (self.band.members & self.band.found).astype(np.int64)
            if self.band
            else nan,
        }
        if s:
            cols["displacement_x"] = s.displacement[:, 0]
            cols["displacement_y"] = s.displacement[:, 1]
            cols["rotation"] = s.rotation
            cols["excess_shear_strain"] = s.excess_shear_strain
            cols["volumetric_strain"] = s.volumetric_strain
            cols["d2min"] = s.d2min
        cols["rattler"] = self.coordination.rattlers.astype(np.int64)
        cols["local_porosity"] = self.porosity.local_porosity if self.porosity else nan
        cols["major_stress_pa"] = self.grain_stress.major if self.grain_stress else nan
        cols["in_strong_network"] = (
            self.networks.in_strong_network.astype(np.int64) if self.networks else nan
        )
        cols["force_chain"] = self.chains.chain if self.chains else nan
        cols["loop_size"] = self.loops.grain_loop_size if self.loops else nan
        return cols


def fabric_summary(snapshot: Snapshot) -> dict[str, float]:
    """The scalar fabric of a snapshot with the library's defaults (boundary
    contacts excluded from Z and the anisotropies, included in lambda), per body
    for a snapshot of clumps; the keys: docs/fabric.md, "Fabric in the biaxial
    records" (the force anisotropies NaN when no contact carries a force)."""
    stability: StabilityIndex
    if has_clumps(snapshot):
        view = body_view(snapshot)
        bodies = BodyCoordination().compute(view)
        stability = BodyStabilityIndex().compute(view)
        coordination = bodies.contact_coordination_number, bodies.mechanical_contact_coordination_number
        snapshot = view.snapshot
    else:
        z = CoordinationNumber().compute(snapshot)
        stability = StabilityIndex().compute(snapshot)
        coordination = z.coordination_number, z.mechanical_coordination_number
    normals = ContactAnisotropy().compute(snapshot)
    out = {
        "coordination_number": coordination[0],
        "mechanical_coordination_number": coordination[1],
        "mean_stability_index": stability.mean,
        "mean_stability_index_all": stability.mean_all,
        "anisotropy": normals.anisotropy,
        "anisotropy_direction_rad": normals.direction,
        "anisotropy_binned": normals.anisotropy_binned,
        "anisotropy_fourier": normals.anisotropy_fourier,
        "force_anisotropy": math.nan,
        "force_anisotropy_binned": math.nan,
    }
    if snapshot.normal_force is not None and float(np.sum(snapshot.normal_force)) > 0.0:
        forces = ContactAnisotropy(weight="normal_force").compute(snapshot)
        out["force_anisotropy"] = forces.anisotropy
        out["force_anisotropy_binned"] = forces.anisotropy_binned
    return {k: float(v) for k, v in out.items()}


def analyze_snapshot(
    snapshot: Snapshot,
    reference: Snapshot | None = None,
    *,
    bins: int = 18,
    min_contacts: int = 2,
    lambda_include_boundary: bool = True,
    fabric_include_boundary: bool = False,
    strain_neighbours: str = "radius",
    strain_cutoff: float | None = None,
    lambda_slots: str = "angular",
    lambda_anchor: str = "min",
    lambda_deviation: str = "sum",
) -> AnalysisResult:
    """Every measure of ``snapshot`` and, with ``reference`` (an earlier state of the
    same particles, matched by id), its local strain and shear band; writes nothing.

    ``bins``: angular bins over 360° (Eq. 7-8, the roses); ``min_contacts``: Z_m's
    rattler threshold; ``lambda_include_boundary``, ``fabric_include_boundary``:
    whether wall and membrane contacts count for lambda (yes) and for Z and the
    anisotropies (no); ``strain_*``: :class:`LocalStrain`'s neighbourhood;
    ``lambda_*``: :class:`StabilityIndex`'s reading of Eqs. 9-11, checked before
    any work. A snapshot of clumps (bodies of several pebbles) gets the measures
    per body too (:attr:`AnalysisResult.bodies`). What is measured, and when:
    docs/analysis.md, "Everything at once".
    """
    stability = StabilityIndex(  # checks the reading before any work
        include_boundary=lambda_include_boundary,
        slots=lambda_slots,
        anchor=lambda_anchor,
        deviation=lambda_deviation,
    )
    notes: list[str] = []
    coordination = CoordinationNumber(
        min_contacts=min_contacts, include_boundary=fabric_include_boundary
    ).compute(snapshot)
    anisotropy = ContactAnisotropy(bins=bins, include_boundary=fabric_include_boundary).compute(
        snapshot
    )
    force_anisotropy = None
    if snapshot.normal_force is not None:
        force_anisotropy = ContactAnisotropy(
            bins=bins, weight="normal_force", include_boundary=fabric_include_boundary
        ).compute(snapshot)
    else:
        notes.append("no contact forces in the input: a_n not computed")
    stability.compute(snapshot)
    fabric_tensor = FabricTensor(include_boundary=fabric_include_boundary).compute(snapshot)
    loops = ContactLoops().compute(snapshot)
    porosity: LocalPorosity | None = None
    try:
        porosity = LocalPorosity().compute(snapshot)
    except (ValueError, RuntimeError) as error:  # fewer than 3 disks, all in a line (Qhull)
        notes.append(f"no power cells, local porosity not computed: {str(error).splitlines()[0]}")
    networks, stress_force_fabric, grains, chains = _force_measures(
        snapshot, fabric_include_boundary, notes
    )
    strain, band = _strain_and_band(
        snapshot, reference, stability, LocalStrain(strain_neighbours, strain_cutoff), notes
    )
    bodies = None
    if has_clumps(snapshot):  # the same measures per body (a snapshot of disks has none)
        bodies = analyze_bodies(
            snapshot, reference, like=(coordination, anisotropy, stability),
            strain=LocalStrain(strain_neighbours, strain_cutoff), notes=notes,
        )
    return AnalysisResult(
        snapshot, coordination, anisotropy, force_anisotropy, stability, strain, band, notes,
        fabric_tensor=fabric_tensor, loops=loops, porosity=porosity, networks=networks,
        stress_force_fabric=stress_force_fabric, grain_stress=grains, chains=chains, bodies=bodies,
    )


def _force_measures(
    snapshot: Snapshot, include_boundary: bool, notes: list[str]
) -> tuple[
    ForceNetworks | None, StressForceFabric | None, GrainStress | None, ForceChains | None
]:
    """:func:`analyze_snapshot`'s measures of the contact forces (None without forces,
    and a note saying so)."""
    if snapshot.normal_force is None or float(np.sum(snapshot.normal_force)) <= 0.0:
        notes.append(
            "no contact forces: force networks, stress-force-fabric and force chains not computed"
        )
        return None, None, None, None
    networks = ForceNetworks(include_boundary=include_boundary).compute(snapshot)
    stress_force_fabric = StressForceFabric(include_boundary=include_boundary).compute(snapshot)
    grains = GrainStress().compute(snapshot)
    return networks, stress_force_fabric, grains, ForceChains().compute(snapshot, grains)


def _strain_and_band(
    snapshot: Snapshot,
    reference: Snapshot | None,
    stability: StabilityIndex,
    strain: LocalStrain,
    notes: list[str],
) -> tuple[LocalStrain | None, ShearBand | None]:
    """:func:`analyze_snapshot`'s local strain since ``reference`` and the shear band in
    its excess strain (None where they cannot be measured, and a note saying why)."""
    if reference is None:
        notes.append(
            "no reference snapshot: displacement, local_shear_strain and in_shear_band are empty, "
            "and no shear band was detected"
        )
        return None, None
    strain.compute(reference, snapshot)
    missing = int((reference.index_of(np.asarray(snapshot.ids)) < 0).sum())
    if missing:
        notes.append(f"{missing} particles have no match (by id) in the reference snapshot")
    if int(np.isfinite(strain.excess_shear_strain[snapshot.is_sample]).sum()) < 10:
        notes.append("fewer than 10 particles with a local strain: no shear band detected")
        return strain, None
    band = ShearBand().compute(
        snapshot,
        strain.excess_shear_strain,
        stability_index=stability.stability_index,
        n_contacts=stability.n_contacts,
    )
    return strain, band
