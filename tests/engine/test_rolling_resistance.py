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
