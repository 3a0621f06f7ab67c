"""Rolling resistance through the Python API (docs/contact-law.md, "Rolling
resistance"): the ContactModel's rolling fields reach the engine's law.

A disk (I = m r^2 / 2) rolling without slip on a floor, with the rolling moment
at its cap mu_r r N (N = m g): m a = -F and I alpha = F r - mu_r r N with
a = -alpha r give the deceleration a = mu_r g / (1 + I / (m r^2)) = (2/3) mu_r g.
The engine's own checks of the law (the cap, the incline, the elastic period,
the bits on 1 and 2 threads) are in crates/grainlab-core/tests/rolling.rs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab import ContactModel, Simulation

KN, R, DENSITY, G = 8.45e7, 1.0e-3, 2.0e8, 9.81


def rolling_disk(rolling_friction: float) -> Simulation:
    mass = DENSITY * math.pi * R * R
    model = ContactModel(KN, KN, 0.5, normal_damping_ratio=0.3, shear_damping_ratio=0.3,
                         rolling_friction=rolling_friction)
    dt = math.pi * math.sqrt(mass / KN) / 50.0
    sim = Simulation([[0.0, R - mass * G / KN]], [R], DENSITY, contact_model=model, time_step=dt,
                     gravity=(0.0, -G), threads=1)
    sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    sim.velocities = [[0.1, 0.0]]
    sim.angular_velocities = [-0.1 / R]
    return sim


def test_a_disk_rolling_on_a_floor_decelerates_at_two_thirds_mu_r_g() -> None:
    mu_r = 0.1
    sim = rolling_disk(mu_r)
    assert sim.contact_model(0, 1).rolling_friction == mu_r
    steps = round(0.02 / sim.time_step)
    sim.run(steps)
    v1 = sim.velocities[0, 0]
    sim.run(2 * steps)
    v2 = sim.velocities[0, 0]
    measured = (v1 - v2) / (2 * steps * sim.time_step)
    assert measured == pytest.approx(2.0 / 3.0 * mu_r * G, rel=2e-4)
    assert sim.energy.rolling_dissipated > 0.0


def test_without_rolling_friction_the_disk_rolls_on() -> None:
    sim = rolling_disk(0.0)
    sim.run(round(0.06 / sim.time_step))
    assert sim.velocities[0, 0] == pytest.approx(0.1, rel=1e-6)
    assert sim.energy.rolling_dissipated == 0.0


# ---- the rolling moment in contacts() and wall_contacts() ----

MU_R = 0.1


def spinning_pair(rolling_friction: float) -> tuple[Simulation, float, float]:
    """Two disks (radii R and 2R, overlap R/100) and a third one on a floor (overlap R/100),
    every degree of freedom prescribed: the disks keep their spins, so each contact
    rolls by exactly its relative rotation. Returns the simulation, the pair's R* and
    the rule's k_r = 2.25 kn mu_r^2 R*^2 for the pair."""
    model = ContactModel(KN, KN, 0.5, rolling_friction=rolling_friction)
    r_star = R * 2 * R / (3 * R)
    mass = DENSITY * math.pi * R * R
    sim = Simulation([[0.0, 10 * R], [2.99 * R, 10 * R], [10 * R, 0.99 * R]], [R, 2 * R, R], DENSITY,
                     contact_model=model, time_step=0.02 * math.sqrt(mass / KN), threads=1)
    sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    sim.fixity = [7, 7, 7]
    # about 15 steps to the pair's cap, 20 to the wall contact's
    sim.angular_velocities = [50.0, -30.0, 40.0]
    return sim, r_star, 2.25 * KN * rolling_friction**2 * r_star**2


def test_contacts_report_the_rolling_moment_minus_k_r_times_the_relative_rotation_then_the_cap() -> None:
    """The exact two-disk oracle: after a relative rotation dtheta of i against j
    the moment on i is -k_r dtheta (and +k_r dtheta on j), until the cap
    mu_r R* F_n; against a wall (which does not turn, R* = r) -k_r theta."""
    sim, r_star, k_r = spinning_pair(MU_R)
    k_wall = 2.25 * KN * MU_R**2 * R**2
    cap = MU_R * r_star * sim.contacts().normal_force[0]
    wall_cap = MU_R * R * sim.wall_contacts().normal_force[0]
    elastic_seen = capped_seen = 0
    for _ in range(60):
        sim.run(1)
        c, w = sim.contacts(), sim.wall_contacts()
        assert (len(c), len(w)) == (1, 1)
        theta = sim.rotations
        dtheta = theta[0] - theta[1]
        if k_r * abs(dtheta) < cap:
            assert c.rolling_moment[0] == pytest.approx(-k_r * dtheta, rel=1e-9)
            elastic_seen += 1
        else:
            assert c.rolling_moment[0] == pytest.approx(-cap * math.copysign(1.0, dtheta), rel=1e-12)
            capped_seen += 1
        if k_wall * abs(theta[2]) < wall_cap:
            assert w.rolling_moment[0] == pytest.approx(-k_wall * theta[2], rel=1e-9)
        else:
            assert w.rolling_moment[0] == pytest.approx(-wall_cap * math.copysign(1.0, theta[2]), rel=1e-12)
    assert elastic_seen > 5 and capped_seen > 5


def test_without_rolling_friction_every_rolling_moment_is_zero() -> None:
    sim, _, _ = spinning_pair(0.0)
    sim.run(20)
    c, w = sim.contacts(), sim.wall_contacts()
    assert len(c) == 1 and len(w) == 1
    assert np.all(c.rolling_moment == 0.0) and np.all(w.rolling_moment == 0.0)
    assert not np.signbit(c.rolling_moment).any()


@pytest.mark.parametrize("threads", [1, 2])
def test_the_contacts_moments_and_shear_forces_sum_to_each_particles_torque(threads: int) -> None:
    """Torque balance: in a packing in a box of walls with rolling resistance (and a
    rolling dashpot), frozen after some motion (every degree of freedom prescribed at
    rest, so that the step's forces are the ones contacts() reports: no dashpot acts),
    each particle's torque is the sum over its contacts of r shear_force + rolling_moment
    (i) and r shear_force - rolling_moment (j), and over its wall contacts of
    r shear_force + rolling_moment."""
    rng = np.random.default_rng(4)
    n, s = 12, 1.0e-3
    grid = (np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2) + 0.5) * s
    positions = grid + rng.uniform(-0.05, 0.05, grid.shape) * s
    radii = rng.uniform(0.45, 0.56, len(grid)) * s
    mass = DENSITY * math.pi * (0.45 * s) ** 2
    model = ContactModel(KN, KN, 0.5, rolling_friction=MU_R, rolling_damping_ratio=0.3)
    sim = Simulation(positions, radii, DENSITY, contact_model=model, time_step=0.1 * math.sqrt(mass / KN),
                     threads=threads)
    side = n * s
    for point, normal in (((0, 0), (0, 1)), ((side, 0), (-1, 0)), ((0, side), (0, -1)), ((0, 0), (1, 0))):
        sim.add_line_wall(point, normal)
    sim.velocities = rng.uniform(-0.02, 0.02, (len(grid), 2))
    sim.angular_velocities = rng.uniform(-20.0, 20.0, len(grid))
    sim.run(300)
    sim.velocities = np.zeros((len(grid), 2))
    sim.angular_velocities = np.zeros(len(grid))
    sim.fixity = np.full(len(grid), 7)
    sim.run(1)
    c, w = sim.contacts(), sim.wall_contacts()
    assert np.count_nonzero(c.rolling_moment) > 100 and np.count_nonzero(w.rolling_moment) > 10
    torque = np.zeros(len(grid))
    scale = np.zeros(len(grid))
    for q, sign in ((c.i, 1.0), (c.j, -1.0)):
        parts = radii[q] * c.shear_force + sign * c.rolling_moment
        np.add.at(torque, q, parts)
        np.add.at(scale, q, np.abs(parts))
    parts = radii[w.particle] * w.shear_force + w.rolling_moment
    np.add.at(torque, w.particle, parts)
    np.add.at(scale, w.particle, np.abs(parts))
    assert np.all(np.abs(sim.torques - torque) <= 1e-12 * scale + 1e-300)
    # the rolling moments' share is no rounding: without them the balance fails
    without = torque - np.bincount(c.i, c.rolling_moment, len(grid)) + np.bincount(c.j, c.rolling_moment, len(grid))
    assert np.max(np.abs(sim.torques - without)) > 1e3 * np.max(np.abs(sim.torques - torque))
