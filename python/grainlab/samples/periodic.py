"""A dense packing of disks in a periodic cell, compressed frictionless to a mean
stress (:func:`periodic_packing`; docs/samples.md, "A periodic packing")."""

from __future__ import annotations

import numpy as np

from grainlab.analysis.stress import contact_stress
from grainlab.paper import DENSITY_KG_PER_M3, NORMAL_STIFFNESS_N_PER_M
from grainlab.samples.placement import random_placement
from grainlab.simulation import ContactModel, Simulation

__all__ = ["cell_mean_stress", "periodic_packing"]


def cell_mean_stress(sim: Simulation) -> float:
    """Mean stress ``(sigma_xx + sigma_yy) / 2`` (Pa, compression positive) of the
    contacts of a simulation in a periodic cell, over the cell's area."""
    cell = sim.cell
    if cell is None:
        raise ValueError("sim: no periodic cell")
    stress = contact_stress(sim.snapshot(), area=cell.area)
    return float(0.5 * (stress[0, 0] + stress[1, 1]))


def periodic_packing(
    n: int,
    *,
    seed: int = 0,
    mean_stress_pa: float = 1.0e5,
    radius_range_m: tuple[float, float] = (0.25e-3, 0.5e-3),
    density: float = DENSITY_KG_PER_M3,
    normal_stiffness: float = NORMAL_STIFFNESS_N_PER_M,
    threads: int = 1,
    max_steps: int = 2_000_000,
) -> Simulation:
    """``n`` disks (radii uniform in ``radius_range_m``) compressed frictionless in a
    square periodic cell to ``mean_stress_pa`` (docs/samples.md, "A periodic packing").
    Raises ValueError before any work for bad input, RuntimeError when ``max_steps``
    do not reach the state.
    """
    if int(n) != n or n < 10:
        raise ValueError(f"n: need at least 10 disks, got {n!r}")
    r_min, r_max = (float(v) for v in radius_range_m)
    if not 0.0 < r_min <= r_max:
        raise ValueError(f"radius_range_m: need 0 < r_min <= r_max, got {radius_range_m!r}")
    if not mean_stress_pa > 0.0:
        raise ValueError(f"mean_stress_pa: must be > 0, got {mean_stress_pa!r}")
    rng = np.random.default_rng(seed)
    diameters = 2.0 * rng.uniform(r_min, r_max, int(n))
    side = float(np.sqrt(np.pi * np.sum((0.5 * diameters) ** 2) / 0.45))  # solid fraction 0.45
    positions, radii = random_placement((0.0, 0.0, side, side), diameters, rng, scale=1.0)
    model = ContactModel(normal_stiffness=normal_stiffness, shear_stiffness=normal_stiffness, friction=0.0)
    sim = Simulation(positions, radii, density, contact_model=model, local_damping=0.7, threads=threads)
    sim.set_periodic_cell((0.0, 0.0), (side, side))
    block = 100
    largest_rate = 2e-4 / (block * sim.time_step)
    while sim.step_count < max_steps:
        pressure = cell_mean_stress(sim)
        if abs(pressure / mean_stress_pa - 1.0) < 0.01 and sim.unbalanced_force_ratio < 1e-4:
            sim.set_velocity_gradient(np.zeros((2, 2)))
            sim.velocities = np.zeros((sim.n_particles, 2))
            sim.angular_velocities = np.zeros(sim.n_particles)
            return sim
        rate = largest_rate * float(np.clip(1.0 - pressure / mean_stress_pa, -1.0, 1.0))
        sim.set_velocity_gradient([[-rate, 0.0], [0.0, -rate]])
        sim.run(block)
    raise RuntimeError(
        f"periodic_packing: {max_steps} steps did not reach {mean_stress_pa:g} Pa at equilibrium "
        f"(mean stress {cell_mean_stress(sim):g} Pa, unbalanced force ratio {sim.unbalanced_force_ratio:.2g})"
    )
