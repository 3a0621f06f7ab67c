"""Readers of other codes' files (tests/data/other_codes, README there): PFC, YADE,
LIGGGHTS/LAMMPS legacy VTK and any CSV through a column mapping, checked for numbers."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from grainlab.analysis import StabilityIndex
from grainlab.io import (
    FileFormatError,
    MissingKindWarning,
    detect_format,
    read_legacy_vtk,
    read_particles_csv,
    read_pfc_balls,
    read_snapshot,
    read_yade_text,
)
from grainlab.snapshot import ParticleKind

FILES = Path(__file__).resolve().parents[1] / "data" / "other_codes"
OVERLAP = 2.0e-6
PAIRS = {(1, 2), (1, 3), (1, 4), (5, 6), (5, 7), (5, 8), (5, 9)}
RADIUS_MM = {1: 1.0, 2: 0.8, 3: 0.9, 4: 1.1, 5: 1.0, 6: 0.7, 7: 0.7, 8: 0.7, 9: 0.7, 10: 0.6}


def _pairs(snap):
    ids = np.asarray(snap.ids)
    return {tuple(sorted((int(ids[i]), int(ids[j])))) for i, j in zip(snap.contact_i, snap.contact_j, strict=True)}


def _check_packing(snap, *, ids_known: bool = True):
    """The README's packing: radii, ball 3 at 90 degrees from ball 1, 7 contacts, lambda by hand."""
    assert snap.n_particles == 10
    if ids_known:
        by_id = {int(k): n for n, k in enumerate(snap.ids)}
    else:  # YADE's x_y_z_r has no ids: find the balls by their radii and places
        order = [4, 1, 7, 10, 2, 9, 5, 3, 8, 6]
        by_id = {bid: n for n, bid in enumerate(order)}
    for bid, r in RADIUS_MM.items():
        assert snap.radii[by_id[bid]] == pytest.approx(r * 1e-3, rel=1e-6)
    d = snap.positions[by_id[3]] - snap.positions[by_id[1]]
    assert d[0] == pytest.approx(0.0, abs=1e-9)
    assert d[1] == pytest.approx(1.9e-3 - OVERLAP, rel=1e-5)
    lam = StabilityIndex().compute(snap).stability_index
    assert lam[by_id[1]] == pytest.approx(1 / 6, abs=1e-6)  # contacts at 0, 90, 180 degrees
    assert lam[by_id[5]] == pytest.approx(0.0, abs=1e-6)  # at 0, 90, 180, 270
    assert lam[by_id[10]] == 1.0 and lam[by_id[2]] == 1.0
    if ids_known:
        assert _pairs(snap) == PAIRS
    else:
        assert snap.n_contacts == len(PAIRS)
    assert snap.contact_counts()[by_id[5]] == 4
    return by_id


def test_pfc_tables_with_their_contacts():
    with pytest.warns(MissingKindWarning, match="membrane or wall disks"):
        snap = read_pfc_balls(FILES / "pfc_balls.csv", contacts=FILES / "pfc_contacts.csv")
    by_id = _check_packing(snap)
    assert snap.metadata["format"] == "pfc-csv"
    # contact k of the table (end1, end2) carries force_normal = 10 k N
    ids = np.asarray(snap.ids)
    for k, (i, j, fn) in enumerate(zip(snap.contact_i, snap.contact_j, snap.normal_force, strict=True)):
        assert (int(ids[i]), int(ids[j])) == sorted(PAIRS)[k]
        assert fn == pytest.approx(10.0 * (k + 1))
    assert snap.shear_force is None  # PFC's own shear sign: not read unless mapped
    vel = snap.particle_fields["vel_x"]
    assert vel[by_id[7]] == pytest.approx(7e-4)


def test_pfc_table_detected_by_read_snapshot_and_contacts_from_geometry():
    assert detect_format(FILES / "pfc_balls.csv") == "pfc-csv"
    with pytest.warns(MissingKindWarning):
        snap = read_snapshot(FILES / "pfc_balls.csv")
    _check_packing(snap)
    with pytest.warns(MissingKindWarning):
        with_contacts = read_snapshot(FILES / "pfc_balls.csv", contacts=FILES / "pfc_contacts.csv")
    assert with_contacts.normal_force is not None and _pairs(with_contacts) == PAIRS


def test_any_csv_through_a_column_mapping(tmp_path):
    text = (FILES / "pfc_balls.csv").read_text().replace("ID,pos_x,pos_y,radius", "ball,X_m,Y_m,R_m")
    balls = tmp_path / "balls.csv"
    balls.write_text(text)
    contacts = tmp_path / "pairs.csv"
    contacts.write_text((FILES / "pfc_contacts.csv").read_text().replace("end1,end2", "first,second"))
    mapping = {"id": "ball", "x": "x_m", "y": "y_m", "radius": "R_m"}
    with pytest.warns(MissingKindWarning):
        snap = read_snapshot(balls, particle_columns=mapping, contacts=contacts,
                             columns={"i": "first", "j": "second", "normal_force": "force_normal"})
    _check_packing(snap)
    assert snap.normal_force.tolist() == pytest.approx([10.0 * k for k in range(1, 8)])
    assert snap.metadata["columns"]["x"] == "x_m"


@pytest.mark.parametrize(
    ("columns", "match"),
    [
        ({"id": "ball", "x": "x_m", "y": "y_m", "radius": "nope"}, r"radius=nope: no column 'nope'"),
        ({"id": "ball", "x": "x_m", "y": "y_m"}, r"missing column\(s\) radius .*--columns radius=NAME"),
    ],
)
def test_a_mapping_naming_a_missing_column_names_the_header_line(tmp_path, columns, match):
    f = tmp_path / "b.csv"
    f.write_text("# exported\nball,x_m,y_m,R_m\n1,0,0,0.001\n")
    with pytest.raises(FileFormatError, match=match) as error:
        read_particles_csv(f, columns=columns)
    assert error.value.line == 2


def test_bad_mappings_are_refused_before_reading(tmp_path):
    missing = tmp_path / "not_read.csv"
    with pytest.raises(ValueError, match="columns: unknown role 'radious'"):
        read_particles_csv(missing, columns={"radious": "r"})
    with pytest.raises(ValueError, match="column 'r' given two roles"):
        read_particles_csv(missing, columns={"radius": "r", "x": "R"})
    with pytest.raises(ValueError, match="contact_columns: only apply to a contacts file"):
        read_particles_csv(missing, contact_columns={"i": "end1"})


def test_a_mapping_onto_a_name_the_file_already_has_is_an_error(tmp_path):
    f = tmp_path / "b.csv"
    f.write_text("id,x,pos_x,y,radius\n1,0,0,0,0.001\n")
    with pytest.raises(FileFormatError, match="header also has a column 'x'"):
        read_particles_csv(f, columns={"x": "pos_x"})


def test_a_contact_end_that_is_no_ball_names_its_line(tmp_path):
    c = tmp_path / "c.csv"
    c.write_text("end1,end2\n1,2\n1,99\n")  # 99: a wall facet, not a ball
    with pytest.warns(MissingKindWarning), pytest.raises(FileFormatError, match="unknown particle id 99") as e:
        read_pfc_balls(FILES / "pfc_balls.csv", contacts=c)
    assert e.value.line == 3


def test_a_kind_column_silences_the_warning_and_grainlab_writes_one(tmp_path):
    from grainlab.io import write_particles_csv

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MissingKindWarning)
        snap = read_pfc_balls(FILES / "pfc_balls.csv")
    out = write_particles_csv(tmp_path / "p.csv", snap)
    assert out.read_text().splitlines()[0].startswith("id,x,y,radius,kind")
    with warnings.catch_warnings():
        warnings.simplefilter("error", MissingKindWarning)
        again = read_particles_csv(out)  # no warning
    assert again.n_contacts == len(PAIRS)


def test_yade_text_export():
    assert detect_format(FILES / "yade_spheres.txt") == "yade-text"
    with pytest.warns(MissingKindWarning):
        snap = read_snapshot(FILES / "yade_spheres.txt")
    _check_packing(snap, ids_known=False)
    assert snap.ids.tolist() == list(range(10))  # row numbers: x_y_z_r has no body ids
    assert snap.metadata["yade_format"] == "x_y_z_r"


def test_yade_formats_with_ids_materials_and_attributes(tmp_path):
    f = tmp_path / "ext.txt"
    f.write_text(
        "#format id_x_y_z_r_matId\n"
        "7\t0\t0\t0.5\t0.001\t0\n"
        "8\t0.00199\t0\t0.5\t0.001\t0\n"
        "9\t0\t0.00199\t0.5\t0.001\t3\n"
    )
    snap = read_yade_text(f, boundary_materials=[3])  # material 3 bounds the sample: no warning
    assert snap.ids.tolist() == [7, 8, 9]
    assert snap.kind.tolist() == [ParticleKind.SOIL, ParticleKind.SOIL, ParticleKind.MEMBRANE]
    assert snap.particle_fields["material_id"].tolist() == [0, 0, 3]
    assert snap.n_contacts == 2
    g = tmp_path / "attrs.txt"
    g.write_text("#format x_y_z_r_attrs\n# dstN\n0\t0\t0\t0.001\t4.5\n0.003\t0\t0\t0.001\t2\n")
    with pytest.warns(MissingKindWarning):
        snap = read_yade_text(g)
    assert snap.particle_fields["dstN"].tolist() == [4.5, 2.0]


@pytest.mark.parametrize(
    ("text", "line", "match"),
    [
        ("0 0 0 1\n", 1, "no '#format NAME' line"),
        ("#format x_y_z_r_color\n0 0 0 1\n", 1, "not supported"),
        ("#format x_y_z_r\n0\t0\t0\t0.001\n0\t1\t0\n", 3, "expected 4 fields, found 3"),
        ("#format x_y_z_r\n0\t0\t0\t0.001\n0\t0.001\t0.5\t0.001\n", None, "3D data"),
    ],
)
def test_yade_errors_name_the_line(tmp_path, text, line, match):
    f = tmp_path / "y.txt"
    f.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MissingKindWarning)
        with pytest.raises(FileFormatError, match=match) as error:
            read_yade_text(f)
    assert error.value.line == line


@pytest.mark.parametrize("name", ["liggghts_particles.vtk", "lammps_particles.vtk"])
def test_legacy_vtk_particles(name):
    path = FILES / name
    assert detect_format(path) == "legacy-vtk"
    snap = read_snapshot(path)
    by_id = _check_packing(snap)
    assert snap.particle_fields["v"].shape == (10, 2)  # vectors keep (x, y)
    assert snap.particle_fields["v"][by_id[9]] == pytest.approx([9e-4, -1.8e-3])
    assert snap.metadata["format"] == "legacy-vtk"


def test_legacy_vtk_boundary_types():
    snap = read_snapshot(FILES / "liggghts_particles.vtk", boundary_types=[2])
    ids = snap.ids.tolist()
    assert snap.kind[ids.index(10)] == ParticleKind.MEMBRANE
    assert int(np.sum(snap.kind == ParticleKind.MEMBRANE)) == 1


def test_vtk_reads_what_vtk_reads():
    """The same points and radii as VTK's own legacy reader."""
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    r = vtk.vtkPolyDataReader()
    r.SetFileName(str(FILES / "liggghts_particles.vtk"))
    r.ReadAllScalarsOn()  # every SCALARS section, not only the first
    r.Update()
    out = r.GetOutput()
    pts = vtk_to_numpy(out.GetPoints().GetData())
    snap = read_legacy_vtk(FILES / "liggghts_particles.vtk")
    np.testing.assert_allclose(snap.positions, pts[:, :2], rtol=1e-6)
    np.testing.assert_allclose(snap.radii, vtk_to_numpy(out.GetPointData().GetArray("radius")), rtol=1e-6)


@pytest.mark.parametrize(
    ("edit", "line", "match"),
    [
        (lambda t: t.replace("ASCII", "BINARY"), 3, "only ASCII"),
        (lambda t: t.replace("SCALARS radius", "SCALARS size"), 5, "no point array 'radius'"),
        (lambda t: t.replace("0.0011\n", "abc\n", 1), None, "cannot read 'abc'"),
        (lambda t: t.replace("POINT_DATA 10", "POINT_DATA 9"), None, "does not match the POINTS count"),
        (lambda t: t.rsplit("\n", 3)[0] + "\n", None, "file ends"),
    ],
)
def test_legacy_vtk_errors_name_the_line(tmp_path, edit, line, match):
    text = (FILES / "liggghts_particles.vtk").read_text()
    f = tmp_path / "bad.vtk"
    f.write_text(edit(text))
    with pytest.raises(FileFormatError, match=match) as error:
        read_legacy_vtk(f)
    if line is not None:
        assert error.value.line == line
    else:
        assert error.value.line is not None and error.value.line > 5


def test_cli_columns_option(tmp_path, capsys):
    import json

    from grainlab.cli import main

    balls = tmp_path / "balls.csv"
    balls.write_text((FILES / "pfc_balls.csv").read_text().replace("ID,pos_x,pos_y", "ball,px,py"))
    out = tmp_path / "out"
    code = main(["analyze", str(balls), "--columns", "id=ball,x=px,y=py", "--contacts",
                 str(FILES / "pfc_contacts.csv"), "--contact-columns", "i=end1,j=end2",
                 "--no-figures", "--out", str(out), "--quiet"])
    assert code == 0
    err = capsys.readouterr().err
    assert "warning" in err and "no 'kind' column" in err
    fabric = json.loads((out / "fabric.json").read_text())
    assert fabric["n_contacts"] == len(PAIRS)
    assert main(["analyze", str(balls), "--columns", "id=ball,x", "--out", str(out)]) == 2
    assert "--columns: expected ROLE=COLUMN" in capsys.readouterr().err


def test_hand_value_is_the_papers_rule():
    """1/6 from the definition itself (docs/fabric.md), independent of the readers."""
    from grainlab.analysis import stability_index_of_angles

    assert stability_index_of_angles([0.0, math.pi / 2, math.pi]) == pytest.approx(1 / 6)
