"""Measures per body (grainlab.analysis.per_body): known answers on hand-built clumps,
invariants on a settled pile of trimers, and today's numbers to the bit for disks."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
import pytest
from factories_analysis import grain_on_membrane, jittered_packing

from grainlab import ContactModel, Simulation, cli
from grainlab.analysis import (
    ContactAnisotropy,
    CoordinationNumber,
    GrainStress,
    LocalStrain,
    LoveWeberStress,
    StabilityIndex,
)
from grainlab.analysis.per_body import (
    BodyCoordination,
    BodyOrientation,
    BodyStabilityIndex,
    body_view,
)
from grainlab.analysis.stress import contact_stress
from grainlab.io import read_snapshot, write_particles_csv
from grainlab.snapshot import Snapshot

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "engine"))
from clump_factories import trimer_pile  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "lammps_dump"


# ---------------------------------------------------------------- disks: today's bits
def _disk_snapshots() -> list[Snapshot]:
    """Real and synthetic snapshots of disks: a LAMMPS pile (its wall disks as the
    boundary, and as grains), a periodic packing, an engine pile on walls, a grain
    on a membrane, and a snapshot labelling every disk a grain of its own."""
    dump = DATA / "atoms.dump"
    contacts = DATA / "contacts.dump"
    grid = np.stack(np.meshgrid(np.arange(1, 9), np.arange(1, 6)), -1).reshape(-1, 2) * 1.2e-3
    sim = Simulation(
        grid + np.random.default_rng(2).uniform(-0.05e-3, 0.05e-3, grid.shape),
        np.random.default_rng(3).uniform(0.4e-3, 0.55e-3, len(grid)),
        2650.0,
        contact_model=ContactModel(8.45e7, 8.45e7, 0.5),
        time_step=1e-5,
        gravity=(0.0, -9.81),
        local_damping=0.7,
    )
    sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    sim.add_line_wall((0.0, 0.0), (1.0, 0.0))
    sim.add_line_wall((10e-3, 0.0), (-1.0, 0.0))
    sim.time_step = sim.critical_time_step(0.5)
    sim.run(150_000)
    packing = jittered_packing(10, 10, seed=5)
    labelled = Snapshot(
        packing.positions,
        packing.radii,
        contact_i=packing.contact_i,
        contact_j=packing.contact_j,
        box=packing.box,
        periodic=packing.periodic,
        particle_fields={"grain": np.arange(packing.n_particles)[::-1] * 3},
    )
    return [
        read_snapshot(dump, contacts=contacts, boundary_types=(2,)),
        read_snapshot(dump, contacts=contacts),
        packing,
        sim.snapshot(),
        grain_on_membrane(),
        labelled,
    ]


@pytest.fixture(scope="module")
def disk_snapshots() -> list[Snapshot]:
    return _disk_snapshots()


@pytest.mark.parametrize("include_boundary", [False, True])
def test_disks_give_todays_coordination_numbers_to_the_bit(disk_snapshots, include_boundary):
    for snap in disk_snapshots:
        assert body_view(snap).identity
        today = CoordinationNumber(include_boundary=include_boundary).compute(snap)
        bodies = BodyCoordination(include_boundary=include_boundary).compute(snap)
        z, z_m = today.coordination_number, today.mechanical_coordination_number
        assert np.array_equal([bodies.coordination_number, bodies.contact_coordination_number], [z, z])
        assert np.array_equal(
            [bodies.mechanical_coordination_number, bodies.mechanical_contact_coordination_number],
            [z_m, z_m],
            equal_nan=True,
        )
        assert np.array_equal(bodies.rattlers, today.rattlers)
        assert np.array_equal(bodies.n_neighbours, today.n_contacts)
        assert np.array_equal(bodies.n_contacts, today.n_contacts)
        assert np.array_equal(bodies.count_distribution, today.count_distribution)


@pytest.mark.parametrize("direction", ["contact_point", "normal"])
@pytest.mark.parametrize("reading", [{}, {"slots": "list", "anchor": "mean"}])
def test_disks_give_todays_stability_index_to_the_bit(disk_snapshots, direction, reading):
    for snap in disk_snapshots:
        for boundary in ("body", "each"):
            today = StabilityIndex(boundary=boundary, **reading).compute(snap)
            bodies = BodyStabilityIndex(boundary=boundary, direction=direction, **reading).compute(snap)
            assert np.array_equal(bodies.stability_index, today.stability_index, equal_nan=True)
            assert np.array_equal(bodies.n_contacts, today.n_contacts)
            assert np.array_equal([bodies.mean, bodies.mean_all], [today.mean, today.mean_all], equal_nan=True)


def test_disks_have_no_long_axis(disk_snapshots):
    for snap in disk_snapshots:
        orientation = BodyOrientation().compute(snap)
        assert np.isnan(orientation.axis).all() and orientation.n_oriented == 0
        assert np.isnan(orientation.anisotropy)


# ---------------------------------------------------------------- hand-built clumps
TRIANGLE = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3.0) / 2.0]])


def _two_trimers() -> Snapshot:
    """Two trimers of touching pebbles (radius 0.5), one the mirror of the other
    below it: they touch at two pebble pairs; the contacts are found from the
    geometry, so the pebbles' contacts inside each trimer are listed too."""
    below = TRIANGLE * [1.0, -1.0] - [0.0, 1.0]
    return Snapshot.from_geometry(
        np.vstack([TRIANGLE, below]),
        np.full(6, 0.5),
        tolerance=1e-9,
        particle_fields={"grain": [4, 4, 4, 9, 9, 9]},
    )


def test_two_trimers_touching_at_two_pebbles_are_one_pair_and_two_contacts():
    snap = _two_trimers()
    assert snap.n_contacts == 8  # 3 inside each trimer, 2 between them
    view = body_view(snap)
    assert view.n_bodies == 2 and view.snapshot.n_contacts == 2
    z = BodyCoordination().compute(view)
    assert z.coordination_number == 1.0  # one pair, 2 x 1 / 2
    assert z.contact_coordination_number == 2.0  # two contacts, 2 x 2 / 2
    assert z.n_neighbours.tolist() == [1, 1] and z.n_contacts.tolist() == [2, 2]
    # each touches one body only: both are rattlers by the pairs (by contacts they would not be)
    assert z.rattlers.tolist() == [True, True]
    assert np.isnan(z.mechanical_coordination_number)
    assert CoordinationNumber().compute(snap).coordination_number == pytest.approx(16 / 6)


def _surface_point(centre: np.ndarray, radius: float, angle: float) -> np.ndarray:
    """The far point where the ray from the origin at ``angle`` leaves the circle."""
    u = np.array([np.cos(angle), np.sin(angle)])
    b = float(u @ centre)
    return (b + np.sqrt(b * b - float(centre @ centre) + radius**2)) * u


def _dimer_on_walls(angles_deg: list[float]) -> Snapshot:
    """A dimer (pebbles of radius 0.75 at x = -0.5 and 0.5, centroid at the origin)
    held by one wall at each of ``angles_deg`` (seen from the centroid), each
    contact on the pebble nearer the wall, its normal from that pebble's centre."""
    pebbles = np.array([[-0.5, 0.0], [0.5, 0.0]])
    ci, points, normals = [], [], []
    for angle in np.radians(angles_deg):
        k = 0 if np.cos(angle) < 0 else 1
        point = _surface_point(pebbles[k], 0.75, angle)
        ci.append(k)
        points.append(point)
        normals.append((point - pebbles[k]) / 0.75)
    return Snapshot(
        pebbles,
        [0.75, 0.75],
        contact_i=ci,
        contact_j=-1 - np.arange(len(ci)),
        contact_point=points,
        contact_normal=normals,
        particle_fields={"grain": [0, 0]},
    )


def test_three_contacts_equally_spaced_about_a_bodys_centroid_are_stable():
    snap = _dimer_on_walls([90.0, 210.0, 330.0])
    assert BodyStabilityIndex().compute(snap).stability_index[0] == pytest.approx(0.0, abs=1e-12)
    # the normals are not equally spaced (they leave the pebbles' centres)
    assert BodyStabilityIndex(direction="normal").compute(snap).stability_index[0] > 0.05


def test_an_asymmetric_arrangement_about_a_bodys_centroid_gives_the_hand_value():
    # 0, 90, 200 degrees: from 90, 200 is 10 degrees short of 210 and 0 (360) 30 past 330:
    # dS = 40 degrees, the least of the three references (70, 40, 50): lambda = 40 / 360
    snap = _dimer_on_walls([0.0, 90.0, 200.0])
    lam = BodyStabilityIndex().compute(snap)
    assert lam.stability_index[0] == pytest.approx(1.0 / 9.0, abs=1e-12)
    assert lam.n_contacts.tolist() == [3]
    turned = _dimer_on_walls([30.0, 150.0, 270.0])  # equally spaced, another turn
    assert BodyStabilityIndex().compute(turned).stability_index[0] == pytest.approx(0.0, abs=1e-12)
    paper = _dimer_on_walls([10.0, 70.0, 130.0])  # 60 degrees apart: the paper's 1/3
    assert BodyStabilityIndex().compute(paper).stability_index[0] == pytest.approx(1.0 / 3.0, abs=1e-12)


def _rods(angles_deg: list[float], spacing: float = 10.0) -> Snapshot:
    """Straight rods of three pebbles (radius 0.6, 0.5 apart) at ``angles_deg``, apart."""
    positions, grain = [], []
    for b, angle in enumerate(np.radians(angles_deg)):
        u = np.array([np.cos(angle), np.sin(angle)])
        for k in (-1, 0, 1):
            positions.append([spacing * b, 0.0] + 0.5 * k * u)
            grain.append(b)
    return Snapshot(np.array(positions), np.full(len(grain), 0.6), particle_fields={"grain": grain})


def test_rods_all_along_x_have_the_largest_orientation_anisotropy():
    orientation = BodyOrientation().compute(_rods([0.0] * 6))
    assert orientation.n_oriented == 6
    assert np.allclose(orientation.axis, 0.0, atol=1e-12)
    assert orientation.anisotropy == pytest.approx(2.0, abs=1e-12)
    assert orientation.direction == pytest.approx(0.0, abs=1e-12)
    assert orientation.tensor == pytest.approx(np.array([[1.0, 0.0], [0.0, 0.0]]), abs=1e-12)


def test_rods_at_0_and_90_degrees_in_equal_number_are_isotropic():
    orientation = BodyOrientation().compute(_rods([0.0, 90.0] * 4))
    assert orientation.anisotropy == pytest.approx(0.0, abs=1e-12)
    tilted = BodyOrientation().compute(_rods([30.0, 30.0, 120.0]))
    assert tilted.axis == pytest.approx(np.radians([30.0, 30.0, 120.0]), abs=1e-12)
    assert tilted.anisotropy == pytest.approx(2.0 / 3.0, abs=1e-12)  # 2 |2 e^{i60} + e^{i240}| / 3
    assert tilted.direction == pytest.approx(np.radians(30.0), abs=1e-12)


def test_an_equilateral_trimer_has_no_long_axis():
    snap = Snapshot(TRIANGLE, np.full(3, 0.5), particle_fields={"grain": [0, 0, 0]})
    assert np.isnan(BodyOrientation().compute(snap).axis).all()


def _two_dimers(force: float) -> Snapshot:
    """A horizontal dimer (pebbles at (0, 0), (1, 0)) pressed along x by ``force``
    against a vertical one (at (2.1, 0), (2.1, 1)), radii 0.6; the list holds
    each dimer's inner contact too, with forces that must not count."""
    return Snapshot(
        [[0.0, 0.0], [1.0, 0.0], [2.1, 0.0], [2.1, 1.0]],
        np.full(4, 0.6),
        contact_i=[0, 1, 2],
        contact_j=[1, 2, 3],
        normal_force=[5.0, force, 7.0],
        particle_fields={"grain": [0, 0, 1, 1]},
    )


def test_love_weber_stress_of_two_dimers_against_a_hand_computation():
    # contact point (1.55, 0) (overlap 0.1), centroids (0.5, 0) and (2.1, 0.5);
    # force -f x on the first, +f x on the second:
    # sum of (x_c - c_b) (x) f_b = (1.05, 0) (x) (-f, 0) + (-0.55, -0.5) (x) (f, 0),
    # symmetric part [[-1.6 f, -0.25 f], [-0.25 f, 0]], so sigma = [[1.6, 0.25], [0.25, 0]] f / A
    f, area = 3.0, 2.0
    view = body_view(_two_dimers(f))
    np.testing.assert_allclose(view.snapshot.positions, [[0.5, 0.0], [2.1, 0.5]], atol=1e-14)
    expected = np.array([[1.6, 0.25], [0.25, 0.0]]) * f / area
    np.testing.assert_allclose(LoveWeberStress(area=area).compute(view.snapshot).stress, expected, atol=1e-13)
    # the contact (branch-vector) form, from centroid to centroid, is the same
    np.testing.assert_allclose(contact_stress(view.snapshot, area=area), expected, atol=1e-13)
    # read as pebbles (arms from the pebbles' centres, the inner contacts counted) it is not
    pebbles = LoveWeberStress(area=area).compute(_two_dimers(f)).stress
    assert abs(pebbles[0, 0] - expected[0, 0]) > 0.1


def test_a_bodys_stress_is_spread_over_its_area():
    view = body_view(_two_dimers(3.0))
    lens = 2 * 0.36 * np.arccos(1.0 / 1.2) - 0.5 * np.sqrt(4 * 0.36 - 1.0)
    area = 2 * np.pi * 0.36 - lens
    np.testing.assert_allclose(view.area, [area, area], rtol=1e-12)
    moment = LoveWeberStress(area=1.0).compute(view.snapshot, region=[True, False]).stress
    np.testing.assert_allclose(GrainStress().compute(view.snapshot).stress[0], moment / area, rtol=1e-12)


# ---------------------------------------------------------------- a settled pile of trimers
@pytest.fixture(scope="module")
def pile() -> tuple[Snapshot, Snapshot]:
    """The trimer pile (and one disk) at its start and settled."""
    sim = trimer_pile(np.random.default_rng(4).uniform(0, 2 * np.pi, 6), with_disk=True)
    start = sim.snapshot()
    sim.run(80_000)
    return start, sim.snapshot()


def test_a_pile_of_trimers_counts_pairs_and_contacts_consistently(pile):
    snap = pile[1]
    view = body_view(snap)
    assert view.n_bodies == 7 and view.n_pebbles.tolist() == [1, 3, 3, 3, 3, 3, 3]
    assert view.snapshot.n_contacts == snap.n_contacts  # no contact inside a clump
    for include_boundary in (False, True):
        z = BodyCoordination(include_boundary=include_boundary, boundary="each").compute(view)
        assert z.contact_coordination_number >= z.coordination_number
        assert np.all(z.n_neighbours <= z.n_contacts)
        used = np.ones(snap.n_contacts, bool) if include_boundary else ~snap.is_boundary_contact
        wall = snap.contact_j[used] < 0
        assert z.n_contacts.sum() == 2 * (~wall).sum() + wall.sum()
        assert z.contact_coordination_number == pytest.approx(z.n_contacts.sum() / 7)
        # every body left has at least two neighbours left
        core = ~z.rattlers
        pairs = view.pairs()
        a, b = pairs.contact_i, pairs.contact_j
        keep = np.ones(a.size, bool) if include_boundary else b >= 0
        neighbours = np.bincount(a[keep & core[a] & ((b < 0) | core[np.maximum(b, 0)])], minlength=7)
        neighbours += np.bincount(b[keep & (b >= 0) & core[a] & core[np.maximum(b, 0)]], minlength=7)
        assert np.all(neighbours[core] >= 2)


def test_a_pile_of_trimers_keeps_its_contact_fabric_and_its_disks_lambda(pile):
    snap = pile[1]
    view = body_view(snap)
    # the bodies' contacts are the pebbles' contacts between bodies: the same normals
    for weight in ("count", "normal_force"):
        ours = ContactAnisotropy(weight=weight).compute(view.snapshot)
        assert ours.anisotropy == ContactAnisotropy(weight=weight).compute(snap).anisotropy
    # the disk among the clumps keeps its lambda to the bit, the clumps have their own
    lam = BodyStabilityIndex().compute(view).stability_index
    assert lam[0] == StabilityIndex().compute(snap).stability_index[0]
    assert np.all(np.isfinite(lam)) and lam.shape == (7,)
    orientation = BodyOrientation().compute(view)
    assert np.isnan(orientation.axis[0]) and np.isfinite(orientation.axis[1:]).all()


def test_bodies_move_and_turn_with_their_centroids_and_angles(pile):
    start, end = pile
    strain = LocalStrain().compute(body_view(start).snapshot, body_view(end).snapshot)
    first = np.r_[0, 1 + 3 * np.arange(6)]  # the first pebble of each body
    centroid = np.asarray(end.particle_fields["grain_centroid"])[first]
    centroid0 = np.asarray(start.particle_fields["grain_centroid"])[first]
    assert np.array_equal(strain.displacement, centroid - centroid0)
    angle = np.asarray(end.particle_fields["grain_angle"])[first]
    angle0 = np.asarray(start.particle_fields["grain_angle"])[first]
    assert np.array_equal(strain.rotation, angle - angle0)
    assert np.abs(strain.displacement[1:, 1]).min() > 1e-4  # they fell


# ---------------------------------------------------------------- grainlab analyze
def test_grainlab_analyze_reports_the_bodies_of_a_pile_of_trimers(pile, tmp_path, capsys):
    start, end = pile
    write_particles_csv(tmp_path / "start.csv", start)
    write_particles_csv(tmp_path / "end.csv", end)
    out = tmp_path / "out"
    args = ["analyze", str(tmp_path / "end.csv"), "--reference", str(tmp_path / "start.csv")]
    assert cli.main([*args, "--tolerance", "1e-12", "--out", str(out)]) == 0
    line = capsys.readouterr().out
    assert "; 7 bodies (6 clumps): Z = " in line
    summary = json.loads((out / "fabric.json").read_text())
    # read from the file, the pebbles' overlaps inside each trimer are contacts; the bodies have none
    assert summary["n_particles"] == 19 and summary["n_contacts"] > end.n_contacts
    engine = BodyCoordination().compute(end)
    assert summary["body_Z"] == engine.coordination_number
    assert summary["body_Z_c"] == engine.contact_coordination_number
    assert summary["body_n_rattlers"] == int(engine.rattlers.sum())
    with open(out / "bodies.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["n_pebbles"]) for r in rows] == [1, 3, 3, 3, 3, 3, 3]
    first = np.r_[0, 1 + 3 * np.arange(6)]
    moved = end.particle_fields["grain_centroid"][first] - start.particle_fields["grain_centroid"][first]
    got = np.array([[float(r["displacement_x"]), float(r["displacement_y"])] for r in rows])
    assert np.array_equal(got, moved)
    assert (out / "map_stability_index_bodies.png").exists()


def test_grainlab_analyze_of_disks_reports_no_bodies(tmp_path, capsys):
    write_particles_csv(tmp_path / "disks.csv", jittered_packing(6, 6, seed=1))
    out = tmp_path / "out"
    assert cli.main(["analyze", str(tmp_path / "disks.csv"), "--no-figures", "--out", str(out)]) == 0
    assert "bodies" not in capsys.readouterr().out
    assert not any(k.startswith("body_") or k == "n_bodies" for k in json.loads((out / "fabric.json").read_text()))
    assert not (out / "bodies.csv").exists()


def test_grainlab_analyze_reads_the_bodies_of_a_lammps_dump_by_molecule(tmp_path, capsys):
    # the two trimers of touching pebbles (mm), molecules 7 and 3, as `fix rigid/small` writes them
    snap = _two_trimers()
    rows = "\n".join(
        f"{k + 1} {7 if k < 3 else 3} 1 {float(x) * 1e-3!r} {float(y) * 1e-3!r} 0.0005"
        for k, (x, y) in enumerate(snap.positions)
    )
    dump = tmp_path / "clumps.dump"
    dump.write_text(
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n6\nITEM: BOX BOUNDS ff ff pp\n"
        "-0.002 0.002\n-0.003 0.002\n-0.0005 0.0005\nITEM: ATOMS id mol type x y radius\n" + rows + "\n"
    )
    out = tmp_path / "out"
    args = ["analyze", str(dump), "--grain-column", "mol", "--tolerance", "1e-12", "--no-figures"]
    assert cli.main([*args, "--out", str(out)]) == 0
    assert "; 2 bodies (2 clumps): Z = 1.000, Z_c = 2.000" in capsys.readouterr().out
    summary = json.loads((out / "fabric.json").read_text())
    assert summary["n_contacts"] == 8 and summary["body_n_contacts"] == 2 and summary["body_n_pairs"] == 1
    with open(out / "bodies.csv", newline="") as fh:
        rows_read = list(csv.DictReader(fh))
    # the centroids come from the pebbles' union (a dump carries none): each triangle's centre
    centre = TRIANGLE.mean(axis=0) * 1e-3
    got = np.array([[float(r["x"]), float(r["y"])] for r in rows_read])
    np.testing.assert_allclose(got, [centre, centre * [1, -1] - [0, 1e-3]], atol=1e-15)
    assert [int(r["grain"]) for r in rows_read] == [7, 3]


def test_the_grain_column_is_refused_for_files_that_are_not_lammps_dumps(tmp_path):
    write_particles_csv(tmp_path / "disks.csv", jittered_packing(3, 3, seed=1))
    with pytest.raises(ValueError, match="grain column: only applies to LAMMPS dumps"):
        read_snapshot(tmp_path / "disks.csv", grain_column="mol")


def test_a_dimer_across_a_periodic_edge_is_one_body_seen_from_its_centroid():
    # pebbles at x = 9.7 and 0.3 of a 10 x 10 periodic cell (0.6 apart across the edge),
    # a disk above the second one
    snap = Snapshot.from_geometry(
        [[9.7, 5.0], [0.3, 5.0], [0.3, 5.95]],
        [0.5, 0.5, 0.5],
        box=[[0.0, 10.0], [0.0, 10.0]],
        periodic=(True, True),
        particle_fields={"grain": [0, 0, 1]},
    )
    view = body_view(snap)
    assert view.n_bodies == 2 and view.snapshot.n_contacts == 1
    np.testing.assert_allclose(view.snapshot.positions[0], [10.0, 5.0], atol=1e-12)
    np.testing.assert_allclose(view.offsets[:2], [[-0.3, 0.0], [0.3, 0.0]], atol=1e-12)
    assert BodyOrientation().compute(view).axis[0] == pytest.approx(0.0, abs=1e-12)
    on_dimer, on_disk = view.end_angles()
    # the contact point (0.3, 5.475) is (0.3, 0.475) from the centroid across the edge
    assert on_dimer[0] == pytest.approx(np.arctan2(0.475, 0.3), abs=1e-12)
    assert on_disk[0] == pytest.approx(1.5 * np.pi, abs=1e-12)  # the disk keeps its normal's angle
