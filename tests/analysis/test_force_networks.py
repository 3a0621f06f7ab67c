"""Strong and weak networks, Satake's fabric tensor and the stress-force-fabric
relation on constructed snapshots with known answers (docs/fabric.md)."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import hex_lattice, jittered_packing, ring, square_lattice

from grainlab.analysis import analyze_snapshot
from grainlab.analysis.networks import ForceNetworks
from grainlab.analysis.stress import contact_stress
from grainlab.analysis.stress_fabric import FabricTensor, StressForceFabric, force_anisotropies
from grainlab.snapshot import Snapshot


def with_forces(snap: Snapshot, normal, shear=None) -> Snapshot:
    return snap.with_contacts(
        snap.contact_i, snap.contact_j, contact_normal=snap.contact_normal,
        normal_force=normal, shear_force=shear,
    )


def hex_three_and_one():
    """Hexagonal lattice (contacts at 0, 60, 120 deg): 3 N on the horizontal contacts, 1 N
    on the others."""
    snap = hex_lattice(8, 8)
    flat = np.abs(snap.contact_normals()[:, 0]) > 0.99
    return with_forces(snap, np.where(flat, 3.0, 1.0)), flat


def test_strong_and_weak_networks_of_a_constructed_lattice():
    snap, flat = hex_three_and_one()
    nets = ForceNetworks().compute(snap)
    assert nets.mean_normal_force == pytest.approx(5.0 / 3.0)
    np.testing.assert_array_equal(nets.strong.contacts, flat)
    np.testing.assert_array_equal(nets.weak.contacts, ~flat)
    # strong: every normal at 0 deg; weak: 60 and 120 deg, a = 1 along 90 deg
    assert nets.strong.anisotropies.a == pytest.approx(2.0)
    assert nets.strong.anisotropies.theta_a == pytest.approx(0.0, abs=1e-12)
    assert nets.weak.anisotropies.a == pytest.approx(1.0)
    assert nets.weak.anisotropies.theta_a == pytest.approx(np.pi / 2)
    # two or one directions cannot give a_n; the whole (three directions) can: a_n = 0.8
    assert np.isnan(nets.strong.anisotropies.a_n) and np.isnan(nets.weak.anisotropies.a_n)
    assert nets.whole.anisotropies.a == pytest.approx(0.0, abs=1e-12)
    assert nets.whole.anisotropies.a_n == pytest.approx(0.8)
    assert nets.whole.anisotropies.f0 == pytest.approx(5.0 / 3.0)
    # stresses: strong N/3 * 3 * d * diag(1, 0), weak N/3 * d * diag(1/2, 3/2), over A
    area = float(np.prod(np.diff(snap.box, axis=1)))
    unit = snap.n_contacts / 3 * 1e-3 / area
    np.testing.assert_allclose(nets.strong.stress, unit * np.diag([3.0, 0.0]), atol=1e-9 * unit)
    np.testing.assert_allclose(nets.weak.stress, unit * np.diag([0.5, 1.5]), atol=1e-9 * unit)
    assert nets.strong.deviatoric_share == pytest.approx(1.5)
    assert nets.weak.deviatoric_share == pytest.approx(-0.5)
    assert nets.strong.mean_stress_share == pytest.approx(0.6)
    assert nets.weak.mean_stress_share == pytest.approx(0.4)
    assert nets.in_strong_network.all()
    assert nets.summary()["strong_deviatoric_share"] == pytest.approx(1.5)


def test_the_networks_add_up_to_the_whole():
    snap = jittered_packing(12, 12, seed=7)
    rng = np.random.default_rng(1)
    snap = with_forces(snap, rng.exponential(1.0, snap.n_contacts), rng.normal(0, 0.2, snap.n_contacts))
    nets = ForceNetworks().compute(snap)
    np.testing.assert_allclose(nets.strong.stress + nets.weak.stress, nets.whole.stress, rtol=1e-12)
    np.testing.assert_allclose(nets.whole.stress, contact_stress(snap), rtol=1e-12)
    assert nets.strong.deviatoric_share + nets.weak.deviatoric_share == pytest.approx(1.0)
    assert nets.strong.mean_stress_share + nets.weak.mean_stress_share == pytest.approx(1.0)
    assert nets.strong.n_contacts + nets.weak.n_contacts == snap.n_contacts
    assert nets.whole.deviatoric_share == pytest.approx(1.0)
    ft = FabricTensor().compute(snap)
    np.testing.assert_allclose(ft.strong_part + ft.weak_part, ft.tensor, rtol=1e-12)
    assert np.trace(ft.strong_part) == pytest.approx(nets.strong.n_contacts / snap.n_contacts)


def test_networks_leave_out_boundary_contacts_by_default():
    snap = Snapshot([[0, 0], [1e-3, 0], [2e-3, 0]], np.full(3, 0.5e-3),
                    contact_i=[0, 1, 2], contact_j=[1, 2, -1], normal_force=[1.0, 3.0, 9.0],
                    contact_point=[[0.5e-3, 0], [1.5e-3, 0], [2.5e-3, 0]])
    nets = ForceNetworks().compute(snap)
    assert nets.mean_normal_force == pytest.approx(2.0)
    np.testing.assert_array_equal(nets.strong.contacts, [False, True, False])
    assert ForceNetworks(include_boundary=True).compute(snap).mean_normal_force == pytest.approx(13 / 3)


@pytest.mark.parametrize("rotation", [0.0, 17.0, 30.0])
def test_satake_tensor_of_lattices(rotation):
    hexagonal = FabricTensor().compute(hex_lattice(8, 8, rotation_deg=rotation))
    square = FabricTensor().compute(square_lattice(6, 6, rotation_deg=rotation))
    for fabric in (hexagonal, square):
        np.testing.assert_allclose(fabric.tensor, 0.5 * np.eye(2), atol=1e-12)
        assert fabric.anisotropy == pytest.approx(0.0, abs=1e-12)
        # phi_ijkk = phi_ij
        np.testing.assert_allclose(np.einsum("ijkk->ij", fabric.fourth_order), fabric.tensor, atol=1e-12)
    # the fourth order tells them apart: isotropic 3/8 against 1/2 (cos^4 + sin^4 turned)
    assert hexagonal.fourth_order[0, 0, 0, 0] == pytest.approx(3.0 / 8.0)
    c, s = np.cos(np.radians(rotation)), np.sin(np.radians(rotation))
    assert square.fourth_order[0, 0, 0, 0] == pytest.approx((c**4 + s**4) / 2)
    assert hexagonal.fourth_harmonic == pytest.approx(0.0, abs=1e-12)
    assert square.fourth_harmonic == pytest.approx(1.0)
    assert hexagonal.strong_part is None  # no forces


def test_force_anisotropies_recover_the_forms_exactly():
    rng = np.random.default_rng(3)
    theta = rng.uniform(0, 2 * np.pi, 200)
    f0, a_n, t_n, a_t, t_t = 2.0, 0.4, np.radians(70), 0.15, np.radians(100)
    fn = f0 * (1 + a_n * np.cos(2 * (theta - t_n)))
    ft = f0 * a_t * np.sin(2 * (theta - t_t))
    rb = force_anisotropies(theta, fn, ft)
    assert (rb.f0, rb.a_n, rb.theta_n, rb.a_t, rb.theta_t) == pytest.approx((f0, a_n, t_n, a_t, t_t))
    moment = np.mean(np.exp(2j * theta))
    assert rb.a == pytest.approx(2 * abs(moment))
    assert np.isnan(force_anisotropies(theta, fn, None).a_t)


def test_stress_force_fabric_is_exact_for_the_forms_on_even_directions():
    """360 directions 1 deg apart (every harmonic but the 360th vanishes): the
    first-order relation q/p = (a + a_n + a_t)/2 holds exactly, and a_t adds to the
    stress along theta_t (the sign convention of the shear force)."""
    angles = np.arange(360.0)
    snap = ring(angles)
    th = np.radians(angles)
    fn = 1.5 * (1 + 0.3 * np.cos(2 * (th - np.pi / 2)))
    ft = 1.5 * 0.2 * np.sin(2 * (th - np.pi / 2))
    rb = StressForceFabric().compute(with_forces(snap, fn, ft))
    assert rb.stress_direction == pytest.approx(np.pi / 2)
    assert rb.stress_ratio == pytest.approx(0.25)
    assert rb.predicted_stress_ratio == pytest.approx(0.25)
    assert rb.residual == pytest.approx(0.0, abs=1e-12)
    assert rb.sigma_ratio == pytest.approx(1.25 / 0.75)
    # the shear forces against the normal ones: q/p = (0.3 - 0.2)/2
    rb = StressForceFabric().compute(with_forces(snap, fn, -ft))
    assert rb.stress_ratio == pytest.approx(0.05) and rb.residual == pytest.approx(0.0, abs=1e-12)


def test_branch_length_anisotropy():
    """Equal forces on 360 contacts 1 deg apart whose branch lengths follow
    l0 [1 + a_l cos 2(theta - 90 deg)]: q/p = a_l / 2, all of it in the branch lengths."""
    th = np.radians(np.arange(360.0))
    length = 2e-3 * (1 + 0.2 * np.cos(2 * (th - np.pi / 2)))
    pos = np.vstack([[0.0, 0.0], length[:, None] * np.c_[np.cos(th), np.sin(th)]])
    radii = np.r_[0.5e-3, length - 0.5e-3]
    snap = Snapshot(pos, radii, contact_i=np.zeros(360, np.int64), contact_j=np.arange(1, 361),
                    normal_force=np.ones(360))
    rb = StressForceFabric().compute(snap)
    assert rb.anisotropies.a_l == pytest.approx(0.2)
    assert rb.anisotropies.theta_l == pytest.approx(np.pi / 2)
    assert rb.anisotropies.l0 == pytest.approx(2e-3)
    assert rb.anisotropies.a_n == pytest.approx(0.0, abs=1e-12)
    assert rb.stress_ratio == pytest.approx(0.1)
    assert rb.predicted_stress_ratio == pytest.approx(0.0, abs=1e-12)
    assert rb.residual == pytest.approx(0.1)
    assert rb.residual_with_branch_length == pytest.approx(0.0, abs=1e-12)


def test_uniaxially_loaded_hexagonal_lattice():
    """Contacts at 30, 90, 150 deg, only the vertical ones loaded: a = 0, a_n = 2,
    q/p = 1 measured and predicted (no fourth harmonic)."""
    lattice = hex_lattice(8, 8)  # x and y swapped: still a periodic lattice
    snap = Snapshot(lattice.positions[:, ::-1], lattice.radii, contact_i=lattice.contact_i,
                    contact_j=lattice.contact_j, box=lattice.box[::-1], periodic=(True, True))
    vertical = np.abs(snap.contact_normals()[:, 1]) > 0.99
    rb = StressForceFabric().compute(with_forces(snap, np.where(vertical, 4.0, 0.0)))
    assert rb.anisotropies.a == pytest.approx(0.0, abs=1e-12)
    assert rb.anisotropies.a_n == pytest.approx(2.0)
    assert rb.anisotropies.theta_n == pytest.approx(np.pi / 2)
    assert rb.stress_ratio == pytest.approx(1.0)
    assert rb.residual == pytest.approx(0.0, abs=1e-12)
    assert rb.anisotropies.a_l == pytest.approx(0.0, abs=1e-12)  # one size of disk
    assert rb.residual_with_branch_length == pytest.approx(0.0, abs=1e-12)


def test_uniaxially_loaded_square_lattice_has_no_a_n():
    snap = square_lattice(6, 6)
    vertical = np.abs(snap.contact_normals()[:, 1]) > 0.99
    rb = StressForceFabric().compute(with_forces(snap, np.where(vertical, 1.0, 0.0)))
    assert rb.stress_ratio == pytest.approx(1.0)
    assert rb.anisotropies.a == pytest.approx(0.0, abs=1e-12)
    assert np.isnan(rb.anisotropies.a_n) and np.isnan(rb.residual)


def test_analyze_reports_the_new_measures(tmp_path):
    from grainlab.postprocess import write_analysis

    snap, _ = hex_three_and_one()
    result = analyze_snapshot(snap)
    s = result.summary()
    assert s["strong_deviatoric_share"] == pytest.approx(1.5)
    assert s["weak_deviatoric_share"] == pytest.approx(-0.5)
    assert s["rb_residual"] == pytest.approx(0.0, abs=1e-12)
    assert s["loop_size_distribution"] == [0.0, 0.0, 0.0, 1.0]
    assert s["porosity_power_cells"] == pytest.approx(1 - np.pi / (2 * np.sqrt(3)))
    np.testing.assert_allclose(s["satake_fabric_tensor"], [[0.5, 0.0], [0.0, 0.5]], atol=1e-12)
    assert s["chains_n_chains"] == 0  # every grain at the same stress: none above the mean
    table = result.particle_table()
    for column in ("local_porosity", "major_stress_pa", "in_strong_network", "force_chain", "loop_size"):
        assert table[column].shape == (snap.n_particles,)
    written = {p.name for p in write_analysis(result, tmp_path)}
    assert {"force_network.png", "force_chains.png", "map_local_porosity.png",
            "map_loop_size.png", "stress_force_fabric.png"} <= written


def test_every_new_measure_draws():
    from grainlab.analysis import ContactLoops, ForceChains, GrainStress, LocalPorosity

    snap, _ = hex_three_and_one()
    for measure in (FabricTensor(), GrainStress(), ForceNetworks(), StressForceFabric(),
                    ForceChains(), LocalPorosity(), ContactLoops()):
        ax = measure.compute(snap).plot()
        assert ax.figure is not None
