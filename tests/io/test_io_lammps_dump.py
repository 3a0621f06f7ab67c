"""LAMMPS / LIGGGHTS text dumps: atoms and local (pair) dumps, written here by hand
in the format of the LAMMPS `dump custom` and `dump local` documentation."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.io import (
    FileFormatError,
    detect_format,
    list_timesteps,
    read_lammps_dump,
    read_snapshot,
)
from grainlab.snapshot import Snapshot

ATOMS = """\
ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
4
ITEM: BOX BOUNDS pp ff pp
0.0 0.01
0.0 0.01
-0.001 0.001
ITEM: ATOMS id type x y z radius vx vy fx fy
3 1 0.0050 0.0050 0 0.0005 0 0 0 0
1 1 0.0002 0.0050 0 0.0005 0 0 0 0
2 1 0.0096 0.0050 0 0.0005 0 0 0 0
4 1 0.0050 0.0059 0 0.0005 0 0 0 0
ITEM: TIMESTEP
100
ITEM: NUMBER OF ATOMS
4
ITEM: BOX BOUNDS pp ff pp
0.0 0.01
0.0 0.01
-0.001 0.001
ITEM: ATOMS id type x y z radius vx vy fx fy
4 1 0.0050 0.0060 0 0.0005 0.1 0.2 1.5 -2.5
3 1 0.0050 0.0050 0 0.0005 0 0 0 0
2 1 0.0096 0.0050 0 0.0005 0 0 0 0
1 1 0.0001 0.0050 0 0.0005 0 0 0 0
"""

# `compute ids all property/local patom1 patom2`, `compute pl all pair/local dist force p1 p2`
LOCAL = """\
ITEM: TIMESTEP
100
ITEM: NUMBER OF ENTRIES
3
ITEM: BOX BOUNDS pp ff pp
0.0 0.01
0.0 0.01
-0.001 0.001
ITEM: ENTRIES index c_ids[1] c_ids[2] c_pl[1] c_pl[2] c_pl[3] c_pl[4]
1 1 2 0.0005 84.5 0.0 -2.0
2 3 4 0.0010 0.0 0 0
3 4 3 0.00099 8.45 1.0 0.0
"""


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_picks_the_last_frame_by_default_and_any_by_timestep(tmp_path):
    p = write(tmp_path, "atoms.dump", ATOMS)
    assert list_timesteps(p) == [0, 100]
    assert detect_format(p) == "lammps-dump"
    last = read_lammps_dump(p)
    assert last.metadata["timestep"] == 100
    np.testing.assert_array_equal(last.ids, [4, 3, 2, 1])
    np.testing.assert_allclose(last.positions[0], [0.005, 0.006])
    np.testing.assert_allclose(last.particle_fields["velocity"][0], [0.1, 0.2])
    np.testing.assert_allclose(last.particle_fields["force"][0], [1.5, -2.5])
    np.testing.assert_array_equal(last.particle_fields["type"], [1, 1, 1, 1])
    assert last.periodic == (True, False)
    np.testing.assert_allclose(last.box, [[0, 0.01], [0, 0.01]])
    first = read_lammps_dump(p, timestep=0)
    np.testing.assert_allclose(first.positions[1], [0.0002, 0.005])


def test_geometric_contacts_use_the_periodic_image(tmp_path):
    p = write(tmp_path, "atoms.dump", ATOMS)
    snap = read_lammps_dump(p)

    def pairs(s):
        return {tuple(sorted(x)) for x in np.c_[s.ids[s.contact_i], s.ids[s.contact_j]].tolist()}

    # 1 and 2 touch across the periodic x boundary (0.0001 + 0.01 - 0.0096 = 0.0005 < 0.001);
    # 3 and 4 are exactly r3 + r4 apart at step 100 (not overlapping), 0.0009 at step 0
    assert pairs(snap) == {(1, 2)}
    assert pairs(read_lammps_dump(p, timestep=0)) == {(1, 2), (3, 4)}
    k = [
        n
        for n, (a, b) in enumerate(
            zip(snap.ids[snap.contact_i], snap.ids[snap.contact_j], strict=True)
        )
        if {a, b} == {1, 2}
    ][0]
    i_id = snap.ids[snap.contact_i[k]]
    expected = [-1.0, 0.0] if i_id == 1 else [1.0, 0.0]
    np.testing.assert_allclose(snap.contact_normals()[k], expected, atol=1e-9)


def test_local_dump_ids_forces_and_non_touching_pairs(tmp_path):
    a = write(tmp_path, "atoms.dump", ATOMS)
    c = write(tmp_path, "pairs.dump", LOCAL)
    snap = read_lammps_dump(
        a,
        contacts=c,
        columns={
            "dist": "c_pl[1]",
            "normal_force": "c_pl[2]",
            "shear_x": "c_pl[3]",
            "shear_y": "c_pl[4]",
        },
    )
    # entry 2 lists 3-4 at distance 0.0010 = r3 + r4: not touching, dropped
    assert snap.n_contacts == 2
    ids = np.c_[snap.ids[snap.contact_i], snap.ids[snap.contact_j]]
    np.testing.assert_array_equal(ids, [[1, 2], [4, 3]])
    np.testing.assert_allclose(snap.normal_force, [84.5, 8.45])
    # pair 1-2: normal from 1 to 2 is -x (periodic image), t = rot90(n) = (0, -1): (0, -2).t = 2
    # pair 4-3: normal from 4 to 3 is -y, t = (1, 0): (1, 0).t = 1
    np.testing.assert_allclose(snap.shear_force, [2.0, 1.0])
    assert snap.metadata["contact_columns"]["i"] == "c_ids[1]"  # found by the id heuristic
    assert "1 listed pairs not touching" in snap.metadata["contacts"]


def test_normal_force_from_pair_force_components(tmp_path):
    a = write(tmp_path, "atoms.dump", ATOMS)
    # a column named 'force' is the normal force (compute pair/local ... force)
    named = LOCAL.replace("c_pl[1] c_pl[2] c_pl[3] c_pl[4]", "dist force p1 p2")
    snap = read_lammps_dump(a, contacts=write(tmp_path, "named.dump", named))
    np.testing.assert_allclose(snap.normal_force, [84.5, 8.45])
    # fx fy = force on atom i (patom1); normal force = -F.n with n from i to j
    comps = """\
ITEM: TIMESTEP
100
ITEM: NUMBER OF ENTRIES
2
ITEM: BOX BOUNDS pp ff pp
0.0 0.01
0.0 0.01
-0.001 0.001
ITEM: ENTRIES patom1 patom2 fx fy
1 2 30.0 0.5
4 3 0.25 7.0
"""
    snap2 = read_lammps_dump(a, contacts=write(tmp_path, "comps.dump", comps))
    # pair 1-2: n = (-1, 0) (periodic image), repulsion pushes 1 towards +x: Fn = 30
    # pair 4-3: exactly touching (distance 0.001 = r3 + r4), so dropped
    np.testing.assert_allclose(snap2.normal_force, [30.0])
    assert snap2.metadata["contact_columns"] == {
        "i": "patom1",
        "j": "patom2",
        "fx": "fx",
        "fy": "fy",
    }


def test_scaled_coordinates_and_diameter(tmp_path):
    text = ATOMS.split("ITEM: TIMESTEP\n100")[0].replace(
        "id type x y z radius vx vy fx fy", "id xs ys diameter"
    )
    rows = ["3 0.5 0.5 0.001", "1 0.02 0.5 0.001", "2 0.96 0.5 0.001", "4 0.5 0.59 0.001"]
    head = text.split("ITEM: ATOMS")[0] + "ITEM: ATOMS id xs ys diameter\n"
    p = write(tmp_path, "s.dump", head + "\n".join(rows) + "\n")
    snap = read_lammps_dump(p)
    np.testing.assert_allclose(snap.positions[1], [0.0002, 0.005])
    np.testing.assert_allclose(snap.radii, 0.0005)


@pytest.mark.parametrize(
    ("mutate", "line", "message"),
    [
        (lambda t: t.replace("radius vx", "rad vx"), 9, "missing column 'radius'"),
        (
            lambda t: t.replace("ITEM: ATOMS id type x y", "ITEM: ATOMS id type a b"),
            9,
            "missing position columns",
        ),
        (
            lambda t: t.replace("1 1 0.0002 0.0050", "3 1 0.0002 0.0050"),
            11,
            "duplicate particle id 3 (first seen on line 10)",
        ),
        (lambda t: t.replace("2 1 0.0096 0.0050 0", "2 1 nan 0.0050 0"), 12, "column 'x'"),
        (
            lambda t: t.replace("4 1 0.0050 0.0059 0 0.0005", "4 1 0.0050 0.0059 0"),
            13,
            "expected 10 fields, found 9",
        ),
        (
            lambda t: t.replace(
                "NUMBER OF ATOMS\n4\nITEM: BOX", "NUMBER OF ATOMS\nfour\nITEM: BOX", 1
            ),
            4,
            "number of atoms",
        ),
        (lambda t: "garbage\n" + t, 1, "expected 'ITEM: TIMESTEP'"),
        (
            lambda t: t.replace("3 1 0.0050 0.0050 0 0.0005", "3 1 0.0050 0.0050 0 -0.0005", 1),
            10,
            "not > 0",
        ),
    ],
)
def test_atom_dump_errors_name_file_and_line(tmp_path, mutate, line, message):
    first_frame = ATOMS.split("ITEM: TIMESTEP\n100")[0]
    p = write(tmp_path, "bad.dump", mutate(first_frame))
    with pytest.raises(FileFormatError) as info:
        read_lammps_dump(p)
    assert str(info.value).startswith(f"{p}:{line}: "), str(info.value)
    assert message in str(info.value)


def test_body_column_labels_boundary_atoms(tmp_path):
    # atoms 1 and 2 (type 2) are boundary atoms in two bodies, given by the 'mol' column
    text = ATOMS.split("ITEM: TIMESTEP\n100")[0].replace("ITEM: ATOMS id type", "ITEM: ATOMS id mol type")
    rows = {"3 1": "3 0 1", "1 1": "1 5 2", "2 1": "2 6 2", "4 1": "4 0 1"}
    for old, new in rows.items():
        text = text.replace(f"\n{old} ", f"\n{new} ")
    p = write(tmp_path, "mol.dump", text)
    snap = read_lammps_dump(p, boundary_types=(2,), body_column="mol")
    np.testing.assert_array_equal(snap.particle_fields["body"], [0, 5, 6, 0])
    np.testing.assert_array_equal(snap.boundary_bodies(), [-1, 5, 6, -1])
    # without the column, atoms 1 and 2 (0.6 mm apart across the periodic x) touch: one body
    np.testing.assert_array_equal(read_lammps_dump(p, boundary_types=(2,)).boundary_bodies(), [-1, 0, 0, -1])
    with pytest.raises(FileFormatError, match="no column 'chain' for body_column"):
        read_lammps_dump(p, body_column="chain")


def test_truncated_file_and_missing_timestep(tmp_path):
    p = write(tmp_path, "t.dump", ATOMS[: ATOMS.rindex("2 1 0.0096")])
    with pytest.raises(FileFormatError, match="file ends inside a frame"):
        read_lammps_dump(p)
    q = write(tmp_path, "atoms.dump", ATOMS)
    with pytest.raises(FileFormatError, match=r"no frame with timestep 50 \(timesteps: 0, 100\)"):
        read_lammps_dump(q, timestep=50)


def test_local_dump_errors(tmp_path):
    a = write(tmp_path, "atoms.dump", ATOMS)
    bad = write(tmp_path, "bad.dump", LOCAL.replace("3 4 3 0.00099", "3 4 99 0.00099"))
    with pytest.raises(FileFormatError) as info:
        read_lammps_dump(a, contacts=bad, columns={"i": "c_ids[1]", "j": "c_ids[2]"})
    assert str(info.value).startswith(f"{bad}:12: ") and "unknown atom id 99" in str(info.value)
    unnamed = write(tmp_path, "u.dump", LOCAL.replace("c_ids[1] c_ids[2]", "c_a c_b"))
    with pytest.raises(FileFormatError, match="cannot tell which columns hold the two atom ids"):
        read_lammps_dump(a, contacts=unnamed)
    with pytest.raises(FileFormatError, match="no column 'c_zz'"):
        read_lammps_dump(
            a, contacts=write(tmp_path, "l.dump", LOCAL), columns={"normal_force": "c_zz"}
        )
    with pytest.raises(ValueError, match="unknown role"):
        read_lammps_dump(a, contacts=write(tmp_path, "l.dump", LOCAL), columns={"force": "c_pl[2]"})
    with pytest.raises(FileFormatError, match="expected a local dump"):
        read_lammps_dump(a, contacts=a)
    with pytest.raises(FileFormatError, match="expected an atoms dump"):
        read_lammps_dump(write(tmp_path, "l.dump", LOCAL))


def test_read_snapshot_dispatch(tmp_path):
    h5 = tmp_path / "run.h5"
    h5.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    assert detect_format(h5) == "grainlab-hdf5"
    with pytest.raises(ValueError, match="cannot be read as HDF5: the file is truncated or corrupt"):
        read_snapshot(h5)
    other = write(tmp_path, "x.txt", "hello,world\n")
    with pytest.raises(FileFormatError, match="unknown format"):
        read_snapshot(other)
    csv = write(tmp_path, "p.csv", "id,x,y,radius\n1,0,0,1\n")
    with pytest.raises(ValueError, match="timestep"):
        read_snapshot(csv, timestep=3)
    with pytest.raises(ValueError, match="format"):
        read_snapshot(csv, format="vtk")


def dump_3d(tmp_path, xyz, radius, name="spheres.dump", columns="x y z", box_z=(-0.01, 0.02)):
    """An atoms dump of spheres (ids 1..N) in a fixed 0.02 m box."""
    rows = "".join(
        f"{k + 1} 1 {p[0]!r} {p[1]!r} {p[2]!r} {r!r}\n"
        for k, (p, r) in enumerate(zip(xyz.tolist(), np.broadcast_to(radius, len(xyz)).tolist(), strict=True))
    )
    text = (
        f"ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n{len(xyz)}\nITEM: BOX BOUNDS ff ff ff\n"
        f"0.0 0.02\n0.0 0.02\n{box_z[0]!r} {box_z[1]!r}\nITEM: ATOMS id type {columns} radius\n{rows}"
    )
    return write(tmp_path, name, text)


def random_spheres(rng, n=200, r=0.5e-3, side=0.02):
    """n non-overlapping spheres of radius r in a cube of the given side (rejection)."""
    out = []
    while len(out) < n:
        p = rng.uniform(r, side - r, 3)
        if all(np.sum((p - q) ** 2) >= (2 * r) ** 2 for q in out):
            out.append(p)
    return np.array(out)


def test_3d_dump_is_refused_with_one_line_naming_file_and_spread(tmp_path):
    rng = np.random.default_rng(3)
    xyz = random_spheres(rng, r=1e-3)  # 10 % of the cube's volume
    p = dump_3d(tmp_path, xyz, 1e-3)
    with pytest.raises(FileFormatError) as info:
        read_lammps_dump(p)
    message = str(info.value)
    spread = xyz[:, 2].max() - xyz[:, 2].min()
    assert message.startswith(f"{p}:9: 3D data: column 'z' spreads over {spread:.6g} m")
    assert "\n" not in message and "z_policy='project'" in message
    # read as 2D the projected disks would overlap everywhere: what the refusal prevents
    flat = Snapshot.from_geometry(xyz[:, :2], np.full(len(xyz), 1e-3))
    assert 2 * flat.n_contacts / len(xyz) > 5.0
    # projected on request: the contacts are the spheres' (none touch), not the disks'
    projected = read_lammps_dump(p, z_policy="project")
    assert projected.n_contacts == 0
    np.testing.assert_array_equal(projected.particle_fields["z"], xyz[:, 2])
    assert projected.metadata["z_policy"] == "project"


def test_planar_tolerance_is_relative_to_the_radii(tmp_path):
    xyz = np.array([[0.005, 0.005, 0.0], [0.006, 0.005, 0.0], [0.010, 0.010, 0.0]])
    for r, scale in ((0.5e-3, 1.0), (5e-6, 0.01)):  # the same sample at 1/100 scale
        xyz_s = xyz * scale
        ok = xyz_s.copy()
        ok[2, 2] = 0.9e-3 * r  # below 1e-3 of the smallest radius: a plane
        snap = read_lammps_dump(dump_3d(tmp_path, ok, r, f"ok{scale}.dump"))
        assert snap.n_particles == 3 and "z" not in snap.particle_fields
        np.testing.assert_array_equal(snap.positions, ok[:, :2])
        bad = xyz_s.copy()
        bad[2, 2] = 1.1e-3 * r
        with pytest.raises(FileFormatError, match="3D data"):
            read_lammps_dump(dump_3d(tmp_path, bad, r, f"bad{scale}.dump"))
    # a constant z, however large, is a plane
    lifted = xyz + [0.0, 0.0, 0.007]
    assert read_lammps_dump(dump_3d(tmp_path, lifted, 0.5e-3, "lifted.dump")).n_particles == 3


def test_projection_keeps_sphere_contacts_with_their_in_plane_direction(tmp_path):
    r = 0.5e-3
    a = np.array([0.008, 0.008, 0.0])
    b = a + 1.999 * r * np.array([np.cos(np.radians(30)), 0.0, np.sin(np.radians(30))])  # overlaps a
    c = a + np.array([0.0, 0.6 * r, 3 * r])  # above a: disks overlap, spheres do not
    p = dump_3d(tmp_path, np.array([a, b, c]), r)
    snap = read_lammps_dump(p, z_policy="project", tolerance=1e-9)
    np.testing.assert_array_equal(np.c_[snap.contact_i, snap.contact_j], [[0, 1]])
    np.testing.assert_allclose(snap.contact_normals(), [[1.0, 0.0]], atol=1e-12)
    np.testing.assert_array_equal(snap.radii, [r, r, r])
    # a listed pair counts only if the spheres touch in 3D (no 'dist' column: recomputed with z)
    local = (
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ENTRIES\n2\nITEM: BOX BOUNDS ff ff ff\n0 0.02\n0 0.02\n0 0.02\n"
        "ITEM: ENTRIES c_ids[1] c_ids[2] c_f[1]\n1 2 0.0\n1 3 0.0\n"
    )
    listed = read_lammps_dump(p, z_policy="project", contacts=write(tmp_path, "c.dump", local),
                              columns={"i": "c_ids[1]", "j": "c_ids[2]"})  # fmt: skip
    np.testing.assert_array_equal(np.c_[listed.contact_i, listed.contact_j], [[0, 1]])
    # one sphere right above another: no direction in the plane
    stacked = dump_3d(tmp_path, np.array([a, a + [1e-15, 0.0, 2 * r]]), r, "stacked.dump")
    with pytest.raises(FileFormatError, match="ids 1 and 2 touch one above the other"):
        read_lammps_dump(stacked, z_policy="project", tolerance=1e-9)


def test_slice_gives_the_cross_sections(tmp_path):
    r = 0.5e-3
    z0 = 0.001
    xyz = np.array(
        [[0.005, 0.005, z0 + 0.6 * r], [0.005 + 1.6 * r, 0.005, z0], [0.010, 0.010, z0 + 1.2 * r]]
    )
    p = dump_3d(tmp_path, xyz, r)
    snap = read_lammps_dump(p, z_policy="slice", z0=z0)
    np.testing.assert_array_equal(snap.ids, [1, 2])  # the third sphere misses the plane
    np.testing.assert_allclose(snap.radii, [0.8 * r, r], rtol=1e-12)
    # cross-sections 1.6 r apart with radii 0.8 r + r overlap: one contact, along +x
    np.testing.assert_array_equal(np.c_[snap.contact_i, snap.contact_j], [[0, 1]])
    np.testing.assert_allclose(snap.particle_fields["z"], xyz[:2, 2])
    assert snap.metadata["z0_m"] == z0
    with pytest.raises(FileFormatError, match="no sphere crosses the plane"):
        read_lammps_dump(p, z_policy="slice", z0=0.5)
    # a sphere right above the first, away from the plane: the slice does not see it,
    # the projection puts two disks on one centre (refused, naming its line)
    column = dump_3d(tmp_path, np.vstack([xyz, xyz[0] + [0.0, 0.0, 5 * r]]), r, "column.dump")
    np.testing.assert_array_equal(read_lammps_dump(column, z_policy="slice", z0=z0).ids, [1, 2])
    with pytest.raises(FileFormatError, match=r"column.dump:13: .*coincident disks"):
        read_lammps_dump(column, z_policy="project")


def test_scaled_z_and_z_policy_errors(tmp_path):
    xyz = np.array([[0.25, 0.25, 0.1], [0.5, 0.5, 0.9]])  # scaled; box z from -0.01 to 0.02
    p = dump_3d(tmp_path, xyz, 0.5e-3, columns="xs ys zs")
    with pytest.raises(FileFormatError, match=r"column 'zs' spreads over 0.024 m"):
        read_lammps_dump(p)
    np.testing.assert_allclose(read_lammps_dump(p, z_policy="project").particle_fields["z"], [-0.007, 0.017])
    flat = write(tmp_path, "flat.dump", ATOMS.split("ITEM: TIMESTEP\n100")[0].replace(" z ", " q "))
    with pytest.raises(FileFormatError, match="z_policy='project': the file has no z column"):
        read_lammps_dump(flat, z_policy="project")
    for kwargs, name in ((dict(z_policy="flatten"), "z_policy"), (dict(z_policy="slice"), "z0"),
                         (dict(z_policy="project", z0=0.0), "z0"),
                         (dict(z_policy="slice", z0=0.0, contacts=p), "contacts")):  # fmt: skip
        with pytest.raises(ValueError, match=rf"^{name}: "):
            read_lammps_dump(p, **kwargs)
