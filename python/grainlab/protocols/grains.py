"""A test's grains counted as bodies: the first ``n`` particles of a simulation
are its grains' particles (disks, or the pebbles of clumps; membrane disks
follow), and a clump is one grain (docs/bodies.md). For disks every function
gives the disk formula's bits."""

from __future__ import annotations

import numpy as np

from grainlab.simulation import Simulation

__all__ = ["clump_summary", "grain_coordination", "grain_count", "grain_labels", "grain_porosity"]


def grain_labels(sim: Simulation, n: int) -> np.ndarray | None:
    """Each of the first ``n`` particles' grain (body), or None when there is no clump."""
    return sim.body_of_particles[:n] if len(sim.clumps) else None


def grain_count(sim: Simulation, n: int) -> int:
    """The grains among the first ``n`` particles: ``n`` disks, or as many bodies."""
    labels = grain_labels(sim, n)
    return n if labels is None else int(np.unique(labels).size)


def grain_coordination(sim: Simulation) -> float:
    """The engine's coordination number ``2 Nc / N`` per grain: per particle for
    disks, per body with clumps (CEGEO's Z_c: two grains touching at two pebbles
    count two contacts)."""
    if not len(sim.clumps):
        return sim.coordination_number
    return sim.coordination_number * sim.n_particles / grain_count(sim, sim.n_particles)


def grain_porosity(sim: Simulation, n: int, area: float) -> float:
    """``1 - sum of the grains' areas / area``: ``pi r^2`` per disk, and per clump the
    exact area of its pebbles' union (its mass over its density, whatever the
    periodic images of its pebbles)."""
    radii = sim.radii[:n]
    labels = grain_labels(sim, n)
    if labels is None:
        return 1.0 - float(np.pi * np.sum(radii**2)) / area
    clumps = sim.clumps
    disks = labels >= len(clumps)
    ids, first = np.unique(labels[~disks], return_index=True)
    pebbles = np.flatnonzero(~disks)[first]
    covered = float(np.pi * np.sum(radii[disks] ** 2)) + float(np.sum(clumps.mass_kg[ids] / sim.densities[pebbles]))
    return 1.0 - covered / area


def clump_summary(sample: dict[str, object]) -> dict[str, object]:
    """A summary's grain keys for a sample of clumps (its generation's ``n_grains``,
    ``shape`` and ``shape_parameter``; ``n_particles`` counts their pebbles); none
    for disks, whose summaries keep their keys."""
    return {key: sample[key] for key in ("n_grains", "shape", "shape_parameter") if key in sample}
