"""Exact cases of the geometrical stability index (paper Sec. 5, DESIGN.md §4)."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import hex_lattice, ring, square_lattice

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
