"""Radius expansion on small boxes: target reached, reproducible, the stress bound, the report."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import grainlab
from grainlab.samples import (
    PAPER_GRADING,
    WALL_NAMES,
    ExpansionError,
    PlacementError,
    UniformByMass,
    expand_to_porosity,
    nominal_porosity,
    overlap_corrected_porosity,
)

SMALL = (0.0, 0.0, 0.02, 0.04)  # about 250 disks of the paper's grading at porosity 0.12


@pytest.fixture(scope="module")
def small_sample():
    return expand_to_porosity(SMALL, 0.12, seed=3, progress=False, keep_simulation=True)


def test_reaches_the_target_porosity_and_reports_where_it_is(small_sample):
    s = small_sample
    area = 0.02 * 0.04
    assert s.n_particles == 250
    assert abs(s.porosity - 0.12) < 0.002
    assert s.porosity == pytest.approx(nominal_porosity(s.radii, area), abs=1e-15)
    assert s.porosity_overlap_corrected == pytest.approx(overlap_corrected_porosity(s.positions, s.radii, SMALL))
    assert s.porosity_overlap_corrected > s.porosity  # overlaps are counted once
    assert s.equilibrium_reached and s.unbalanced_force_ratio < 1e-4
    # dense and stressed: locked-in stress of order MPa (docs/samples.md, the Table 1 sample)
    assert 2e5 < s.mean_wall_stress_pa < 5e6
    assert s.mean_wall_stress_pa == pytest.approx(s.wall_stresses_pa.mean())
    assert 3.0 < s.coordination_number < 5.0
    assert 0.0 < s.mean_overlap_ratio < 0.3 and s.max_overlap_ratio < 0.5
    assert s.radius_factor == pytest.approx(1.0, abs=0.1)
    assert s.grading == PAPER_GRADING.name and s.seed == 3 and s.threads == 1
    assert s.steps > 0 and s.wall_time_s > 0


def test_disks_stay_inside_the_walls(small_sample):
    s = small_sample
    x0, y0, x1, y1 = s.box
    # contacts with the walls overlap a little, never more than the largest particle overlaps
    slack = s.max_overlap_ratio * s.radii.max()
    assert np.all(s.positions[:, 0] - s.radii >= x0 - slack) and np.all(s.positions[:, 0] + s.radii <= x1 + slack)
    assert np.all(s.positions[:, 1] - s.radii >= y0 - slack) and np.all(s.positions[:, 1] + s.radii <= y1 + slack)
    assert s.wall_points.shape == (4, 2, 2)
    assert WALL_NAMES == ("bottom", "right", "top", "left")


def test_the_live_simulation_continues_from_the_sample(small_sample):
    sim = small_sample.simulation
    assert isinstance(sim, grainlab.Simulation)
    assert np.array_equal(sim.positions, small_sample.positions)
    assert np.array_equal(sim.radii, small_sample.radii)
    assert np.all(sim.densities == 2e8)  # Table 1 density restored after density scaling
    assert np.all(sim.velocities == 0.0)
    assert len(sim.walls) == 4
    # the inward normals of bottom, right, top, left
    normals = np.array([w.inward_normal for w in sim.walls])
    assert np.allclose(normals, [[0, 1], [-1, 0], [0, -1], [1, 0]])
    # walls hold the packing: stresses are compressive
    assert all(w.normal_stress(1.0) > 0 for w in sim.walls)


def test_same_seed_same_sample_bit_for_bit(small_sample):
    again = expand_to_porosity(SMALL, 0.12, seed=3, progress=False)
    assert np.array_equal(again.positions, small_sample.positions)
    assert np.array_equal(again.radii, small_sample.radii)
    assert again.mean_wall_stress_pa == small_sample.mean_wall_stress_pa
    assert again.steps == small_sample.steps
    other = expand_to_porosity(SMALL, 0.12, seed=4, progress=False)
    assert not np.array_equal(other.radii, small_sample.radii)


def test_summary_and_dict(small_sample):
    line = small_sample.summary()
    assert "250 disks" in line and "0.1200 nominal" in line and "kPa" in line
    d = json.loads(json.dumps(small_sample.to_dict()))
    assert d["porosity"] == small_sample.porosity and d["n_particles"] == 250


def test_stress_bound_error_names_the_densest_porosity_reached():
    with pytest.raises(ExpansionError) as info:
        expand_to_porosity(SMALL, 0.08, seed=3, progress=False, max_stress_pa=1.0e6)
    e = info.value
    assert e.target == 0.08
    assert 0.08 < e.porosity < 0.2
    assert e.stress_pa > 1.0e6
    message = str(e)
    assert f"nominal porosity {e.porosity:.4f}" in message
    assert f"{e.stress_pa / 1e6:.3g} MPa" in message
    assert "max_stress_pa" in message
    assert isinstance(e, ValueError)


@pytest.mark.parametrize("target", [0.20, 0.30])
def test_a_target_looser_than_jamming_gives_a_stress_free_sample(target):
    s = expand_to_porosity(SMALL, target, seed=1, progress=False)
    assert s.porosity == pytest.approx(target, abs=1e-12)
    # above the jamming porosity the disks do not fill the box: nothing carries load
    assert not s.jammed and s.equilibrium_reached
    assert s.mean_wall_stress_pa < 1e3
    assert "not jammed" in s.summary()


def test_the_dense_sample_is_jammed(small_sample):
    assert small_sample.jammed
    assert "not jammed" not in small_sample.summary()


def test_other_grading_explicit_diameters_friction_and_count():
    g = UniformByMass(0.5e-3, 1.5e-3)
    s = expand_to_porosity((0.0, 0.0, 0.015, 0.015), 0.16, g, seed=2, n_particles=150, friction=0.5, progress=False)
    assert s.n_particles == 150 and s.grading == g.name and s.friction == 0.5
    assert s.porosity == pytest.approx(0.16, abs=1e-12)
    d = g.sample(120, np.random.default_rng(9))
    t = expand_to_porosity((0.0, 0.0, 0.015, 0.015), 0.18, g, diameters=d, seed=2, progress=False)
    # one common factor scales the drawn diameters
    assert np.allclose(2 * t.radii / d, t.radius_factor, rtol=1e-14)


def test_unreached_equilibrium_warns():
    with pytest.warns(RuntimeWarning, match="equilibrium_ratio"):
        s = expand_to_porosity(SMALL, 0.12, seed=3, progress=False, max_equilibrium_steps=0)
    assert not s.equilibrium_reached


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"porosity": 1.2}, "porosity"),
        ({"porosity": 0.0}, "porosity"),
        ({"box": (0, 0, -1, 1)}, "box"),
        ({"friction": -0.1}, "friction"),
        ({"local_damping": 1.0}, "local_damping"),
        ({"initial_scale": 0.0}, "initial_scale"),
        ({"max_stress_pa": 0.0}, "max_stress_pa"),
        ({"threads": 0}, "threads"),
        ({"n_particles": 10, "diameters": [1e-3] * 10}, "n_particles"),
        ({"diameters": [1e-3, -1e-3]}, r"diameters\[1\]"),
        ({"box": (0, 0, 0.002, 0.002)}, "box"),
    ],
)
def test_bad_input_names_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        expand_to_porosity(**{"box": SMALL, "progress": False, **kwargs})


def test_a_grading_must_be_a_grading():
    with pytest.raises(TypeError, match="grading"):
        expand_to_porosity(SMALL, grading="sand", progress=False)


def test_placement_too_dense_is_reported():
    with pytest.raises(PlacementError):
        expand_to_porosity(SMALL, 0.12, seed=0, initial_scale=1.0, progress=False)


@pytest.mark.slow
def test_paper_scale_sample():
    """Table 1: 75 x 150 mm, 0.5-3 mm, nominal porosity 0.12 (about 3,500 disks)."""
    s = expand_to_porosity(seed=0, progress=False)
    assert s.n_particles == 3518
    assert s.porosity == pytest.approx(0.12, abs=1e-12)
    assert s.equilibrium_reached
    # docs/samples.md: 1-3.5 MPa locked in, mean overlaps 2-10% of the smallest radius
    assert 1.0e6 < s.mean_wall_stress_pa < 3.5e6
    assert 0.02 < s.mean_overlap_ratio < 0.12
    assert 0.12 < s.porosity_overlap_corrected < 0.13
    assert math.isfinite(s.coordination_number) and 3.8 < s.coordination_number < 4.6
