"""The Python API of the engine: input validation, read-only state, contacts,
walls, bonds, fixity, the periodic cell, save/load and determinism."""

from __future__ import annotations

import numpy as np
import pytest

import grainlab
from grainlab import ContactModel, Simulation


def two_disks(**kwargs) -> Simulation:
    return Simulation([[0.0, 0.0], [2.5e-3, 0.0]], [1e-3, 1e-3], **({"density": 2.0e8} | kwargs))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"positions": [[0, 0], [1, 0]], "radii": [1e-3, -1e-3]}, "radius[1]"),
        ({"positions": [[0, 0], [1, 0]], "radii": [0.0, 1e-3]}, "radius[0]"),
        ({"positions": [[0, np.nan], [1, 0]], "radii": [1e-3, 1e-3]}, "positions[0]"),
        ({"positions": [[0, 0], [1, 0]], "radii": [1e-3, 1e-3, 1e-3]}, "radii"),
        ({"positions": [[0, 0, 0]], "radii": [1e-3]}, "positions"),
        ({"positions": [[0, 0]], "radii": [1e-3], "density": -1.0}, "density[0]"),
        ({"positions": [[0, 0]], "radii": [1e-3], "density": None}, "density: give the grains' density"),
        ({"positions": [[0, 0]], "radii": [1e-3], "contact_model": ContactModel(normal_stiffness=0.0)}, "normal_stiffness"),
        ({"positions": [[0, 0]], "radii": [1e-3], "contact_model": ContactModel(shear_stiffness=-5.0)}, "shear_stiffness"),
        ({"positions": [[0, 0]], "radii": [1e-3], "contact_model": ContactModel(rolling_friction=-0.1)}, "rolling_friction"),
        ({"positions": [[0, 0]], "radii": [1e-3], "contact_model": ContactModel(rolling_stiffness=-1.0)}, "rolling_stiffness"),
        ({"positions": [[0, 0]], "radii": [1e-3], "contact_model": ContactModel(rolling_damping_ratio=np.nan)}, "rolling_damping_ratio"),
        ({"positions": [[0, 0]], "radii": [1e-3], "local_damping": 1.0}, "local_damping"),
        ({"positions": [[0, 0]], "radii": [1e-3], "time_step": 0.0}, "time_step"),
    ],
)
def test_bad_input_names_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field.replace("[", r"\[").replace("]", r"\]")):
        Simulation(**({"density": 2.0e8} | kwargs))


def test_bad_input_after_construction_names_the_field():
    sim = two_disks()
    with pytest.raises(ValueError, match="wall_id"):
        sim.wall(3)
    with pytest.raises(ValueError, match=r"radii\[1\]"):
        sim.radii = [1e-3, -2e-3]
    with pytest.raises(ValueError, match="velocities"):
        sim.velocities = [[0.0, 0.0]]
    with pytest.raises(ValueError, match="groups"):
        sim.groups = [0, 16]
    with pytest.raises(ValueError, match="normal_stiffness"):
        sim.set_contact_model(0, 1, ContactModel(normal_stiffness=-1.0))
    with pytest.raises(ValueError, match=r"^contact_model\.rolling_friction: must be finite and >= 0, got -0\.2$"):
        sim.set_contact_model(0, 1, ContactModel(rolling_friction=-0.2))
    wall = sim.add_segment_wall((0, -1e-3), (1e-2, -1e-3))
    with pytest.raises(ValueError, match="relaxation"):
        wall.servo(1e5, 1e-2, relaxation=2.0)
    with pytest.raises(ValueError, match="bond"):
        sim.add_bond(0, 0, 1e6, 1e6)


def test_state_arrays_are_read_only_copies():
    sim = two_disks()
    pos = sim.positions
    with pytest.raises(ValueError):
        pos[0, 0] = 1.0
    assert pos.shape == (2, 2) and sim.radii.shape == (2,)
    sim.positions = [[0.0, 0.0], [3e-3, 0.0]]
    assert sim.positions[1, 0] == 3e-3


def test_masses_are_those_of_unit_thickness_disks():
    sim = Simulation([[0, 0], [1, 0]], [1e-3, 2e-3], density=[2e8, 1e3])
    np.testing.assert_allclose(sim.masses, [2e8 * np.pi * 1e-6, 1e3 * np.pi * 4e-6], rtol=1e-15)
    np.testing.assert_allclose(sim.inertias, 0.5 * sim.masses * sim.radii**2, rtol=1e-15)


def test_free_fall_is_exact_from_full_step_velocities():
    # constant force: leapfrog started with a half kick gives x = x0 + v0 t + g t^2 / 2 exactly
    sim = Simulation([[0.0, 0.0]], [1e-3], density=2.0e8, time_step=1e-4, gravity=(0.0, -9.81))
    sim.velocities = [[0.5, 1.0]]
    sim.run(1000)
    t = sim.time
    np.testing.assert_allclose(sim.positions[0], [0.5 * t, 1.0 * t - 0.5 * 9.81 * t * t], rtol=1e-12)


def test_contacts_are_consistent(dense_periodic):
    sim = dense_periodic()
    sim.run(50)
    c = sim.contacts()
    assert len(c) > 100
    assert np.all(c.i < c.j)
    order = np.lexsort((c.j, c.i))
    np.testing.assert_array_equal(order, np.arange(len(c)))
    np.testing.assert_allclose(np.linalg.norm(c.normal, axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(c.normal_force, 8.45e7 * c.overlap, rtol=1e-14)
    # the contact point lies between the centres, r_i - overlap/2 from i
    branch = c.point - sim.positions[c.i]
    arm = np.einsum("ij,ij->i", branch, c.normal)
    np.testing.assert_allclose(arm, sim.radii[c.i] - c.overlap / 2, rtol=1e-9)


def test_resultants_are_the_sums_of_contact_forces(dense_periodic):
    # frictionless: the next step's resultant on each particle is the sum of kn * overlap * n
    sim = dense_periodic(friction=0.0)
    sim.run(30)
    c = sim.contacts()
    sim.run(1)
    expected = np.zeros((sim.n_particles, 2))
    f = c.normal_force[:, None] * c.normal
    np.add.at(expected, c.j, f)
    np.add.at(expected, c.i, -f)
    scale = np.abs(f).max()
    np.testing.assert_allclose(sim.forces, expected, rtol=0, atol=1e-12 * scale)
    assert sim.contact_count == len(c)


def test_bond_carries_tension():
    # two bonded disks pulled apart by +-F settle at extension F / kn_bond
    sim = Simulation([[0.0, 0.0], [2e-3, 0.0]], [1e-3, 1e-3], density=2.0e8, local_damping=0.7, time_step=1e-5, threads=1)
    sim.add_bond(0, 1, normal_stiffness=1e6, shear_stiffness=1e6)
    force = 50.0
    sim.external_forces = [[-force, 0.0], [force, 0.0]]
    sim.run(300_000)
    gap = sim.positions[1, 0] - sim.positions[0, 0]
    assert gap - 2e-3 == pytest.approx(force / 1e6, rel=1e-6)
    c = sim.contacts()
    assert c.bonded.tolist() == [True]
    assert c.normal_force[0] == pytest.approx(-force, rel=1e-6)


def test_prescribed_velocity_ignores_forces():
    sim = Simulation([[0.0, 0.0], [1.8e-3, 0.0]], [1e-3, 1e-3], density=2.0e8, time_step=1e-5)
    sim.fixity = [grainlab.FIX_X | grainlab.FIX_Y | grainlab.FIX_ROTATION, 0]
    sim.velocities = [[0.01, 0.0], [0.0, 0.0]]
    sim.run(100)
    np.testing.assert_allclose(sim.positions[0], [100 * 1e-5 * 0.01, 0.0], rtol=1e-12)
    assert sim.velocities[1, 0] > 0  # pushed away by the overlap


def test_homogeneous_deformation_maps_a_particle_affinely():
    # a lone disk with no fluctuation follows x_n = (I + dt L)^n x_0 about the cell origin
    sim = Simulation([[0.02, 0.03]], [1e-3], density=2.0e8, time_step=1e-3)
    sim.set_periodic_cell((0.0, 0.0), (0.05, 0.05))
    grad = np.array([[-0.2, 0.1], [0.0, 0.2]])
    sim.set_velocity_gradient(grad)
    sim.run(100)
    step = np.eye(2) + 1e-3 * grad
    expected = np.linalg.matrix_power(step, 100) @ np.array([0.02, 0.03])
    np.testing.assert_allclose(sim.positions[0], expected, rtol=1e-12)
    cell = sim.cell
    np.testing.assert_allclose(cell.a, np.linalg.matrix_power(step, 100) @ [0.05, 0.0], rtol=1e-12)


def test_periodic_images_interact_across_the_boundary():
    sim = Simulation([[0.0005, 0.01], [0.0195, 0.01]], [1e-3, 1e-3], density=2.0e8, time_step=1e-5)
    sim.set_periodic_cell((0.0, 0.0), (0.02, 0.02))
    c = sim.contacts()
    assert len(c) == 1
    assert c.overlap[0] == pytest.approx(1e-3, rel=1e-9)


def test_save_and_load_continue_bitwise(tmp_path, dense_periodic):
    sim = dense_periodic(threads=2)
    sim.run(200)
    path = tmp_path / "state.bin"
    sim.save(path)
    sim.run(300)
    resumed = Simulation.load(path)
    resumed.run(300)
    assert resumed.threads == 2
    np.testing.assert_array_equal(sim.positions, resumed.positions)
    np.testing.assert_array_equal(sim.velocities, resumed.velocities)
    np.testing.assert_array_equal(sim.contacts().shear_force, resumed.contacts().shear_force)
    assert sim.energy == resumed.energy


def test_a_file_that_is_not_a_state_is_refused(tmp_path):
    path = tmp_path / "junk.bin"
    path.write_bytes(b"hello")
    with pytest.raises(ValueError, match="not a grainlab engine state"):
        Simulation.load(path)


def test_blow_up_stops_with_the_particles_named(dense_periodic):
    # a dense packing at 10x the critical time step: leapfrog is unstable and the overlap runs away
    sim = dense_periodic()
    sim.time_step = 10 * sim.time_step
    with pytest.raises(grainlab.SimulationUnstableError, match=r"overlap of particles \d+ and \d+ reached"):
        sim.run(1000)


def test_density_scaling_factor_matches_eq16():
    i = grainlab.density_scaling_factor(0.02 / 60, 2e8, 0.25e-3, 1e5)
    assert i == pytest.approx(0.02 / 60 * np.sqrt(2e8 * 0.25e-3**2 / 1e5), rel=1e-15)


def test_snapshot_carries_the_contacts_with_the_analysis_conventions(dense_periodic):
    from grainlab.analysis import CoordinationNumber

    sim = dense_periodic(friction=0.5)
    sim.run(40)
    c = sim.contacts()
    snap = sim.snapshot(axial_strain=0.0)
    z = CoordinationNumber().compute(snap)
    assert z.coordination_number == pytest.approx(2 * len(c) / sim.n_particles, rel=1e-12)
    # one convention on the Python side: the snapshot's contacts are the simulation's
    assert np.any(c.shear_force != 0)
    np.testing.assert_array_equal(snap.shear_force[: len(c)], c.shear_force)
    np.testing.assert_array_equal(snap.contact_normal[: len(c)], c.normal)


def test_snapshot_wall_contacts_point_to_the_wall():
    sim = Simulation([[0.0, 0.9e-3]], [1e-3], density=2.0e8, time_step=1e-6)
    sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    snap = sim.snapshot()
    assert snap.contact_j.tolist() == [-1]
    np.testing.assert_allclose(snap.contact_normal[0], [0.0, -1.0])
    w = sim.wall_contacts()
    np.testing.assert_allclose(w.normal[0], [0.0, -1.0])
    # the floor pushes the disk up: compression positive along the normal to the wall
    np.testing.assert_allclose(w.force_on_particle[0], [0.0, w.normal_force[0]])
    assert w.normal_force[0] == pytest.approx(sim.contact_model(0, 1).normal_stiffness * 0.1e-3)


def test_pressure_chain_pushes_with_pressure_times_span():
    # ten touching disks in a column between a floor and a ceiling, pressed by a follower
    # pressure against a wall on their right: the wall carries p * H at equilibrium
    r, height, pressure = 1e-3, 20e-3, 1e5
    y = r + 2 * r * np.arange(10)
    sim = Simulation(np.column_stack([np.zeros(10), y]), np.full(10, r), density=2.0e8, local_damping=0.7, threads=1)
    sim.set_contact_model(0, 1, ContactModel(friction=0.0))
    floor = sim.add_line_wall((0, 0), (0, 1))
    ceiling = sim.add_line_wall((0, height), (0, -1))
    wall = sim.add_line_wall((r, 0), (-1, 0))  # particles on its left
    chain = sim.add_pressure_chain(np.arange(10), pressure, start_wall=floor, end_wall=ceiling)
    sim.run(20_000)
    assert wall.force[0] == pytest.approx(pressure * height, rel=1e-6)
    assert wall.normal_stress(height) == pytest.approx(pressure, rel=1e-6)
    assert sim.pressure_chain(chain).particles == list(range(10))
    # the follower load did the work stored in the contacts and lost to damping
    e = sim.energy
    assert e.boundary_work > 0
    assert e.balance == pytest.approx(0.0, abs=1e-3 * e.boundary_work)


def test_inactive_wall_lets_particles_through():
    sim = Simulation([[0.0, 0.5e-3]], [1e-3], density=2.0e8, time_step=1e-6)
    floor = sim.add_line_wall((0, 0), (0, 1))
    sim.run(1)
    assert floor.contact_count == 1
    floor.active = False
    sim.run(1)
    assert floor.contact_count == 0 and not floor.active
    assert len(sim.wall_contacts()) == 0


def test_added_particles_join_and_old_contacts_keep_their_history(dense_periodic):
    sim = dense_periodic(friction=0.5)
    sim.run(50)
    before = sim.contacts()
    new = sim.add_particles([[1e-4, 1e-4]], [1e-4], 2e8)
    assert new.tolist() == [sim.n_particles - 1]
    after = sim.contacts()
    old_rows = after.j < new[0]
    np.testing.assert_array_equal(after.shear_force[old_rows], before.shear_force)
    assert sim.masses[-1] == pytest.approx(2e8 * np.pi * 1e-8)
    sim.run(10)


def test_groups_that_do_not_interact_pass_through_each_other():
    sim = Simulation([[0.0, 0.0], [1.5e-3, 0.0]], [1e-3, 1e-3], density=2.0e8, time_step=1e-5, threads=1)
    sim.groups = [0, 2]
    sim.set_contact_model(0, 2, ContactModel(enabled=False))
    sim.velocities = [[0.1, 0.0], [-0.1, 0.0]]
    sim.run(100)
    assert len(sim.contacts()) == 0
    np.testing.assert_allclose(sim.velocities, [[0.1, 0.0], [-0.1, 0.0]])
    assert sim.contact_model(2, 0).enabled is False
