"""servo_box: a box of disks is brought to the target stress, or reports that it was not."""

from __future__ import annotations

import numpy as np

from grainlab.demo import random_disks
from grainlab.protocols.consolidate import BOX_WALLS, box_state, servo_box
from grainlab.simulation import WALL_GROUP, ContactModel, Simulation


def _box(n_side=10, spacing=3.2e-3):
    positions, radii = random_disks(n_side, spacing, 0.5e-3, 3.0e-3, 4)
    sim = Simulation(positions, radii, 2.0e8, contact_model=ContactModel(8.45e7, 8.45e7, 0.5), local_damping=0.8,
                     threads=1)
    sim.set_contact_model(0, WALL_GROUP, ContactModel(friction=0.0))
    box = n_side * spacing
    corners = [(0.0, 0.0), (box, 0.0), (box, box), (0.0, box)]
    return sim, {name: sim.add_segment_wall(corners[k], corners[(k + 1) % 4]) for k, name in enumerate(BOX_WALLS)}


def test_the_box_reaches_the_target_stress_in_equilibrium():
    sim, walls = _box()
    seen = []
    state, steps, converged = servo_box(sim, walls, 1e5, tolerance=0.01, unbalanced_force_limit=1e-3,
                                        max_steps=400_000, max_speed_m_per_s=0.05,
                                        after_chunk=lambda s, k: seen.append(k))
    assert converged and seen[-1] == steps and len(seen) == steps // 2000
    assert abs(state.stress_xx_pa / 1e5 - 1) < 0.01 and abs(state.stress_yy_pa / 1e5 - 1) < 0.01
    assert sim.unbalanced_force_ratio < 1e-3
    # the state is the walls' own: force over the loaded length, from the box's size
    again = box_state(walls)
    assert again == state
    assert np.isclose(state.width_m, walls["right"].points[0, 0] - walls["left"].points[0, 0])


def test_running_out_of_steps_is_reported():
    sim, walls = _box()
    state, steps, converged = servo_box(sim, walls, 1e5, tolerance=0.01, unbalanced_force_limit=1e-3,
                                        max_steps=2000, max_speed_m_per_s=0.05)
    assert not converged and steps == 2000
    # one of the criteria still fails after one chunk
    assert (abs(state.stress_xx_pa / 1e5 - 1) >= 0.01 or abs(state.stress_yy_pa / 1e5 - 1) >= 0.01
            or sim.unbalanced_force_ratio >= 1e-3)
