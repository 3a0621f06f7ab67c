"""Rigid bodies from Python: clumps placed from a template, their mass from the
exact union, their motion (momentum of colliding clumps, a pile at rest), the
body of every particle, save and load, and bad input refused before any change."""

from __future__ import annotations

import numpy as np
import pytest
from clump_factories import trimer_pile

from grainlab import ContactModel, Simulation
from grainlab.bodies import clump_mass_properties

TRIMER = np.array([[0.0, 0.7e-3], [-0.6e-3, -0.35e-3], [0.6e-3, -0.35e-3]])
RADII = np.full(3, 1.0e-3)
DENSITY = 2.0e8
KN = 8.45e7


def _two_trimers(**kwargs: object) -> Simulation:
    sim = Simulation(
        np.empty((0, 2)), np.empty(0), DENSITY, contact_model=ContactModel(KN, KN, 0.0), time_step=1e-4
    )
    sim.add_clumps(TRIMER, RADII, positions=[[0.0, 0.0], [4.2e-3, 0.8e-3]], angles=[0.0, 0.7], density=DENSITY)
    return sim


def test_clumps_are_placed_from_their_template_with_the_unions_mass():
    sim = _two_trimers()
    union = clump_mass_properties(TRIMER, RADII, density=DENSITY)
    clumps = sim.clumps
    assert len(clumps) == 2 and sim.n_particles == 6
    # (the turned clump's union is computed from its turned pebbles: round-off apart)
    np.testing.assert_allclose(clumps.mass_kg, [union.mass_kg] * 2, rtol=1e-14)
    np.testing.assert_allclose(clumps.moment_of_inertia_kg_m2, [union.moment_of_inertia_kg_m2] * 2, rtol=1e-14)
    np.testing.assert_array_equal(clumps.angle_rad, [0.0, 0.7])
    # the second clump's pebbles are the template turned by 0.7 about its origin
    c, s = np.cos(0.7), np.sin(0.7)
    turned = TRIMER @ np.array([[c, s], [-s, c]]) + [4.2e-3, 0.8e-3]
    np.testing.assert_allclose(sim.positions[3:], turned, rtol=0, atol=1e-18)
    centroid = union.centroid_m @ np.array([[c, s], [-s, c]]) + [4.2e-3, 0.8e-3]
    np.testing.assert_allclose(clumps.centroid_m[1], centroid, rtol=0, atol=1e-18)
    np.testing.assert_array_equal(sim.body_of_particles, [0, 0, 0, 1, 1, 1])
    # the pebbles carry the body's mass (what the contact laws' damping sees)
    np.testing.assert_array_equal(sim.masses, np.repeat(clumps.mass_kg, 3))
    assert sim.fixity.max() == 0


def test_colliding_clumps_keep_their_momentum_and_exchange_spin():
    sim = _two_trimers()
    sim.set_clump_velocities([[0.01, 0.0], [-0.01, 0.0]], [0.0, 0.0])
    mass = sim.clumps.mass_kg

    def momentum() -> np.ndarray:
        return (mass[:, None] * sim.clumps.velocity_m_per_s).sum(0)

    p0 = momentum()
    touched = False
    for _ in range(200):
        sim.run(10)
        touched |= sim.contact_count > 0
        np.testing.assert_allclose(momentum(), p0, rtol=0, atol=1e-15 * np.abs(mass * 0.01).sum())
    assert touched
    # the off-centre hit turned them (frictionless: through the pebbles' centres)
    assert np.abs(sim.clumps.angular_velocity_rad_per_s).min() > 1e-3


def test_a_pile_of_clumps_comes_to_rest_on_a_floor_without_inner_contacts():
    sim = trimer_pile(np.random.default_rng(4).uniform(0, 2 * np.pi, 6))
    sim.run(80_000)
    body = sim.body_of_particles
    contacts = sim.contacts()
    assert len(contacts) >= 3  # every clump of the second row rests on the first
    assert not np.any(body[contacts.i] == body[contacts.j])
    # at rest: the floor and, by friction, the side walls carry the clumps' weight
    carried = sum(sim.wall(k).force[1] for k in range(3))
    assert carried == pytest.approx(-9.81 * sim.clumps.mass_kg.sum(), rel=1e-6)
    assert np.abs(sim.clumps.velocity_m_per_s).max() < 1e-9


def test_save_and_load_keep_the_clumps_to_the_bit(tmp_path):
    sim = _two_trimers()
    sim.set_clump_velocities([[0.01, 0.0], [-0.01, 0.0]], [0.0, 3.0])
    sim.run(50)
    sim.save(tmp_path / "state.bin")
    sim.run(100)
    again = Simulation.load(tmp_path / "state.bin")
    again.run(100)
    np.testing.assert_array_equal(again.positions, sim.positions)
    np.testing.assert_array_equal(again.clumps.angle_rad, sim.clumps.angle_rad)
    np.testing.assert_array_equal(again.body_of_particles, sim.body_of_particles)


@pytest.mark.parametrize(
    ("pebbles", "kwargs", "message"),
    [
        ([[0, 1], [1, 2]], {}, r"bodies\[1\]: particle 1 is also a pebble of body 0"),
        ([[0, 1], []], {}, r"bodies\[1\]: a body needs at least one pebble"),
        ([[0, 7]], {}, r"bodies\[0\].pebbles: particle index 7 out of range 0..2"),
        ([[0, -1]], {}, r"bodies\[0\].pebbles: particle index -1 out of range"),
        ([[0, 1]], {"masses": [(0.0, 1.0, (0.0, 0.0))]}, r"bodies\[0\].mass"),
        ([[0, 1]], {"masses": [(1.0, -1.0, (0.0, 0.0))]}, r"bodies\[0\].moment_of_inertia"),
        ([[0, 1]], {"angles": [np.nan]}, r"angles\[0\]: must be finite"),
        ([[0, 1]], {"masses": []}, r"masses: expected 1 entries"),
    ],
)
def test_bad_bodies_are_refused_with_the_field_before_any_change(pebbles, kwargs, message):
    sim = Simulation([[0.0, 0.0], [1.5e-3, 0.0], [3.0e-3, 0.0]], [1e-3] * 3, DENSITY, time_step=1e-5)
    with pytest.raises(ValueError, match=message):
        sim.add_bodies(pebbles, **kwargs)
    assert len(sim.clumps) == 0
    np.testing.assert_array_equal(sim.body_of_particles, [0, 1, 2])


def test_scaled_clumps_are_similar_clumps_of_the_same_density():
    sim = _two_trimers()
    before = sim.clumps
    sim.scale_clumps([2.0, 0.5])
    after = sim.clumps
    np.testing.assert_allclose(after.mass_kg, before.mass_kg * [4.0, 0.25], rtol=1e-15)
    np.testing.assert_allclose(after.moment_of_inertia_kg_m2, before.moment_of_inertia_kg_m2 * [16.0, 1 / 16], rtol=1e-15)
    np.testing.assert_array_equal(sim.radii, [2e-3] * 3 + [0.5e-3] * 3)
    union = clump_mass_properties(sim.positions[:3], sim.radii[:3], density=DENSITY)
    assert after.mass_kg[0] == pytest.approx(union.mass_kg, rel=1e-13)
    with pytest.raises(ValueError, match=r"factors\[1\]"):
        sim.scale_clumps([1.0, 0.0])


def test_a_clumps_new_density_scales_its_mass_and_inertia():
    """All pebbles of a clump given one new density: the body's mass and moment of
    inertia scale by the density ratio (density scaling of a clump sample); pebbles
    of one clump that disagree are refused before any change."""
    sim = _two_trimers()
    before = sim.clumps
    sim.densities = [3 * DENSITY] * 3 + [DENSITY] * 3
    after = sim.clumps
    np.testing.assert_allclose(after.mass_kg, before.mass_kg * [3.0, 1.0], rtol=1e-15)
    np.testing.assert_allclose(after.moment_of_inertia_kg_m2, before.moment_of_inertia_kg_m2 * [3.0, 1.0],
                               rtol=1e-15)
    np.testing.assert_array_equal(sim.masses, np.repeat(after.mass_kg, 3))
    union = clump_mass_properties(sim.positions[:3], sim.radii[:3], density=3 * DENSITY)
    assert after.mass_kg[0] == pytest.approx(union.mass_kg, rel=1e-13)
    with pytest.raises(ValueError, match=r"densities\[4\]: particles 3 and 4 are pebbles of clump 1 with different"):
        sim.densities = [DENSITY] * 4 + [2 * DENSITY, DENSITY]
    np.testing.assert_array_equal(sim.clumps.mass_kg, after.mass_kg)
    # and back: the clump's own mass again
    sim.densities = [DENSITY] * 6
    np.testing.assert_allclose(sim.clumps.mass_kg, before.mass_kg, rtol=1e-15)


def test_a_pebble_moves_only_with_its_body():
    sim = _two_trimers()
    # the whole assembly shifted: each clump follows rigidly, to round-off
    centroids = sim.clumps.centroid_m
    sim.positions = sim.positions + [1e-3, 2e-3]
    np.testing.assert_allclose(sim.clumps.centroid_m, centroids + [1e-3, 2e-3], rtol=0, atol=1e-15)
    # zeros stop the clumps; a radius of one pebble cannot change alone
    sim.set_clump_velocities([[0.01, 0.0], [0.0, 0.02]], [3.0, -1.0])
    sim.velocities = np.zeros((6, 2))
    sim.angular_velocities = np.zeros(6)
    assert not sim.clumps.velocity_m_per_s.any() and not sim.clumps.angular_velocity_rad_per_s.any()
    assert not sim.velocities.any()
    with pytest.raises(ValueError, match=r"radii\[4\]: particle 4 is a pebble of clump 1"):
        sim.radii = [1e-3] * 4 + [2e-3, 1e-3]
    with pytest.raises(ValueError, match=r"different fixity"):
        sim.fixity = [7, 0, 0, 0, 0, 0]
    sim.fixity = [7, 7, 7, 0, 0, 0]
    np.testing.assert_array_equal(sim.clumps.fixity, [7, 0])
    np.testing.assert_array_equal(sim.fixity, [7, 7, 7, 0, 0, 0])
    with pytest.raises(ValueError, match=r"velocities: has 1 rows but there are 2 clumps"):
        sim.set_clump_velocities([[0.0, 0.0]], [0.0])


def test_bodies_by_label_group_the_particles_that_share_one():
    sim = Simulation([[0.0, 0.0], [1.5e-3, 0.0], [9e-3, 0.0], [20e-3, 0.0], [21.5e-3, 0.0]], [1e-3] * 5, DENSITY,
                     time_step=1e-6)
    assert sim.add_bodies_by_label([7, 7, -1, 3, 3]) == [3, 7]
    # clumps in label order: label 3 (particles 3, 4) is clump 0, label 7 clump 1
    np.testing.assert_array_equal(sim.body_of_particles, [1, 1, 2, 0, 0])
    with pytest.raises(ValueError, match=r"labels\[1\]: a body label is >= 0"):
        Simulation([[0.0, 0.0], [3e-3, 0.0]], [1e-3] * 2, DENSITY, time_step=1e-6).add_bodies_by_label([0, -2])
    with pytest.raises(ValueError, match=r"labels: expected 2 integers"):
        Simulation([[0.0, 0.0], [3e-3, 0.0]], [1e-3] * 2, DENSITY, time_step=1e-6).add_bodies_by_label([0.5, 1.0])
