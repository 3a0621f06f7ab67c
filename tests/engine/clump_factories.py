"""A pile of trimers for the body tests: six clumps (and optionally one disk)
dropped into a box of three line walls under gravity, with local damping."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from grainlab import ContactModel, Simulation

#: A trimer's pebble centres (m), radii 1 mm each.
TRIMER = np.array([[0.0, 0.7e-3], [-0.6e-3, -0.35e-3], [0.6e-3, -0.35e-3]])


def trimer_pile(angles: ArrayLike, *, with_disk: bool = False) -> Simulation:
    """Six trimers at ``angles`` in two rows over a floor between two side walls
    (friction 0.5, 2,650 kg/m^3, local damping 0.7), after one disk when ``with_disk``."""
    sim = Simulation(
        np.empty((0, 2)),
        np.empty(0),
        2650.0,
        contact_model=ContactModel(8.45e7, 8.45e7, 0.5),
        time_step=1e-4,
        local_damping=0.7,
        gravity=(0.0, -9.81),
    )
    sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    sim.add_line_wall((0.0, 0.0), (1.0, 0.0))
    sim.add_line_wall((12e-3, 0.0), (-1.0, 0.0))
    if with_disk:
        sim.add_particles([[10e-3, 9e-3]], [0.8e-3], 2650.0)
    centres = [[2.2e-3 + 3.5e-3 * (k % 3), 2.2e-3 + 3.5e-3 * (k // 3)] for k in range(6)]
    sim.add_clumps(TRIMER, np.full(3, 1e-3), positions=centres, angles=angles, density=2650.0)
    sim.time_step = sim.critical_time_step(0.5)
    return sim
