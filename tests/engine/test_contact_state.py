"""Contacts are one consistent state: the forces at the current positions exactly
as the next force evaluation computes them (docs/contact-law.md), and setting
state between runs counts the last step's displacement once."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab import ContactModel, Simulation

MU = 0.3
KN = 8.45e7


def sheared_packing(n_side: int = 14, seed: int = 1, **model) -> Simulation:
    """A dense frictional packing in a periodic cell under pure shear."""
    g = np.random.default_rng(seed)
    s = 1.0e-3
    a, b = np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="ij")
    pos = np.column_stack([(a.ravel() + 0.5) * s, (b.ravel() + 0.5) * s]) + g.uniform(-0.03, 0.03, (n_side**2, 2)) * s
    rad = g.uniform(0.48, 0.56, n_side**2) * s
    sim = Simulation(pos, rad, density=2.0e8, contact_model=ContactModel(KN, KN, MU, **model), threads=1, local_damping=0.2)
    sim.set_periodic_cell((0.0, 0.0), (n_side * s, n_side * s))
    sim.set_velocity_gradient([[-2.0, 0.0], [0.0, 2.0]])
    sim.velocities = g.normal(0.0, 0.01, (n_side**2, 2))
    return sim


def walled_packing(n_side: int = 12, seed: int = 2) -> Simulation:
    """Dense frictional disks in a box of four walls, the first column bonded, the top wall shearing."""
    g = np.random.default_rng(seed)
    s = 1.0e-3
    a, b = np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="ij")
    pos = np.column_stack([(a.ravel() + 0.5) * s, (b.ravel() + 0.5) * s]) + g.uniform(-0.03, 0.03, (n_side**2, 2)) * s
    rad = g.uniform(0.48, 0.56, n_side**2) * s
    sim = Simulation(pos, rad, density=2.0e8, contact_model=ContactModel(KN, KN, MU), threads=1, local_damping=0.2)
    side = n_side * s
    corners = [(0, 0), (side, 0), (side, side), (0, side)]
    walls = [sim.add_segment_wall(corners[k], corners[(k + 1) % 4]) for k in range(4)]
    walls[2].velocity = (0.02, -0.002)
    for k in range(n_side - 1):
        sim.add_bond(k, k + 1, 0.1 * KN, 0.1 * KN)
    sim.velocities = g.normal(0.0, 0.01, (n_side**2, 2))
    sim.angular_velocities = g.normal(0.0, 10.0, n_side**2)
    return sim


def resultants(sim: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """Force and torque on every particle from the reported contacts, bonds and wall contacts."""
    c, w = sim.contacts(), sim.wall_contacts()
    n = sim.n_particles
    f = c.force_on_i  # on i; its opposite on j
    force, torque = np.zeros((n, 2)), np.zeros(n)
    for k in (0, 1):
        force[:, k] += np.bincount(c.i, f[:, k], minlength=n) - np.bincount(c.j, f[:, k], minlength=n)
    r = sim.radii
    # shear on i along t at r_i n from i, its opposite on j at -r_j n from j: both turn the same way
    torque += np.bincount(c.i, r[c.i] * c.shear_force, minlength=n) + np.bincount(c.j, r[c.j] * c.shear_force, minlength=n)
    fw = w.force_on_particle
    for k in (0, 1):
        force[:, k] += np.bincount(w.particle, fw[:, k], minlength=n)
    torque += np.bincount(w.particle, r[w.particle] * w.shear_force, minlength=n)
    return force, torque


def check_coulomb(c) -> None:
    free = ~c.bonded if hasattr(c, "bonded") else np.ones(len(c), bool)
    fs, cap, sliding = np.abs(c.shear_force[free]), MU * c.normal_force[free], c.sliding[free]
    assert np.all(fs <= cap * (1 + 1e-12))
    # sliding exactly where the shear force is at the cap
    np.testing.assert_array_equal(fs[sliding], cap[sliding])
    assert np.all(fs[~sliding] < cap[~sliding])


def test_reported_forces_obey_coulomb_at_every_query():
    sim = sheared_packing()
    slid = 0
    for _ in range(40):
        sim.run(7)
        c = sim.contacts()
        check_coulomb(c)
        assert len(c) > 150
        slid += int(c.sliding.sum())
    assert slid > 100  # the cap is reached, not only approached


@pytest.mark.parametrize("builder", [sheared_packing, walled_packing])
def test_reported_forces_are_those_the_next_step_applies(builder):
    # with no external loads the resultant of the next step (before local damping)
    # is the sum of the reported contact, bond and wall forces
    sim = builder()
    for steps in (0, 1, 30):
        sim.run(steps)
        force, torque = resultants(sim)
        sim.run(1)
        scale = np.abs(sim.forces).max()
        np.testing.assert_allclose(sim.forces, force, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(sim.torques, torque, rtol=0, atol=1e-12 * scale * 1e-3)
    assert len(sim.wall_contacts()) == 0 or builder is walled_packing


def test_a_new_contact_reports_the_increment_it_will_get():
    sim = sheared_packing()
    c = sim.contacts()
    for _ in range(500):
        before = set(zip(c.i, c.j, strict=True))
        sim.run(1)
        c = sim.contacts()
        new = np.array([(i, j) not in before for i, j in zip(c.i, c.j, strict=True)])
        if new.sum() >= 3:
            break
    assert new.sum() >= 3
    # its spring was zero: the shear on i is ks v_t dt at the current state (along the motion
    # of j past i), capped
    x, v, w, r = sim.positions, sim.velocities, sim.angular_velocities, sim.radii
    i, j = c.i[new].astype(int), c.j[new].astype(int)
    side = sim.cell.a[0]
    d = x[j] - x[i]
    d -= side * np.round(d / side)
    grad = np.array(sim.cell.velocity_gradient)
    dv = v[j] - v[i] + d @ grad.T
    t = np.column_stack([-c.normal[new, 1], c.normal[new, 0]])
    vt = (dv * t).sum(1) - (w[i] * r[i] + w[j] * r[j])
    increment = KN * vt * sim.time_step
    expected = np.clip(increment, -MU * c.normal_force[new], MU * c.normal_force[new])
    np.testing.assert_allclose(c.shear_force[new], expected, rtol=1e-9, atol=1e-9 * np.abs(increment).max())
    assert np.any(expected != 0)


def test_shear_dashpot_is_not_reported_and_the_cap_still_holds():
    sim = sheared_packing(normal_damping_ratio=0.3, shear_damping_ratio=0.3)
    for _ in range(10):
        sim.run(10)
        check_coulomb(sim.contacts())


@pytest.mark.parametrize(
    "change",
    [
        lambda sim: setattr(sim, "velocities", 0.5 * sim.velocities),
        lambda sim: setattr(sim, "angular_velocities", sim.angular_velocities + 3.0),
        lambda sim: setattr(sim, "positions", sim.positions),
        lambda sim: setattr(sim, "time_step", 0.5 * sim.time_step),
        lambda sim: setattr(sim, "local_damping", 0.1),
        lambda sim: sim.set_velocity_gradient([[0.0, 1.0], [0.0, 0.0]]),
        lambda sim: sim.set_contact_model(0, 0, ContactModel(KN, KN, MU)),
    ],
    ids=["velocities", "spins", "positions", "time_step", "local_damping", "cell flow", "contact model"],
)
def test_a_change_between_runs_counts_the_last_displacement_once(change):
    # the last step's displacement is added to the springs before the change,
    # exactly as the next step would have added it; the change itself adds nothing
    sim = sheared_packing()
    sim.run(25)
    pending = sim.contacts()
    change(sim)
    after = sim.contacts()
    np.testing.assert_array_equal(after.i, pending.i)
    np.testing.assert_array_equal(after.shear_force, pending.shear_force)
    np.testing.assert_array_equal(after.sliding, pending.sliding)
    check_coulomb(after)


def test_wall_velocity_and_bonds_between_runs_count_the_last_displacement_once():
    sim = walled_packing()
    sim.run(25)
    pending = sim.contacts(), sim.wall_contacts()
    sim.wall(2).velocity = (0.0, 0.0)
    sim.velocities = np.zeros((sim.n_particles, 2))
    after = sim.contacts(), sim.wall_contacts()
    for a, b in zip(after, pending, strict=True):
        np.testing.assert_array_equal(a.shear_force, b.shear_force)
        np.testing.assert_array_equal(a.sliding, b.sliding)
    assert np.any(after[0].bonded) and len(after[1]) > 20
    check_coulomb(after[0])
    check_coulomb(after[1])
