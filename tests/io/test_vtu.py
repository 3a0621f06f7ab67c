"""The .vtu twin of the .vtp writer (for meshio, which reads no PolyData) and the walls file."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.io.vtk import CELL_CONTACT, CELL_PARTICLE, CELL_WALL, write_vtu, write_walls_vtp

POINTS = np.array([[0.0, 0.0], [1e-3, 0.0], [2e-3, 5e-4]])
LINES = [[0, 1], [1, 2]]


@pytest.mark.parametrize("binary", [True, False])
def test_vtu_read_by_meshio(tmp_path, binary):
    meshio = pytest.importorskip("meshio")
    path = write_vtu(tmp_path / "s.vtu", POINTS, lines=LINES, point_data={"radius": [5e-4, 5e-4, 4e-4]},
                     line_data={"normal_force": [1.5, 2.5]}, binary=binary)
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points[:, :2], POINTS)
    blocks = {b.type: b.data for b in mesh.cells}
    assert blocks["vertex"].ravel().tolist() == [0, 1, 2]
    assert blocks["line"].tolist() == LINES
    np.testing.assert_array_equal(mesh.point_data["radius"], [5e-4, 5e-4, 4e-4])
    vertex_kind, line_kind = mesh.cell_data["cell_kind"]
    assert set(vertex_kind) == {CELL_PARTICLE} and set(line_kind) == {CELL_CONTACT}
    assert mesh.cell_data["normal_force"][1].tolist() == [1.5, 2.5]
    assert np.isnan(mesh.cell_data["normal_force"][0]).all()  # the vertex cells' fill


def test_vtu_read_by_vtk(tmp_path):
    vtk = pytest.importorskip("vtk")
    path = write_vtu(tmp_path / "s.vtu", POINTS, lines=LINES, field_data={"axial_strain": [0.01]})
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    grid = r.GetOutput()
    assert grid.GetNumberOfPoints() == 3 and grid.GetNumberOfCells() == 5
    assert [grid.GetCellType(k) for k in range(5)] == [1, 1, 1, 3, 3]  # VTK_VERTEX, VTK_LINE
    assert grid.GetCell(4).GetPointIds().GetId(1) == 2
    assert grid.GetFieldData().GetArray("axial_strain").GetValue(0) == 0.01


def test_walls_file_holds_lines_only(tmp_path):
    vtk = pytest.importorskip("vtk")
    segments = [[[0.0, 0.0], [0.02, 0.0]], [[0.02, 0.04], [0.0, 0.04]]]
    path = write_walls_vtp(tmp_path / "w.vtp", segments)
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(path))
    r.Update()
    poly = r.GetOutput()
    assert poly.GetNumberOfVerts() == 0 and poly.GetNumberOfLines() == 2
    p = poly.GetPoints()
    assert p.GetPoint(3) == (0.0, 0.04, 0.0)
    kinds = poly.GetCellData().GetArray("cell_kind")
    assert [kinds.GetValue(k) for k in range(2)] == [CELL_WALL, CELL_WALL]


def test_export_writes_vtu_twins_and_the_walls(tmp_path):
    meshio = pytest.importorskip("meshio")
    vtk = pytest.importorskip("vtk")
    from grainlab.io.hdf5 import ResultsWriter
    from grainlab.io.walls import WALL_LINE, WALL_SEGMENT, WallGeometry
    from grainlab.postprocess.vtk import export_vtk
    from grainlab.snapshot import Snapshot

    snap = Snapshot.from_geometry([[0.005, 0.001], [0.007, 0.001]], [1e-3, 1e-3], tolerance=1e-9, axial_strain=0.0)
    walls = WallGeometry(
        ("bottom", "top", "left"), [WALL_SEGMENT, WALL_SEGMENT, WALL_LINE],
        [[0.0, 0.0], [0.02, 0.002], [0.004, 0.0]], [[0.02, 0.0], [0.0, 0.002], [0.004, 0.0]],
        [[0.0, 1.0], [0.0, -1.0], [1.0, 0.0]], [True, True, True],
    )
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        out.write_snapshot("strain_0.0000", snap, walls=walls)
        out.write_snapshot("strain_0.0100", snap.with_contacts(snap.contact_i, snap.contact_j))  # no walls
    done = export_vtk(tmp_path)
    assert [f.name for f in done.vtu_files] == ["snapshot_0000.vtu", "snapshot_0001.vtu"]
    mesh = meshio.read(done.vtu_files[0])
    np.testing.assert_array_equal(mesh.points[:, :2], snap.positions)
    assert {b.type: len(b.data) for b in mesh.cells} == {"vertex": 2, "line": 1}
    assert "stability_index" in mesh.point_data
    assert [f.name for f in done.wall_files] == ["walls_0000.vtp"] and done.walls_pvd.name == "walls.pvd"
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(done.wall_files[0]))
    r.Update()
    poly = r.GetOutput()
    assert poly.GetNumberOfLines() == 3
    pts = np.array([poly.GetPoint(k) for k in range(poly.GetNumberOfPoints())])[:, :2]
    np.testing.assert_array_equal(pts[2:4], [[0.02, 0.002], [0.0, 0.002]])  # the top platen
    left = pts[4:6]  # the infinite line x = 0.004, clipped: vertical, beyond the particles' extent
    assert np.allclose(left[:, 0], 0.004) and left[:, 1].min() < 0.0 and left[:, 1].max() > 0.002
