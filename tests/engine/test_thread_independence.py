"""Results are bitwise independent of the thread count (docs/engine.md): the
work partition depends on the system only, reductions are merged in a fixed
order and the pairs across stripes are applied in pair order."""

from __future__ import annotations

import dataclasses

import numpy as np

from grainlab import ContactModel, Simulation

KN = 8.45e7


def sheared_box(threads: int, n_side: int = 60) -> Simulation:
    """3,600 dense frictional disks (the parallel path) in a box whose top wall shears
    and compresses them; the left side is a bonded chain under a follower pressure."""
    g = np.random.default_rng(7)
    s = 1.0e-3
    a, b = np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="ij")
    pos = np.column_stack([(a.ravel() + 0.5) * s, (b.ravel() + 0.5) * s]) + g.uniform(-0.03, 0.03, (n_side**2, 2)) * s
    rad = g.uniform(0.48, 0.56, n_side**2) * s
    sim = Simulation(pos, rad, density=2.0e8, contact_model=ContactModel(KN, KN, 0.5), threads=threads, local_damping=0.3,
                     time_step_safety=0.5)
    side = n_side * s
    bottom = sim.add_segment_wall((0, 0), (side, 0))
    sim.add_segment_wall((side, 0), (side, side))
    top = sim.add_segment_wall((side, side), (0, side))
    top.velocity = (0.02, -0.002)
    left = np.arange(n_side)  # the first column, bottom to top: the sample on its right
    for k in left[:-1]:
        sim.add_bond(int(k), int(k + 1), 0.1 * KN, 0.1 * KN)
    sim.add_pressure_chain(left, 2.0e5, start_wall=bottom, end_wall=top)
    sim.velocities = g.normal(0.0, 0.01, (n_side**2, 2))
    return sim


def test_one_to_four_threads_give_the_same_bits():
    states = []
    for threads in (1, 2, 3, 4):
        sim = sheared_box(threads)
        sim.run(300)
        c, w = sim.contacts(), sim.wall_contacts()
        states.append(
            {
                "positions": sim.positions,
                "velocities": sim.velocities,
                "angular_velocities": sim.angular_velocities,
                "forces": sim.forces,
                "contact_pairs": np.column_stack([c.i, c.j]),
                "normal_force": c.normal_force,
                "shear_force": c.shear_force,
                "sliding": c.sliding,
                "wall_normal_force": w.normal_force,
                "wall_shear_force": w.shear_force,
                "top_wall_force": sim.wall(2).force,
                "energy": np.array(dataclasses.astuple(sim.energy)),
            }
        )
        assert sim.threads == threads
    assert len(states[0]["normal_force"]) > 5000 and len(states[0]["wall_normal_force"]) > 50
    for threads, state in zip((2, 3, 4), states[1:], strict=True):
        for key, value in state.items():
            np.testing.assert_array_equal(value, states[0][key], err_msg=f"{key}, {threads} threads")


def test_switching_threads_mid_run_changes_nothing():
    straight = sheared_box(1)
    straight.run(200)
    switched = sheared_box(2)
    switched.run(100)
    switched.threads = 3
    switched.run(100)
    np.testing.assert_array_equal(switched.positions, straight.positions)
    np.testing.assert_array_equal(switched.contacts().shear_force, straight.contacts().shear_force)
