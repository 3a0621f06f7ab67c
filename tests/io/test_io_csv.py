"""Particles / contacts CSV: round trip and error messages naming file and line."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.io import (
    FileFormatError,
    read_contacts_csv,
    read_particles_csv,
    read_snapshot,
    write_contacts_csv,
    write_particles_csv,
)
from grainlab.snapshot import ParticleKind, Snapshot


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_round_trip_keeps_values_exactly(tmp_path):
    rng = np.random.default_rng(5)
    n = 50
    snap = Snapshot.from_geometry(
        rng.uniform(0, 0.02, (n, 2)),
        rng.uniform(0.5e-3, 1.5e-3, n),
        ids=rng.permutation(1000)[:n],
        rotations=rng.normal(size=n),
        kind=np.where(np.arange(n) < 5, ParticleKind.MEMBRANE, ParticleKind.SOIL),
    )
    forces = rng.uniform(0, 10, snap.n_contacts)
    snap = Snapshot(
        snap.positions,
        snap.radii,
        ids=snap.ids,
        rotations=snap.rotations,
        kind=snap.kind,
        contact_i=snap.contact_i,
        contact_j=snap.contact_j,
        normal_force=forces,
        shear_force=-forces / 3,
    )
    write_particles_csv(tmp_path / "p.csv", snap, {"score": np.linspace(0, 1, n)})
    write_contacts_csv(tmp_path / "c.csv", snap)
    back = read_particles_csv(tmp_path / "p.csv", contacts=tmp_path / "c.csv")
    np.testing.assert_array_equal(back.positions, snap.positions)
    np.testing.assert_array_equal(back.radii, snap.radii)
    np.testing.assert_array_equal(back.ids, snap.ids)
    np.testing.assert_array_equal(back.rotations, snap.rotations)
    np.testing.assert_array_equal(back.kind, snap.kind)
    np.testing.assert_array_equal(back.particle_fields["score"], np.linspace(0, 1, n))
    np.testing.assert_array_equal(back.contact_i, snap.contact_i)
    np.testing.assert_array_equal(back.contact_j, snap.contact_j)
    np.testing.assert_array_equal(back.normal_force, snap.normal_force)
    np.testing.assert_array_equal(back.shear_force, snap.shear_force)
    assert back.n_contacts > 10


def test_body_labels_round_trip_and_are_checked(tmp_path):
    # two membrane chains (labels 0 and 1) that touch: only the labels keep them apart
    pos = np.c_[np.arange(6) * 0.8e-3, np.zeros(6)]
    snap = Snapshot(pos, np.full(6, 0.5e-3), kind=[1] * 6, particle_fields={"body": [0, 0, 0, 1, 1, 1]})
    write_particles_csv(tmp_path / "p.csv", snap)
    back = read_particles_csv(tmp_path / "p.csv", detect=False)
    np.testing.assert_array_equal(back.boundary_bodies(), [0, 0, 0, 1, 1, 1])
    assert back.particle_fields["body"].dtype == np.int64
    unlabelled = read_particles_csv(write(tmp_path, "u.csv", "id,x,y,radius,kind\n" + "".join(
        f"{k},{float(x)!r},0,0.0005,1\n" for k, x in enumerate(pos[:, 0]))), detect=False)
    np.testing.assert_array_equal(unlabelled.boundary_bodies(), np.zeros(6))  # one touching chain
    bad = write(tmp_path, "b.csv", "id,x,y,radius,kind,body\n1,0,0,1,1,0\n2,3,0,1,1,-2\n")
    with pytest.raises(FileFormatError, match=r"b.csv:3: column 'body': -2 is not a body label"):
        read_particles_csv(bad)


def test_header_order_case_comments_and_detected_contacts(tmp_path):
    p = write(
        tmp_path,
        "p.csv",
        "# exported by hand\n\nRadius, Y, X, ID\n0.5e-3,0,0,10\n# a comment\n"
        "0.5e-3,0,0.9e-3,20\n0.5e-3,5e-3,0,30\n",
    )
    snap = read_particles_csv(p)
    np.testing.assert_array_equal(snap.ids, [10, 20, 30])
    np.testing.assert_allclose(snap.positions[1], [0.9e-3, 0.0])
    np.testing.assert_array_equal(np.c_[snap.contact_i, snap.contact_j], [[0, 1]])
    touching = write(tmp_path, "t.csv", "id,x,y,radius\n1,0,0,0.5\n2,1.0,0,0.5\n")
    assert read_particles_csv(touching).n_contacts == 0
    assert read_particles_csv(touching, tolerance=1e-9).n_contacts == 1
    assert read_snapshot(touching, tolerance=1e-9).n_contacts == 1


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("id,x,radius\n1,0,0.5\n", 1, "missing column(s) y"),
        ("id,x,y,radius\n1,0,0,0.5\n2,0,nan,0.5\n", 3, "column 'y'"),
        (
            "id,x,y,radius\n1,0,0,0.5\n2,0,1,0.5\n\n1,0,2,0.5\n",
            5,
            "duplicate particle id 1 (first seen on line 2)",
        ),
        ("id,x,y,radius\n1,0,0,0.5\n2,0,1\n", 3, "expected 4 fields, found 3"),
        ("id,x,y,radius\n1,0,0,0.5\n2,0,abc,0.5\n", 3, "cannot read 'abc'"),
        ("id,x,y,radius\n1,0,0,0.5\n2,0,1,-0.5\n", 3, "not > 0"),
        ("id,x,y,radius\n1.5,0,0,0.5\n", 2, "not an integer id"),
        ("id,x,y,y,radius\n", 1, "duplicate column 'y'"),
        ("id,x,y,radius,kind\n1,0,0,0.5,9\n", 2, "unknown code 9"),
    ],
)
def test_particle_errors_name_file_and_line(tmp_path, text, line, message):
    p = write(tmp_path, "bad.csv", text)
    with pytest.raises(FileFormatError) as info:
        read_particles_csv(p)
    assert str(info.value).startswith(f"{p}:{line}: ")
    assert message in str(info.value)
    assert info.value.line == line and info.value.path == str(p)


def test_file_level_errors(tmp_path):
    with pytest.raises(FileFormatError, match="file not found"):
        read_particles_csv(tmp_path / "nope.csv")
    with pytest.raises(FileFormatError, match="empty file"):
        read_particles_csv(write(tmp_path, "e.csv", "\n# only a comment\n"))
    with pytest.raises(FileFormatError, match="no particle rows"):
        read_particles_csv(write(tmp_path, "h.csv", "id,x,y,radius\n"))


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("i,j\n1,2\n1,7\n", 3, "column 'j': unknown particle id 7"),
        ("i,j\n2,2\n", 2, "particle id 2 in contact with itself"),
        ("i,j,normal_force\n1,2,inf\n", 2, "column 'normal_force'"),
        ("i\n1\n", 1, "missing column(s) j"),
    ],
)
def test_contact_errors_name_file_and_line(tmp_path, text, line, message):
    p = write(tmp_path, "p.csv", "id,x,y,radius\n1,0,0,0.5\n2,1,0,0.5\n")
    c = write(tmp_path, "c.csv", text)
    with pytest.raises(FileFormatError) as info:
        read_particles_csv(p, contacts=c)
    assert str(info.value).startswith(f"{c}:{line}: ")
    assert message in str(info.value)


def test_read_contacts_csv_columns(tmp_path):
    c = write(tmp_path, "c.csv", "i,j,normal_force,shear_force\n1,2,3.5,-1\n")
    out = read_contacts_csv(c)
    assert out["i"].tolist() == [1] and out["j"].tolist() == [2]
    assert out["normal_force"].tolist() == [3.5] and out["shear_force"].tolist() == [-1.0]
    assert out["line"].tolist() == [2]


def test_writer_writes_nan_as_empty_and_checks_lengths(tmp_path):
    snap = Snapshot([[0, 0], [1, 0]], [0.5, 0.5])
    p = write_particles_csv(
        tmp_path / "w.csv", snap, {"v": [1.0, np.nan], "flag": np.array([True, False])}
    )
    lines = p.read_text().splitlines()
    assert lines[0] == "id,x,y,radius,kind,v,flag"  # kind always: the file reads back without a warning
    assert lines[2] == "1,1,0,0.5,0,,0"
    with pytest.raises(ValueError, match="columns"):
        write_particles_csv(tmp_path / "w.csv", snap, {"v": [1.0]})


def test_z_column_3d_refused_unless_projected_or_sliced(tmp_path):
    r = 0.5e-3
    rows = [(1, 0.0, 0.0, 0.0), (2, 0.85e-3, 0.0, 0.3e-3), (3, 0.0, 0.2e-3, 2.0e-3)]
    text = "id,x,y,z,radius\n" + "".join(f"{i},{x!r},{y!r},{z!r},{r!r}\n" for i, x, y, z in rows)
    p = write(tmp_path, "s.csv", text)
    with pytest.raises(FileFormatError) as info:
        read_particles_csv(p)
    assert str(info.value).startswith(f"{p}: 3D data: column 'z' spreads over 0.002 m (4 times")
    # projection: spheres 1-2 overlap in 3D; 1-3 overlap only as disks
    proj = read_particles_csv(p, z_policy="project")
    np.testing.assert_array_equal(np.c_[proj.contact_i, proj.contact_j], [[0, 1]])
    np.testing.assert_allclose(proj.contact_normals(), [[1.0, 0.0]])
    # the slice z = 0 cuts spheres 1 and 2 (the second at 0.3 mm: radius 0.4 mm)
    cut = read_particles_csv(p, z_policy="slice", z0=0.0)
    np.testing.assert_array_equal(cut.ids, [1, 2])
    np.testing.assert_allclose(cut.radii, [r, 0.4e-3])
    assert cut.n_contacts == 1  # 0.85 mm apart, radii 0.5 + 0.4 mm
    # a flat z column is 2D data and stays a field
    flat = write(tmp_path, "f.csv", text.replace("0.0003,", "0.0,").replace("0.002,", "0.0,"))
    assert read_particles_csv(flat).n_particles == 3
    with pytest.raises(ValueError, match="^z_policy: "):
        read_particles_csv(p, z_policy="drop")
