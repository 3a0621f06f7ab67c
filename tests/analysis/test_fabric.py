"""Coordination numbers, contact-normal distribution and anisotropy (Eq. 6-8)."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import grain_on_membrane, hex_lattice, square_lattice

from grainlab.analysis import (
    EDGE_TOLERANCE_RAD,
    ContactAnisotropy,
    CoordinationNumber,
    angular_histogram,
    anisotropy_eq7,
    anisotropy_fourier,
    fabric_tensor,
    rattlers,
)
from grainlab.snapshot import ParticleKind, Snapshot


def sample_eq6(rng, n, a, theta_a):
    """Angles drawn from E(theta) = (1 + a cos 2(theta - theta_a)) / 2pi by rejection."""
    out = np.empty(0)
    while out.size < n:
        t = rng.uniform(0, 2 * np.pi, 4 * n)
        keep = rng.uniform(0, 1 + a, t.size) < 1 + a * np.cos(2 * (t - theta_a))
        out = np.r_[out, t[keep]]
    return out[:n]


def snapshot_with_normals(angles, rng, forces=None):
    """Contacts with the given normal angles between random pairs of 500 particles."""
    n = 500
    i = rng.integers(0, n, angles.size)
    j = (i + rng.integers(1, n, angles.size)) % n
    return Snapshot(
        rng.uniform(0, 0.1, (n, 2)),
        np.full(n, 1e-3),
        contact_i=i,
        contact_j=j,
        contact_normal=np.c_[np.cos(angles), np.sin(angles)],
        normal_force=forces,
    )


def test_hex_lattice_z6_and_isotropic():
    snap = hex_lattice(rotation_deg=7.0)  # away from bin edges
    z = CoordinationNumber().compute(snap)
    assert z.coordination_number == 6.0
    assert z.mechanical_coordination_number == 6.0
    assert not z.rattlers.any()
    np.testing.assert_allclose(z.count_distribution, [0, 0, 0, 0, 0, 0, 1.0])
    an = ContactAnisotropy().compute(snap)
    assert an.anisotropy == pytest.approx(0.0, abs=1e-12)
    assert an.anisotropy_binned == pytest.approx(0.0, abs=1e-12)
    assert an.anisotropy_fourier == an.anisotropy
    np.testing.assert_allclose(an.fabric_tensor, 0.5 * np.eye(2), atol=1e-12)
    # each contact counted in both directions: 6 directions x 64 particles / 2 x 2
    assert an.histogram.sum() == 2 * snap.n_contacts == 6 * 64


#: Rotations (deg) of the lattices: a fine scan, the multiples of 10 deg that put
#: contacts exactly on the 20 deg bin edges (or centres), and odd ones.
ROTATIONS = sorted({*np.arange(0.0, 90.0, 0.5).tolist(), 1e-12, 1e-7, 13.37, 59.999, 100.0, 170.0, 345.0})


def test_hexagon_is_isotropic_at_every_rotation_binned_or_not():
    # six directions 60 deg apart: no second harmonic, so Eq. 6 fits a = 0. Bins of
    # 20 deg put all six at the same place in their bins (60 deg = 3 bins), so Eq. 7
    # gives 0 too, once contacts on a bin edge count half to each side
    worst_exact = worst_binned = 0.0
    for deg in ROTATIONS:
        an = ContactAnisotropy().compute(hex_lattice(rotation_deg=deg))
        worst_exact = max(worst_exact, an.anisotropy)
        worst_binned = max(worst_binned, an.anisotropy_binned)
        np.testing.assert_allclose(an.fabric_tensor, 0.5 * np.eye(2), atol=1e-12)
    assert worst_exact < 1e-12
    assert worst_binned < 1e-12
    # binned by floor alone, contacts on the edges fall into one bin or the other by round-off
    on_edges = ContactAnisotropy(edge_tolerance=0.0).compute(hex_lattice(rotation_deg=20.0))
    assert on_edges.anisotropy_binned > 0.05


def test_square_lattice_exact_zero_and_binned_closed_forms():
    # four directions 90 deg apart have no second harmonic either: Eq. 6 fits a = 0 (the
    # lattice's anisotropy is in the fourth harmonic, which Eq. 6 does not have)
    dt = np.radians(20.0)
    generic = np.sin(dt) / dt * 2 * np.sin(dt / 2)  # 0.340: x, y half a bin apart (90 = 4.5 bins)
    on_edge = np.sin(dt) / dt * (1 - np.cos(dt))  # 0.059: one of x, y on an edge, split
    for deg in ROTATIONS:
        snap = square_lattice(rotation_deg=deg)
        an = ContactAnisotropy().compute(snap)
        assert an.anisotropy < 1e-12
        np.testing.assert_allclose(an.fabric_tensor, 0.5 * np.eye(2), atol=1e-12)
        theta = snap.contact_angles()
        assert abs(np.exp(4j * theta).mean()) == pytest.approx(1.0, abs=1e-12)
        edge = abs(np.radians((deg + 5) % 10 - 5)) <= EDGE_TOLERANCE_RAD  # 1e-12 deg is, 1e-7 is not
        expected = on_edge if edge else generic
        assert an.anisotropy_binned == pytest.approx(expected, abs=1e-12), deg
        # with 10 deg bins (90 = 9 bins) Eq. 7 sees no anisotropy at any rotation
        assert ContactAnisotropy(bins=36).compute(snap).anisotropy_binned < 1e-12


def test_square_lattice_z4():
    assert CoordinationNumber().compute(square_lattice()).coordination_number == 4.0


def test_rattlers_removed_iteratively():
    # triangle 0-1-2 plus a dangling chain 2-3-4: 4 then 3 are removed
    i = np.array([0, 1, 2, 2, 3])
    j = np.array([1, 2, 0, 3, 4])
    np.testing.assert_array_equal(rattlers(i, j, 5), [False, False, False, True, True])
    np.testing.assert_array_equal(rattlers(i, j, 5, min_contacts=3), [True] * 5)
    snap = Snapshot(np.c_[np.arange(5.0), np.zeros(5)], np.full(5, 0.6), contact_i=i, contact_j=j)
    z = CoordinationNumber().compute(snap)
    assert z.coordination_number == pytest.approx(2.0)
    assert z.mechanical_coordination_number == pytest.approx(2.0)  # 3 contacts, 3 particles
    np.testing.assert_allclose(z.count_distribution, [0, 0.2, 0.6, 0.2])  # 4 | 0,1,3 | 2
    z3 = CoordinationNumber(min_contacts=3).compute(snap)
    assert np.isnan(z3.mechanical_coordination_number)


def test_rattler_next_to_a_rigid_core():
    # square lattice (Z = 4) plus one extra particle touching a single lattice particle
    sq = square_lattice(4, 4)
    pos = np.vstack([sq.positions, [[-1e-3, 0.0]]])
    i = np.r_[sq.contact_i, 16]
    j = np.r_[sq.contact_j, 0]
    snap = Snapshot(pos, np.full(17, 0.5e-3), contact_i=i, contact_j=j)
    z = CoordinationNumber().compute(snap)
    assert z.coordination_number == pytest.approx(2 * 33 / 17)
    assert z.mechanical_coordination_number == pytest.approx(4.0)
    assert z.rattlers.sum() == 1 and z.rattlers[16]


def test_thornton_rattlers_need_the_second_round():
    """Thornton's rule (fewer than 2 contacts), applied until nothing changes: on a square
    lattice core (grains 0-15), grain 16 touches only grains 17 and 18, which touch
    nothing else. Round 1 removes 17 and 18 (one contact each), which leaves 16 with
    none: round 2 removes it. One round would keep 16 (two contacts) and give Z_m =
    2 (32 + 2) / 17; a wall contact counts as one when boundary contacts are included."""
    sq = square_lattice(4, 4)
    d = 1e-3
    pos = np.vstack([sq.positions, [[-2 * d, 0.0], [-2 * d, d], [-2 * d, -d]]])
    i = np.r_[sq.contact_i, 16, 16]
    j = np.r_[sq.contact_j, 17, 18]
    np.testing.assert_array_equal(rattlers(i, j, 19), [False] * 16 + [True] * 3)
    snap = Snapshot(pos, np.full(19, 0.5e-3), contact_i=i, contact_j=j)
    z = CoordinationNumber().compute(snap)
    np.testing.assert_array_equal(np.flatnonzero(z.rattlers), [16, 17, 18])
    assert z.mechanical_coordination_number == pytest.approx(4.0)  # 32 contacts, 16 grains
    # grain 17 also on a wall: 18 goes in round 1, then 16 (left with 17 only), then 17
    # (left with the wall only); with 16 on the wall too, only 18 is a rattler
    def walls(*grains):
        k = len(grains)
        return Snapshot(pos, np.full(19, 0.5e-3), contact_i=np.r_[i, grains],
                        contact_j=np.r_[j, [-1] * k],
                        contact_point=np.vstack([np.zeros((i.size, 2)), pos[list(grains)] - [0.5 * d, 0]]))

    one = CoordinationNumber(include_boundary=True).compute(walls(17))
    np.testing.assert_array_equal(np.flatnonzero(one.rattlers), [16, 17, 18])
    two = CoordinationNumber(include_boundary=True).compute(walls(16, 17))
    np.testing.assert_array_equal(np.flatnonzero(two.rattlers), [18])
    assert two.mechanical_coordination_number == pytest.approx((2 * 32 + 2 + 2) / 18)
    # without boundary contacts the walls do not hold them
    assert np.flatnonzero(CoordinationNumber().compute(walls(16, 17)).rattlers).tolist() == [16, 17, 18]


def test_boundary_contacts_excluded_from_z_by_default():
    snap = Snapshot(
        [[0, 0], [1e-3, 0], [2e-3, 0]],
        np.full(3, 0.5e-3),
        kind=[0, 0, ParticleKind.MEMBRANE],
        contact_i=[0, 1, 0],
        contact_j=[1, 2, -1],
        contact_normal=[[1, 0], [1, 0], [-1, 0]],
    )
    z = CoordinationNumber().compute(snap)
    assert z.n_particles == 2  # the membrane disk is not part of the sample
    assert z.coordination_number == pytest.approx(1.0)
    zb = CoordinationNumber(include_boundary=True).compute(snap)
    assert zb.coordination_number == pytest.approx((2 + 2) / 2)


def test_boundary_bodies_count_once_when_boundary_contacts_are_included():
    # grain 0 touches seven disks of one membrane chain and grain 1
    snap = grain_on_membrane()
    assert CoordinationNumber().compute(snap).coordination_number == 1.0  # boundary excluded
    body = CoordinationNumber(include_boundary=True).compute(snap)
    each = CoordinationNumber(include_boundary=True, boundary="each").compute(snap)
    np.testing.assert_array_equal(body.n_contacts[:2], [2, 1])
    np.testing.assert_array_equal(each.n_contacts[:2], [8, 1])
    assert body.coordination_number == pytest.approx(1.5)
    assert each.coordination_number == pytest.approx(4.5)
    # grain 1 is a rattler; without it grain 0 keeps one contact (the chain) or seven
    np.testing.assert_array_equal(body.rattlers[:2], [True, True])
    np.testing.assert_array_equal(each.rattlers[:2], [False, True])
    assert each.mechanical_coordination_number == pytest.approx(7.0)
    with pytest.raises(ValueError, match="boundary"):
        CoordinationNumber(boundary="disk")


@pytest.mark.parametrize(("a", "theta_deg"), [(0.0, 0.0), (0.2, 30.0), (0.5, 120.0)])
def test_recovers_eq6_parameters(rng, a, theta_deg):
    n = 40_000
    angles = sample_eq6(rng, n, a, np.radians(theta_deg))
    an = ContactAnisotropy(bins=18).compute(snapshot_with_normals(angles, rng))
    sigma = np.sqrt(2.0 / n)  # standard error of a from n contacts
    assert an.anisotropy_fourier == pytest.approx(a, abs=4 * sigma)
    assert an.anisotropy == an.anisotropy_fourier
    # Eq. 7 as printed carries the binning factor (sin dt / dt)^2 = 0.960 at 18 bins
    dt = np.radians(20.0)
    assert an.anisotropy_binned == pytest.approx(a * (np.sin(dt) / dt) ** 2, abs=4 * sigma)
    # the same contacts give the same binned value with and without the edge rule
    plain = ContactAnisotropy(bins=18, edge_tolerance=0.0).compute(snapshot_with_normals(angles, rng))
    assert plain.anisotropy_binned == pytest.approx(an.anisotropy_binned, abs=1e-6)
    # the fabric tensor gives the same a as the Fourier estimate
    w = np.linalg.eigvalsh(an.fabric_tensor)
    assert 2 * (w[1] - w[0]) == pytest.approx(an.anisotropy_fourier, rel=1e-9)
    if a > 0:
        tol = np.degrees(4 * sigma / (2 * a))
        for theta in (an.direction, an.direction_binned):
            diff = (np.degrees(theta) - theta_deg + 90) % 180 - 90
            assert abs(diff) < tol


def test_eq7_single_direction_closed_form():
    # all contacts along the centre of bin 3 of 18: a = 2 sin(dt)/dt, theta_a = that centre
    dt = 2 * np.pi / 18
    centre = 3.5 * dt
    values, edges = angular_histogram(np.full(10, centre), 18)
    assert values[3] == 10 and values[12] == 10 and values.sum() == 20
    a, theta = anisotropy_eq7(values)
    assert a == pytest.approx(2 * np.sin(dt) / dt, rel=1e-12)
    assert theta == pytest.approx(centre, abs=1e-12)
    np.testing.assert_allclose(edges, np.linspace(0, 2 * np.pi, 19))


def test_force_weighted_anisotropy():
    # horizontal contacts carry 2 N, vertical ones 1 N: a_n = 2 (2n - n) / 3n = 2/3
    ang = np.radians(np.r_[np.full(50, 5.0), np.full(50, 95.0)])
    forces = np.r_[np.full(50, 2.0), np.full(50, 1.0)]
    snap = snapshot_with_normals(ang, np.random.default_rng(1), forces)
    an = ContactAnisotropy(weight="normal_force").compute(snap)
    assert an.anisotropy_fourier == pytest.approx(2 / 3, rel=1e-12)
    assert np.degrees(an.direction) == pytest.approx(5.0, abs=1e-9)
    assert an.total == pytest.approx(150.0)
    assert an.histogram.sum() == pytest.approx(300.0)
    # counts alone are isotropic in the second harmonic sense: equal numbers at 5 and 95 deg
    assert ContactAnisotropy().compute(snap).anisotropy_fourier == pytest.approx(0.0, abs=1e-12)


def test_force_anisotropy_needs_forces(rng):
    snap = snapshot_with_normals(np.zeros(3), rng)
    with pytest.raises(ValueError, match="normal_force"):
        ContactAnisotropy(weight="normal_force").compute(snap)


def test_functions_validate_and_handle_empty():
    with pytest.raises(ValueError, match="bins"):
        angular_histogram([0.1], bins=1)
    assert np.isnan(anisotropy_eq7(np.zeros(18))[0])
    assert np.isnan(anisotropy_fourier([])[0])
    assert np.isnan(fabric_tensor(np.zeros((0, 2)))).all()
    phi = fabric_tensor([[1, 0], [0, 1], [1, 0]], weights=[1, 2, 1])
    np.testing.assert_allclose(phi, [[0.5, 0], [0, 0.5]])


def test_fabric_summary_headline_is_exact_and_binned_beside_it():
    from grainlab.analysis import fabric_summary

    hexagon = fabric_summary(hex_lattice(rotation_deg=20.0))  # contacts on bin edges
    assert hexagon["anisotropy"] < 1e-12 and hexagon["anisotropy_binned"] < 1e-12
    square = fabric_summary(square_lattice(rotation_deg=5.0))
    assert square["anisotropy"] < 1e-12
    assert square["anisotropy_fourier"] == square["anisotropy"]
    assert square["anisotropy_binned"] == pytest.approx(0.3403, abs=1e-4)
    # contacts found from the geometry carry no force: no force anisotropy either way
    assert np.isnan(square["force_anisotropy"]) and np.isnan(square["force_anisotropy_binned"])
