"""Simulation's per-particle arrays (one typed descriptor each) and a wall's
state read in one engine call (WallState)."""

from __future__ import annotations

import dataclasses
import pydoc

import numpy as np
import pytest

from grainlab import Simulation, WallState

N = 3

#: name -> (dtype, columns or None, a valid value to set, or None when read-only)
ARRAYS = {
    "positions": (np.float64, 2, [[0.0, 0.0], [3e-3, 0.0], [0.0, 3e-3]]),
    "velocities": (np.float64, 2, [[0.1, -0.2], [0.0, 0.3], [1e-3, 0.0]]),
    "rotations": (np.float64, None, [0.1, -0.2, 3.0]),
    "angular_velocities": (np.float64, None, [1.0, 0.0, -2.5]),
    "radii": (np.float64, None, [1e-3, 1.2e-3, 0.9e-3]),
    "densities": (np.float64, None, [2e3, 2.5e3, 3e3]),
    "masses": (np.float64, None, None),
    "inertias": (np.float64, None, None),
    "forces": (np.float64, 2, None),
    "torques": (np.float64, None, None),
    "external_forces": (np.float64, 2, [[0.0, -1.0], [2.0, 0.0], [0.5, 0.5]]),
    "external_torques": (np.float64, None, [0.0, 1e-3, -1e-3]),
    "groups": (np.uint8, None, [0, 3, 15]),
    "fixity": (np.uint8, None, [0, 5, 7]),
}


def three_disks() -> Simulation:
    return Simulation([[0.0, 0.0], [5e-3, 0.0], [0.0, 5e-3]], [1e-3, 1e-3, 1e-3], density=2.0e8)


@pytest.mark.parametrize("name", ARRAYS)
def test_each_array_has_its_dtype_and_shape_and_is_read_only(name):
    dtype, columns, _ = ARRAYS[name]
    array = getattr(three_disks(), name)
    assert array.dtype == dtype
    assert array.shape == ((N, columns) if columns else (N,))
    with pytest.raises(ValueError, match="read-only"):
        array[0] = 1


@pytest.mark.parametrize("name", [k for k, v in ARRAYS.items() if v[2] is not None])
def test_a_settable_array_reads_back_what_was_set(name):
    sim = three_disks()
    value = ARRAYS[name][2]
    setattr(sim, name, value)
    np.testing.assert_array_equal(getattr(sim, name), np.asarray(value, dtype=ARRAYS[name][0]))


@pytest.mark.parametrize("name", [k for k, v in ARRAYS.items() if v[2] is not None])
def test_a_wrong_shape_is_refused_naming_the_array(name):
    sim = three_disks()
    before = getattr(sim, name).copy()
    wrong = np.zeros((N + 1, 2)) if ARRAYS[name][1] else np.zeros(N + 1)
    with pytest.raises(ValueError, match=rf"^{name}: "):
        setattr(sim, name, wrong)
    np.testing.assert_array_equal(getattr(sim, name), before)


@pytest.mark.parametrize("name", [k for k, v in ARRAYS.items() if v[2] is None])
def test_a_derived_array_cannot_be_set(name):
    sim = three_disks()
    with pytest.raises(AttributeError, match=rf"property '{name}' of 'Simulation' object has no setter"):
        setattr(sim, name, np.ones(N))


def test_radii_set_change_the_masses_of_unit_thickness_disks():
    sim = three_disks()
    sim.densities = [2e3, 2e3, 2e3]
    sim.radii = [1e-3, 2e-3, 0.5e-3]
    r = np.array([1e-3, 2e-3, 0.5e-3])
    np.testing.assert_allclose(sim.masses, 2e3 * np.pi * r**2, rtol=1e-14)
    np.testing.assert_allclose(sim.inertias, 0.5 * sim.masses * r**2, rtol=1e-14)


def test_help_shows_every_array_with_its_doc():
    text = pydoc.render_doc(Simulation, renderer=pydoc.plaintext)
    for name in ARRAYS:
        doc = Simulation.__dict__[name].__doc__
        assert doc and doc.split("\n")[0].strip() in text
        assert isinstance(Simulation.__dict__[name], property)
    readonly = text.split("Readonly properties defined here:")[1].split("----")[0]
    assert "\n |  masses\n" in readonly and "\n |  positions\n" not in readonly


def test_wall_state_reads_the_force_of_a_pressed_disk():
    # a disk overlapping a floor by half its radius: the wall carries kn * overlap
    # along -inward normal, and its stress over L is kn * overlap / L
    sim = Simulation([[0.0, 0.5e-3]], [1e-3], density=2.0e8, time_step=1e-7)
    floor = sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    segment = sim.add_segment_wall((1.0, 1.0), (2.0, 1.0))
    sim.run(1)
    kn = sim.contact_model(0, 1).normal_stiffness
    state = floor.state
    assert isinstance(state, WallState) and state.id == floor.id
    assert state.kind == "line" and state.points == ((0.0, 0.0),)
    assert state.contact_count == 1 and state.active and state.control == "velocity"
    np.testing.assert_allclose(state.force, (0.0, -kn * 0.5e-3), rtol=1e-12, atol=1e-9)
    np.testing.assert_array_equal(floor.force, state.force)
    np.testing.assert_array_equal(floor.inward_normal, state.inward_normal)
    assert floor.normal_stress(2e-3) == pytest.approx(kn * 0.5e-3 / 2e-3, rel=1e-12)
    assert state.target_stress_pa is None and state.max_speed_m_per_s is None
    far = segment.state
    assert far.kind == "segment" and far.points == ((1.0, 1.0), (2.0, 1.0))
    assert far.contact_count == 0 and far.force == (0.0, 0.0)
    np.testing.assert_array_equal(segment.points, [[1.0, 1.0], [2.0, 1.0]])


def test_wall_state_is_a_frozen_snapshot_of_the_wall():
    sim = Simulation([[0.0, 5e-3]], [1e-3], density=2.0e8, time_step=1e-7)
    wall = sim.add_segment_wall((-1e-2, 0.0), (1e-2, 0.0))
    before = wall.state
    with pytest.raises(dataclasses.FrozenInstanceError):
        before.velocity = (1.0, 0.0)
    wall.servo(2e5, 2e-2, relaxation=0.3, max_speed_m_per_s=0.05)
    wall.translate((0.0, 1e-4))
    after = wall.state
    assert before.control == "velocity" and before.displacement == (0.0, 0.0)
    assert after.control == "servo" and wall.control == "servo"
    assert after.displacement == pytest.approx((0.0, 1e-4), abs=1e-18)
    assert (after.target_stress_pa, after.loaded_length_m) == (2e5, 2e-2)
    assert (after.relaxation, after.max_speed_m_per_s) == (0.3, 0.05)
    assert repr(wall) == f"Wall(id={wall.id}, kind='segment', control='servo')"
