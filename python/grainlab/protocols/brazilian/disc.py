"""The Brazilian test's disc, carved from the consolidated and cemented sample: the
grains whose centre lies within the disc's circle (:func:`disc_circle`,
:func:`in_disc`) and that the cement holds together (:func:`held_by_cement`) kept
with the cement bonds between them, in a new simulation (:func:`carved_simulation`),
since the engine removes no particle.

The new simulation has the kept particles in their state (positions, radii,
densities, rotations, velocities, groups, fixity, external loads; clumps with
their frames, masses and velocities), the engine's parameters and contact
models, and the bonds between kept grains with their strengths, remade
stress-free at the same distances. Carved where the bonds were just made, the
bonds were stress-free too, so they are the same bonds. What it does not have:
the contacts' shear and rolling springs (a frictionless consolidation, the
default, leaves none), the walls, the step count, the time and the energy
ledger, which count from the carve."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from grainlab.protocols.config import Config
from grainlab.protocols.specimen import SpecimenError, SpecimenRun, add_cement
from grainlab.simulation import MAX_GROUPS, Simulation

__all__ = ["BONDS_TO_HOLD", "carved_simulation", "disc_circle", "held_by_cement", "in_disc"]

#: The bonds a grain of the disc has at least, to other grains of the disc.
BONDS_TO_HOLD = 2


def disc_circle(sim: Simulation, run: SpecimenRun, fraction: float) -> tuple[tuple[float, float], float]:
    """The centre of the consolidated box (its four walls) and ``fraction`` of its smaller side."""
    walls = {name: sim.wall(wall_id).points[0] for name, wall_id in run.walls.items()}
    left, right = float(walls["left"][0]), float(walls["right"][0])
    bottom, top = float(walls["bottom"][1]), float(walls["top"][1])
    return (0.5 * (left + right), 0.5 * (bottom + top)), fraction * min(right - left, top - bottom)


def in_disc(centroids: NDArray[np.float64], centre: tuple[float, float], diameter: float) -> NDArray[np.bool_]:
    """Whether each grain's centre (its clump's centroid for a pebble) lies within ``diameter / 2`` of ``centre``."""
    offset = np.asarray(centroids, dtype=np.float64) - np.asarray(centre)
    return np.asarray(np.hypot(offset[:, 0], offset[:, 1]) <= 0.5 * diameter)


def held_by_cement(inside: NDArray[np.bool_], i: NDArray[np.int64], j: NDArray[np.int64],
                   body: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Of the particles ``inside`` the circle, those the cement holds in the disc: the
    grains with at least :data:`BONDS_TO_HOLD` bonds ``(i[k], j[k])`` to other such grains
    (a grain on the rim hanging by one bond breaks off under the first load and rolls
    under the platen), of the largest group they join (the pebbles of a clump, by
    ``body``, stand or fall together)."""
    n = len(inside)
    kept = inside.copy()
    grain = np.unique(body, return_inverse=True)[1]  # each particle's grain, 0..grains-1
    while True:  # peel off the grains held by fewer bonds, until none is left to peel
        both = kept[i] & kept[j] & (grain[i] != grain[j])
        bonds = np.bincount(grain[i[both]], minlength=n) + np.bincount(grain[j[both]], minlength=n)
        loose = kept & (bonds[grain] < BONDS_TO_HOLD)
        if not np.any(loose):
            break
        kept &= ~loose
    order = np.argsort(body, kind="stable")
    same = body[order][1:] == body[order][:-1]  # consecutive pebbles of one clump
    rows = np.concatenate([i[both], order[1:][same]])
    cols = np.concatenate([j[both], order[:-1][same]])
    count, label = connected_components(coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)), directed=False)
    sizes = np.bincount(label[kept], minlength=count)
    return np.asarray(kept & (label == int(np.argmax(sizes))), dtype=np.bool_)


def carved_simulation(sim: Simulation, keep: NDArray[np.bool_], config: Config) -> Simulation:
    """A new simulation of the particles ``keep`` marks, in their state, with the cement
    bonds between them (the module's rules; bonds of the ``cement.*`` keys)."""
    if not np.any(keep):
        raise SpecimenError("the disc holds no grain that the cement holds to two others: cement the sample more "
                            "(cement.gap) or carve a larger disc (brazilian.diameter_fraction)")
    carved = Simulation(sim.positions[keep], sim.radii[keep], sim.densities[keep], time_step=sim.time_step,
                        threads=sim.threads, local_damping=sim.local_damping, gravity=sim.gravity)
    for a in range(MAX_GROUPS):
        for b in range(a, MAX_GROUPS):
            carved.set_contact_model(a, b, sim.contact_model(a, b))
    carved.max_overlap_ratio, carved.skin = sim.max_overlap_ratio, sim.skin
    carved.groups, carved.fixity = sim.groups[keep], sim.fixity[keep]
    carved.rotations, carved.angular_velocities = sim.rotations[keep], sim.angular_velocities[keep]
    carved.velocities = sim.velocities[keep]
    carved.external_forces, carved.external_torques = sim.external_forces[keep], sim.external_torques[keep]
    index = np.cumsum(keep) - 1  # a kept particle's index in the carved simulation
    _copy_clumps(sim, carved, keep, index)
    _copy_bonds(sim, carved, keep, index, config)
    return carved


def _copy_clumps(sim: Simulation, carved: Simulation, keep: NDArray[np.bool_], index: NDArray[np.int64]) -> None:
    """The clumps of the kept pebbles (whole clumps), in their order, frames, masses and velocities."""
    clumps = sim.clumps
    if not len(clumps):
        return
    body = sim.body_of_particles
    kept = np.unique(body[keep & (body < len(clumps))])
    pebbles = [index[np.flatnonzero(body == b)].tolist() for b in kept]
    masses = [(float(clumps.mass_kg[b]), float(clumps.moment_of_inertia_kg_m2[b]), clumps.centroid_m[b]) for b in kept]
    carved.add_bodies(pebbles, angles=clumps.angle_rad[kept], masses=masses)
    carved.set_clump_velocities(clumps.velocity_m_per_s[kept], clumps.angular_velocity_rad_per_s[kept])


def _copy_bonds(sim: Simulation, carved: Simulation, keep: NDArray[np.bool_], index: NDArray[np.int64],
                config: Config) -> None:
    """The cement bonds whose two grains are kept, with their strengths, remade stress-free."""
    bonds = sim.cement_bonds()
    i, j = np.asarray(bonds.i, dtype=np.int64), np.asarray(bonds.j, dtype=np.int64)
    both = keep[i] & keep[j]
    loaded = np.flatnonzero(both & ((bonds.normal_force != 0) | (bonds.shear_force != 0) | (bonds.moment != 0)))
    if len(loaded):
        k = int(loaded[0])
        raise SpecimenError(f"the disc is carved where its bonds are stress-free, but the bond of grains {i[k]} and "
                            f"{j[k]} carries a force of {bonds.normal_force[k]:.3g} N: it cannot be remade as it is")
    if np.any(both):
        add_cement(carved, config, index[i[both]], index[j[both]], bonds.tensile_strength[both], bonds.cohesion[both])
