"""Love-Weber stress of grains, regions and sets of contacts on snapshots (docs/fabric.md, "Stress")."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import hex_lattice, jittered_packing

from grainlab.analysis.stress import (
    GrainStress,
    LoveWeberStress,
    branch_vectors,
    contact_forces_on_i,
    contact_points,
    contact_stress,
    grain_stress,
    love_weber_stress,
)
from grainlab.snapshot import Snapshot


def loaded(snap: Snapshot, seed: int = 0, shear: bool = True) -> Snapshot:
    """``snap`` with random normal (and shear) forces on its contacts."""
    rng = np.random.default_rng(seed)
    k = snap.n_contacts
    return snap.with_contacts(
        snap.contact_i,
        snap.contact_j,
        normal_force=rng.uniform(0.1, 2.0, k),
        shear_force=rng.uniform(-0.5, 0.5, k) if shear else None,
    )


def test_two_disks_pressed_together():
    snap = Snapshot([[0, 0], [3, 0]], [1.0, 2.0], contact_i=[0], contact_j=[1], normal_force=[5.0])
    grains = GrainStress().compute(snap)
    # grain 0: lever 1 m, grain 1: lever 2 m, 5 N along x over pi r^2
    np.testing.assert_allclose(grains.major, [5.0 / np.pi, 5.0 * 2 / (np.pi * 4)])
    np.testing.assert_allclose(grains.minor, 0.0, atol=1e-15)
    np.testing.assert_allclose(grains.major_direction, 0.0)
    np.testing.assert_allclose(contact_points(snap), [[1.0, 0.0]])


def test_contact_point_splits_the_overlap():
    snap = Snapshot([[0, 0], [2.5, 0]], [1.0, 2.0], contact_i=[0], contact_j=[1], normal_force=[1.0])
    np.testing.assert_allclose(contact_points(snap), [[1.0 - 0.25, 0.0]])  # overlap 0.5


def test_shear_force_direction():
    # normal +x, t = +y: the shear force acts on i along +y, on j along -y
    snap = Snapshot([[0, 0], [2, 0]], [1.0, 1.0], contact_i=[0], contact_j=[1],
                    normal_force=[2.0], shear_force=[0.5])
    np.testing.assert_allclose(contact_forces_on_i(snap), [[-2.0, 0.5]])
    s = contact_stress(snap, area=1.0)
    np.testing.assert_allclose(s, [[4.0, -0.5], [-0.5, 0.0]])


@pytest.mark.parametrize("periodic", [False, True])
def test_grain_stresses_sum_to_the_contact_stress(periodic):
    """sum_p V_p sigma_p = A sigma (every contact, even out of equilibrium, periodic
    contacts measured with their minimum image)."""
    snap = loaded(hex_lattice(6, 6) if periodic else jittered_packing(8, 8, seed=2), seed=3)
    if periodic:  # a disordered periodic state: jitter the lattice, keep its contacts
        rng = np.random.default_rng(5)
        snap = Snapshot(snap.positions + rng.normal(0, 2e-5, snap.positions.shape), snap.radii,
                        contact_i=snap.contact_i, contact_j=snap.contact_j,
                        normal_force=snap.normal_force, shear_force=snap.shear_force,
                        box=snap.box, periodic=snap.periodic)
    v = np.pi * snap.radii**2
    total = np.einsum("p,pij->ij", v, grain_stress(snap))
    np.testing.assert_allclose(total, contact_stress(snap, area=1.0), rtol=1e-12, atol=1e-18)


def test_region_stress_is_the_array_function_on_a_snapshot():
    snap = loaded(jittered_packing(8, 8, seed=4), seed=6)
    region = snap.positions[:, 0] < np.median(snap.positions[:, 0])
    f_i = contact_forces_on_i(snap)
    expected = love_weber_stress(snap.positions, snap.contact_i, snap.contact_j,
                                 contact_points(snap), -f_i, 2.0e-5, region)
    measured = LoveWeberStress(area=2.0e-5).compute(snap, region)
    np.testing.assert_allclose(measured.stress, expected, rtol=1e-12)
    assert measured.n_particles == int(region.sum())


def test_region_stress_of_a_uniformly_loaded_periodic_lattice():
    """Every contact of a hexagonal lattice carrying f: sigma = (N_c d f / A) * I/2."""
    snap = hex_lattice(6, 6)
    f = 2.0
    snap = snap.with_contacts(snap.contact_i, snap.contact_j, normal_force=np.full(snap.n_contacts, f))
    area = float(np.prod(np.diff(snap.box, axis=1)))
    expected = snap.n_contacts * 1e-3 * f / area / 2.0
    whole = LoveWeberStress().compute(snap)
    np.testing.assert_allclose(whole.stress, expected * np.eye(2), rtol=1e-12, atol=1e-9)
    assert whole.region_area == pytest.approx(area)
    # a half of it, over the half's power cells: the same stress
    half = snap.positions[:, 1] < snap.box[1].mean()
    np.testing.assert_allclose(LoveWeberStress().compute(snap, half).stress,
                               expected * np.eye(2), rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(GrainStress(area=np.full(snap.n_particles, area / snap.n_particles))
                               .compute(snap).major, expected, rtol=1e-12)


def test_branch_vectors_use_the_minimum_image():
    snap = hex_lattice(4, 4)
    length = np.hypot(*branch_vectors(snap).T)
    np.testing.assert_allclose(length, 1e-3, rtol=1e-9)


def test_needs_forces():
    with pytest.raises(ValueError, match="normal_force"):
        GrainStress().compute(hex_lattice(4, 4))
