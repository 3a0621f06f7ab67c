"""Exact cases of the geometrical stability index (paper Sec. 5, docs/fabric.md)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from factories_analysis import grain_on_membrane, hex_lattice, ring, square_lattice

from grainlab.analysis import StabilityIndex, stability_index, stability_index_of_angles
from grainlab.analysis._util import NotComputedError
from grainlab.snapshot import ParticleKind, Snapshot


def brute_force(angles_deg) -> float:
    """Direct transcription of Eq. 9-11 with explicit loops (reference only)."""
    a = np.sort(np.mod(np.radians(angles_deg), 2 * np.pi))
    n = a.size
    if n < 2:
        return 1.0
    best = np.inf
    for k in range(n):
        total = 0.0
        for m in range(n):
            contact = a[(k + m) % n] + (2 * np.pi if k + m >= n else 0.0)
            stable = a[k] + 2 * np.pi * m / n
            diff = abs(contact - stable) % (2 * np.pi)
            total += min(diff, 2 * np.pi - diff)
        best = min(best, total)
    return best / (2 * np.pi)


@pytest.mark.parametrize(
    ("angles", "expected"),
    [
        ([0, 60, 120], 1 / 3),
        ([0, 90], 1 / 4),
        ([0, 180], 0.0),
        ([0, 60, 120, 180, 240, 300], 0.0),
        ([0, 120, 240], 0.0),
        ([10, 100, 190, 280], 0.0),
        ([0, 10], 170 / 360),
        ([], 1.0),
        ([37.0], 1.0),
    ],
)
def test_exact_values(angles, expected):
    assert stability_index_of_angles(angles, degrees=True) == pytest.approx(expected, abs=1e-12)


def test_worked_example_three_contacts():
    # contacts at 0, 100, 200 deg: ref 0 -> |100-120| + |200-240| = 60,
    # ref 100 -> |200-220| + |360-340| = 40, ref 200 -> |360-320| + |460-440| = 60
    assert stability_index_of_angles([0, 100, 200], degrees=True) == pytest.approx(
        40 / 360, abs=1e-12
    )


def test_matches_brute_force_on_random_sets(rng):
    n_sets = 400
    counts = rng.integers(0, 9, n_sets)
    owner = np.repeat(np.arange(n_sets), counts)
    angles = rng.uniform(-720, 720, owner.size)
    lam, got_counts = stability_index(owner, np.radians(angles), n_sets)
    np.testing.assert_array_equal(got_counts, counts)
    starts = np.cumsum(counts) - counts
    expected = [brute_force(angles[s : s + c]) for s, c in zip(starts, counts, strict=True)]
    np.testing.assert_allclose(lam, expected, atol=1e-12)


def test_three_equal_neighbours_never_exceed_one_third(rng):
    # three equal disks touching a fourth of the same size sit >= 60 deg apart
    trials = rng.uniform(0, 360, (200_000, 3))
    s = np.sort(trials, axis=1)
    gaps = np.diff(np.c_[s, s[:, :1] + 360], axis=1)
    valid = s[(gaps >= 60).all(axis=1)]
    assert len(valid) > 10_000
    owner = np.repeat(np.arange(len(valid)), 3)
    lam, _ = stability_index(owner, np.radians(valid.ravel()), len(valid))
    assert lam.max() <= 1 / 3 + 1e-12
    assert lam.max() > 0.32  # the bound is approached by the sampled arrangements
    # and reached by the arrangement 0, 60, 120 built from real disks
    snap = ring([0, 60, 120])
    assert StabilityIndex().compute(snap).stability_index[0] == pytest.approx(1 / 3, abs=1e-12)


def test_invariant_under_rotation_and_order(rng):
    n_sets = 300
    counts = rng.integers(2, 8, n_sets)
    owner = np.repeat(np.arange(n_sets), counts)
    angles = rng.uniform(0, 2 * np.pi, owner.size)
    lam, _ = stability_index(owner, angles, n_sets)
    shift = np.repeat(rng.uniform(0, 2 * np.pi, n_sets), counts)
    lam_rot, _ = stability_index(owner, angles + shift, n_sets)
    perm = rng.permutation(owner.size)
    lam_perm, _ = stability_index(owner[perm], angles[perm], n_sets)
    np.testing.assert_allclose(lam_rot, lam, atol=1e-12)
    np.testing.assert_array_equal(lam_perm, lam)
    assert lam.std() > 0.01  # the sets really differ


@pytest.mark.parametrize("make", [hex_lattice, square_lattice])
def test_lattices_are_perfectly_stable(make):
    snap = make()
    result = StabilityIndex().compute(snap)
    np.testing.assert_allclose(result.stability_index, 0.0, atol=1e-9)
    assert result.mean == pytest.approx(0.0, abs=1e-9)


def test_rotated_hex_lattice_still_zero():
    result = StabilityIndex().compute(hex_lattice(rotation_deg=13.0))
    np.testing.assert_allclose(result.stability_index, 0.0, atol=1e-9)


def test_snapshot_counts_both_ends_and_means():
    # particle 0 has contacts at 0 and 90 deg; 1 and 2 have one contact each; 3 none
    snap = Snapshot(
        [[0, 0], [1e-3, 0], [0, 1e-3], [5e-3, 5e-3]],
        np.full(4, 0.5e-3),
        contact_i=[0, 2],
        contact_j=[1, 0],
    )
    r = StabilityIndex().compute(snap)
    np.testing.assert_allclose(r.stability_index, [0.25, 1.0, 1.0, 1.0])
    np.testing.assert_array_equal(r.n_contacts, [2, 1, 1, 0])
    assert r.mean == pytest.approx(0.25)
    assert r.mean_all == pytest.approx((0.25 + 3) / 4)


def test_wall_contacts_count_by_default_and_can_be_excluded():
    # particle at the origin: neighbours at 0 and 120 deg, a wall below (270 deg)
    snap = Snapshot(
        [[0, 0], [1e-3, 0], [1e-3 * np.cos(2.0944), 1e-3 * np.sin(2.0944)]],
        np.full(3, 0.5e-3),
        contact_i=[0, 0, 0],
        contact_j=[1, 2, -1],  # -1 = wall 0
        contact_point=[[0.5e-3, 0], [0, 0], [0, -0.5e-3]],
    )
    with_wall = StabilityIndex().compute(snap).stability_index[0]
    without = StabilityIndex(include_boundary=False).compute(snap).stability_index[0]
    assert with_wall == pytest.approx(brute_force([0, np.degrees(2.0944), 270]), abs=1e-9)
    assert without == pytest.approx(brute_force([0, np.degrees(2.0944)]), abs=1e-9)
    assert with_wall != pytest.approx(without)


def test_membrane_particles_are_nan_and_their_contacts_are_boundary():
    snap = Snapshot(
        [[0, 0], [1e-3, 0], [-1e-3, 0]],
        np.full(3, 0.5e-3),
        kind=[ParticleKind.SOIL, ParticleKind.SOIL, ParticleKind.MEMBRANE],
        contact_i=[0, 0],
        contact_j=[1, 2],
    )
    r = StabilityIndex().compute(snap)
    assert np.isnan(r.stability_index[2])
    assert r.stability_index[0] == pytest.approx(0.0)  # 0 and 180 deg
    r2 = StabilityIndex(include_boundary=False).compute(snap)
    assert r2.stability_index[0] == 1.0  # only one contact left


def test_results_raise_before_compute():
    with pytest.raises(NotComputedError, match="compute"):
        StabilityIndex().stability_index  # noqa: B018


@pytest.mark.parametrize("n", range(2, 11))
def test_range_is_floor_n2_over_4_over_n(rng, n):
    # all n contacts at one angle give the largest lambda, floor(n^2/4)/n (1 at n = 4)
    bound = (n * n // 4) / n
    assert stability_index_of_angles(np.full(n, 37.0), degrees=True) == pytest.approx(
        bound, abs=1e-12
    )
    assert stability_index_of_angles([37.0] * (n - 1) + [37.5], degrees=True) < bound
    # no arrangement exceeds it: uniform angles, and angles crowded into 30 deg
    for spread in (2 * np.pi, np.radians(30.0)):
        owner = np.repeat(np.arange(20_000), n)
        lam, _ = stability_index(owner, rng.uniform(0, spread, owner.size), 20_000)
        assert lam.max() <= bound + 1e-12
    if n >= 5:  # crowded contacts really exceed 1
        lam, _ = stability_index(owner, rng.uniform(0, np.radians(5.0), owner.size), 20_000)
        assert lam.min() > 1.0


def test_membrane_chain_counts_as_one_contact_at_the_mean_direction():
    # seven membrane disks wrap the grain's left side, one grain touches it at 0 deg
    each = StabilityIndex(boundary="each").compute(grain_on_membrane())
    assert each.n_contacts[0] == 8
    assert each.stability_index[0] > 1.0  # eight contacts, seven crowded within 50 deg
    body = StabilityIndex().compute(grain_on_membrane())
    assert body.n_contacts[0] == 2
    # equal forces, symmetric chain: the mean direction is 180 deg, opposite the grain
    assert body.stability_index[0] == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_array_equal(body.n_contacts[1:], [1, 0, 0, 0, 0, 0, 0, 0])
    assert np.isnan(body.stability_index[2:]).all()


def test_mean_direction_is_force_weighted():
    forces = np.arange(1.0, 8.0)
    snap = grain_on_membrane(forces=forces)
    n = snap.contact_normals()[1:]
    mean = np.degrees(np.arctan2(forces @ n[:, 1], forces @ n[:, 0])) % 360
    assert abs(mean - 180.0) > 5.0  # the heavier disks pull the direction round
    lam = StabilityIndex().compute(snap).stability_index[0]
    # two contacts, at 0 deg and at the mean: lambda = |mean - 180| / 360
    assert lam == pytest.approx(abs(mean - 180.0) / 360.0, abs=1e-12)
    # without forces in the snapshot the plain mean direction is used: 180 deg again
    unforced = dataclasses.replace(snap, normal_force=None)
    assert StabilityIndex().compute(unforced).stability_index[0] == pytest.approx(0.0, abs=1e-12)


def test_chains_found_from_geometry_without_a_label():
    labelled = StabilityIndex(boundary="body").compute(grain_on_membrane(forces=np.arange(1.0, 8.0)))
    found = StabilityIndex().compute(grain_on_membrane(forces=np.arange(1.0, 8.0), labelled=False))
    np.testing.assert_array_equal(found.n_contacts, labelled.n_contacts)
    np.testing.assert_allclose(found.stability_index, labelled.stability_index, atol=1e-12)
    # two labels on one geometric chain: two bodies, two contacts on that side
    snap = grain_on_membrane()
    split = snap.with_boundary_bodies(np.r_[-1, -1, 0, 0, 0, 1, 1, 1, 1])
    assert StabilityIndex().compute(split).n_contacts[0] == 3


def test_walls_are_bodies_too():
    # a grain touching wall 0 twice (a corner of one polyline wall) and wall 1 once
    snap = Snapshot(
        [[0.0, 0.0]],
        [1e-3],
        contact_i=[0, 0, 0],
        contact_j=[-1, -1, -2],
        contact_normal=[[0.0, -1.0], [-1.0, 0.0], [1.0, 0.0]],
        normal_force=[1.0, 1.0, 2.0],
    )
    each = StabilityIndex(boundary="each").compute(snap)
    body = StabilityIndex().compute(snap)
    assert each.n_contacts[0] == 3 and body.n_contacts[0] == 2
    # wall 0 at its mean direction 225 deg, wall 1 at 0 deg: 135 deg apart, 45 deg off
    assert body.stability_index[0] == pytest.approx(45.0 / 360.0, abs=1e-12)
    assert each.stability_index[0] == pytest.approx(brute_force([270, 180, 0]), abs=1e-12)
    np.testing.assert_array_equal(snap.contact_counts(), [2])
    np.testing.assert_array_equal(snap.contact_counts(boundary="each"), [3])


def test_boundary_option_is_checked():
    with pytest.raises(ValueError, match="boundary"):
        StabilityIndex(boundary="chain")


@pytest.mark.slow
def test_membrane_grains_of_a_quick_biaxial_run(quick_biaxial_run):
    from grainlab.io.hdf5 import read_results

    results = read_results(quick_biaxial_run / "run.h5")
    for name in results.snapshot_names:
        snap = results.snapshot(name)
        membrane = ~snap.is_sample
        # the protocol labels its two chains; the label agrees with the geometry
        np.testing.assert_array_equal(np.unique(snap.particle_fields["body"][membrane]), [0, 1])
        unlabelled = dataclasses.replace(
            snap, particle_fields={k: v for k, v in snap.particle_fields.items() if k != "body"}
        )
        np.testing.assert_array_equal(unlabelled.boundary_bodies(), snap.boundary_bodies())
        ci, cj = np.asarray(snap.contact_i), np.asarray(snap.contact_j)
        pp = cj >= 0
        on_membrane = np.zeros(snap.n_particles, bool)
        on_membrane[ci[pp & membrane[np.where(pp, cj, 0)]]] = True
        on_membrane[cj[pp & membrane[ci]]] = True
        on_membrane &= snap.is_sample
        body = StabilityIndex().compute(snap)
        each = StabilityIndex(boundary="each").compute(snap)
        grains = snap.is_sample
        # counted disk by disk the membrane's grains exceed 1; counted as one body none does
        assert (each.stability_index[grains] > 1).sum() > 10
        assert np.nanmax(body.stability_index[grains]) <= 1.0
        two = grains & (body.n_contacts >= 2)
        assert np.nanmax(body.stability_index[two]) < 0.6
        # and the membrane's grains are about as stable as the others
        inside = np.nanmean(body.stability_index[two & ~on_membrane])
        assert np.nanmean(body.stability_index[two & on_membrane]) == pytest.approx(inside, abs=0.05)
        np.testing.assert_array_equal(body.n_contacts[grains], snap.contact_counts()[grains])
