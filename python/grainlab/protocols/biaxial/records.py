"""The biaxial run's measurements: one record of the shearing phase (stresses,
strains, energies, fabric) and the state as a snapshot with its walls."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grainlab.columns import BIAXIAL
from grainlab.io.walls import WallGeometry
from grainlab.protocols.biaxial.config import BiaxialConfig
from grainlab.protocols.biaxial.state import BiaxialRun, Boundary
from grainlab.protocols.boundary import GrainBoundary, Membrane, WallBoundary, sample_area
from grainlab.protocols.cracks import bonds_broken
from grainlab.protocols.specimen import grain_columns
from grainlab.simulation import Simulation
from grainlab.snapshot import ParticleKind, Snapshot

__all__ = ["TIMESERIES_UNITS", "PlatenState", "deviator_stress", "enclosed_area", "measure", "platen_state",
           "take_snapshot", "wall_geometry"]

#: Column -> unit of the shearing's records (:data:`grainlab.columns.BIAXIAL`).
TIMESERIES_UNITS = BIAXIAL.units()


@dataclass(frozen=True)
class PlatenState:
    """The platens' state: sample height and area, and the mean axial stress
    of the two platens over the sample's mean width (area over height)."""

    height_m: float
    area_m2: float
    width_m: float
    axial_stress_pa: float


def platen_state(sim: Simulation, boundary: Boundary) -> PlatenState:
    """The platens' state now."""
    bottom, top = sim.wall(boundary.bottom_wall), sim.wall(boundary.top_wall)
    height = float(top.points[0, 1] - bottom.points[0, 1])
    area = enclosed_area(sim, boundary)
    width = area / height
    axial_force = 0.5 * (float(top.force[1]) - float(bottom.force[1]))
    return PlatenState(height, area, width, axial_force / width)


def deviator_stress(sim: Simulation, run: BiaxialRun, config: BiaxialConfig) -> float:
    """q = sigma_1 - sigma_3' from the platens' and the lateral boundary's forces alone
    (cheap enough for every 100 steps): sigma_3' is the confining pressure held, or the
    side walls' stress at constant volume."""
    boundary = run.lateral_boundary()
    sigma_1 = platen_state(sim, boundary).axial_stress_pa
    if isinstance(boundary, WallBoundary) and boundary.constant_volume:
        return sigma_1 - boundary.lateral_stress(sim)
    return sigma_1 - float(config.consolidation.pressure)


def measure(sim: Simulation, run: BiaxialRun, config: BiaxialConfig) -> dict[str, float]:
    """One record of the shearing phase."""
    boundary = run.lateral_boundary()
    shear = run.shear_plan()
    platens = platen_state(sim, boundary)
    height, area, sigma_1 = platens.height_m, platens.area_m2, platens.axial_stress_pa
    sigma_3 = config.consolidation.pressure  # the confining pressure held (a cell pressure)

    c = sim.contacts()
    n = run.n_grains
    f_on_j = -c.force_on_i
    grain_i, grain_j = c.i < n, c.j < n
    if isinstance(boundary, Membrane):
        # confining stress the grains feel: force of the grains on the membrane, per side, over the height
        left = np.zeros(sim.n_particles, dtype=bool)
        left[boundary.left] = True
        right = np.zeros(sim.n_particles, dtype=bool)
        right[boundary.right] = True
        on_membrane = np.zeros((len(c), 2))
        on_membrane[grain_i & ~grain_j] = f_on_j[grain_i & ~grain_j]
        on_membrane[~grain_i & grain_j] = -f_on_j[~grain_i & grain_j]
        membrane_particle = np.where(grain_i, c.j, c.i)
        felt_left = -on_membrane[left[membrane_particle] & (grain_i ^ grain_j), 0].sum() / height
        felt_right = on_membrane[right[membrane_particle] & (grain_i ^ grain_j), 0].sum() / height
    elif isinstance(boundary, WallBoundary):
        felt_left = felt_right = boundary.lateral_stress(sim)
    else:
        # the follower loads act on the grains themselves: the pressure over the full height
        felt_left = felt_right = boundary.pressure
    # at constant volume the side walls' stress is the effective one, sigma_3'
    sigma_3_ratio = felt_left if isinstance(boundary, WallBoundary) and boundary.constant_volume else sigma_3
    return {
        "step": float(sim.step_count),
        "time_s": sim.time,
        "axial_strain": (shear.height0 - height) / shear.height0,
        "axial_stress_pa": sigma_1,
        "confining_pressure_pa": sigma_3,
        "confining_stress_felt_pa": 0.5 * (felt_left + felt_right),
        "stress_ratio": sigma_1 / sigma_3_ratio,
        "stress_ratio_mobilised": (sigma_1 - sigma_3_ratio) / (sigma_1 + sigma_3_ratio),
        "volumetric_strain": (shear.area0 - area) / shear.area0,
        "area_m2": area,
        "height_m": height,
        **grain_columns(sim, n, area, c, take_snapshot(sim, run, 0.0)),
        **bonds_broken(sim, run.consolidation, config),
    }


def enclosed_area(sim: Simulation, boundary: Boundary) -> float:
    """The area inside the lateral boundary and the platens, m^2."""
    return sample_area(sim, boundary) if isinstance(boundary, Membrane) else boundary.area(sim)


def take_snapshot(sim: Simulation, run: BiaxialRun, strain: float) -> Snapshot:
    """The state as a snapshot: grains, membrane disks labelled by chain (left 0, right 1)."""
    kind = np.full(sim.n_particles, int(ParticleKind.SOIL), dtype=np.int8)
    kind[run.n_grains :] = int(ParticleKind.MEMBRANE)
    body = np.full(sim.n_particles, -1, dtype=np.int64)
    if isinstance(run.boundary, GrainBoundary):
        kind[run.boundary.left + run.boundary.right] = int(ParticleKind.BOUNDARY)
    elif isinstance(run.boundary, Membrane):
        body[run.boundary.left] = 0
        body[run.boundary.right] = 1
    snap = sim.snapshot(kind=kind, axial_strain=strain, step=sim.step_count)
    return snap.with_boundary_bodies(body)


def wall_geometry(sim: Simulation, run: BiaxialRun) -> WallGeometry:
    """The walls now (the platens active, the consolidation box's sides not), named
    as the run names them, for the snapshot."""
    return WallGeometry.from_simulation(sim, names={wall_id: name for name, wall_id in run.walls.items()})
