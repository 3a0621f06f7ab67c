"""Displacements, local deformation gradient, D2min and the shear invariant."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import jittered_packing

from grainlab.analysis import LocalStrain, match_ids
from grainlab.snapshot import Snapshot


@pytest.fixture
def packing():
    return jittered_packing(20, 20, seed=4)


def deformed(ref: Snapshot, F, shift=(0.0, 0.0), **kw) -> Snapshot:
    return Snapshot(ref.positions @ np.asarray(F).T + shift, ref.radii, ids=ref.ids, **kw)


def test_affine_field_is_recovered_exactly(packing):
    F = np.array([[0.99, 0.004], [-0.002, 1.006]])
    cur = deformed(packing, F, shift=(3e-4, -1e-4))
    s = LocalStrain().compute(packing, cur)
    ok = np.isfinite(s.shear_strain)
    assert ok.mean() > 0.95
    np.testing.assert_allclose(
        s.deformation_gradient[ok], np.broadcast_to(F, (ok.sum(), 2, 2)), atol=1e-12
    )
    np.testing.assert_allclose(s.d2min[ok], 0.0, atol=1e-25)
    eps = np.eye(2) - 0.5 * (F + F.T)  # compression positive
    np.testing.assert_allclose(s.strain[ok], np.broadcast_to(eps, (ok.sum(), 2, 2)), atol=1e-12)
    gamma = np.hypot(eps[0, 0] - eps[1, 1], 2 * eps[0, 1])
    np.testing.assert_allclose(s.shear_strain[ok], gamma, rtol=1e-9)
    np.testing.assert_allclose(s.volumetric_strain[ok], eps[0, 0] + eps[1, 1], rtol=1e-9)
    np.testing.assert_allclose(s.excess_shear_strain[ok], 0.0, atol=1e-12)
    np.testing.assert_allclose(s.displacement, cur.positions - packing.positions, atol=1e-18)


def test_simple_shear_gives_gamma_and_compression_is_positive(packing):
    s = LocalStrain().compute(packing, deformed(packing, [[1.0, 0.03], [0.0, 1.0]]))
    assert np.nanmedian(s.shear_strain) == pytest.approx(0.03, rel=1e-9)
    c = LocalStrain().compute(packing, deformed(packing, 0.99 * np.eye(2)))
    assert np.nanmedian(c.volumetric_strain) == pytest.approx(0.02, rel=1e-9)
    g = LocalStrain(strain="green").compute(packing, deformed(packing, 0.99 * np.eye(2)))
    assert np.nanmedian(g.volumetric_strain) == pytest.approx(1 - 0.99**2, rel=1e-9)


def test_non_affine_particle_has_d2min(packing):
    cur_pos = packing.positions.copy()
    k = 210
    cur_pos[k] += [2e-5, 0.0]
    s = LocalStrain(neighbours="contacts").compute(packing, Snapshot(cur_pos, packing.radii))
    d2 = s.d2min
    top = np.argsort(np.nan_to_num(d2))[-1]
    neighbours = set(packing.contact_j[packing.contact_i == k]) | set(
        packing.contact_i[packing.contact_j == k]
    )
    assert top == k or top in neighbours
    far = np.hypot(*(packing.positions - packing.positions[k]).T) > 4e-3
    assert np.nanmax(d2) > 1e-10  # about n_contacts * (2e-5 m)^2
    assert np.nanmax(d2[far]) < 1e-9 * np.nanmax(d2)  # round-off only away from the defect


def test_matching_by_id_with_shuffled_and_missing_particles(packing, rng):
    F = np.array([[1.0, 0.01], [0.0, 1.0]])
    full = deformed(packing, F, rotations=np.linspace(0, 1, packing.n_particles))
    ref = Snapshot(
        packing.positions, packing.radii, ids=packing.ids, rotations=np.zeros(packing.n_particles)
    )
    order = rng.permutation(packing.n_particles)[:-5]  # shuffle and drop five particles
    cur = Snapshot(
        full.positions[order],
        full.radii[order],
        ids=full.ids[order],
        rotations=full.rotations[order],
    )
    extra = Snapshot(
        np.vstack([cur.positions, [[1.0, 1.0]]]),
        np.r_[cur.radii, 1e-3],
        ids=np.r_[cur.ids, 10_000],
        rotations=np.r_[cur.rotations, 0.0],
    )
    np.testing.assert_array_equal(match_ids(ref, extra)[:-1], order)
    assert match_ids(ref, extra)[-1] == -1
    s = LocalStrain().compute(ref, extra)
    np.testing.assert_allclose(
        s.displacement[:-1], cur.positions - packing.positions[order], atol=1e-18
    )
    np.testing.assert_allclose(s.rotation[:-1], full.rotations[order])
    assert np.isnan(s.displacement[-1]).all() and np.isnan(s.shear_strain[-1])
    assert np.nanmedian(s.shear_strain) == pytest.approx(0.01, rel=1e-9)


def test_periodic_displacement_uses_minimum_image():
    box = [[0.0, 10e-3], [0.0, 10e-3]]
    ref = Snapshot([[9.9e-3, 5e-3], [5e-3, 5e-3]], [0.5e-3] * 2, box=box, periodic=(True, True))
    cur = Snapshot([[0.1e-3, 5e-3], [5e-3, 5e-3]], [0.5e-3] * 2, box=box, periodic=(True, True))
    s = LocalStrain().compute(ref, cur)
    np.testing.assert_allclose(s.displacement[0], [0.2e-3, 0.0], atol=1e-15)
    assert np.isnan(s.rotation).all()  # no rotations in the snapshots


def test_isolated_particles_get_nan_and_parameters_are_validated():
    ref = Snapshot([[0, 0], [1.0, 0]], [1e-3, 1e-3])
    s = LocalStrain(cutoff=0.1).compute(ref, ref)
    assert np.isnan(s.shear_strain).all() and np.isnan(s.d2min).all()
    np.testing.assert_array_equal(s.n_neighbours, [0, 0])
    for bad in (dict(neighbours="knn"), dict(strain="log"), dict(cutoff=-1.0)):
        with pytest.raises(ValueError):
            LocalStrain(**bad)
