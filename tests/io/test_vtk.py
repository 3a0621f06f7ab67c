"""ParaView export (grainlab.io.vtk, grainlab.postprocess.vtk, ``grainlab export --vtk``), read back by VTK's own reader.

Every file is parsed with ``vtkXMLPolyDataReader`` (the reader ParaView uses)
and compared exactly with the snapshot it came from; the ``.pvd`` is parsed
with ElementTree.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from grainlab.cli import main
from grainlab.io.hdf5 import ResultsWriter, read_results, snapshot_name
from grainlab.io.vtk import (
    CELL_CONTACT,
    CELL_PARTICLE,
    contact_lines,
    write_pvd,
    write_vtp,
)
from grainlab.postprocess.vtk import export_vtk
from grainlab.snapshot import Snapshot

vtk_xml = pytest.importorskip("vtkmodules.vtkIOXML")
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow  # noqa: E402

D = 1.0e-3
STRAINS = (0.0, 0.01, 0.02)


# ------------------------------------------------------------------ reading back
@dataclass
class PolyData:
    """A .vtp file as VTK's reader sees it, as NumPy arrays."""

    points: np.ndarray
    point_data: dict[str, np.ndarray]
    cell_data: dict[str, np.ndarray]
    field_data: dict[str, np.ndarray]
    verts: tuple[np.ndarray, np.ndarray]  # connectivity, offsets
    lines: tuple[np.ndarray, np.ndarray]
    n_polys: int
    n_strips: int


def _arrays(data) -> dict[str, np.ndarray]:
    out = {}
    for k in range(data.GetNumberOfArrays()):
        array = data.GetAbstractArray(k)
        out[array.GetName()] = vtk_to_numpy(array).copy()
    return out


def _cells(cell_array) -> tuple[np.ndarray, np.ndarray]:
    return (
        vtk_to_numpy(cell_array.GetConnectivityArray()).copy(),
        vtk_to_numpy(cell_array.GetOffsetsArray()).copy(),
    )


def read_vtp(path: Path) -> PolyData:
    """Read ``path`` with vtkXMLPolyDataReader; fail on any VTK error or warning."""
    window = vtkStringOutputWindow()
    vtkOutputWindow.SetInstance(window)
    events: list[str] = []
    reader = vtk_xml.vtkXMLPolyDataReader()
    for event in ("ErrorEvent", "WarningEvent"):
        reader.AddObserver(event, lambda _obj, name: events.append(name))
    reader.SetFileName(str(path))
    reader.Update()
    assert not events and reader.GetErrorCode() == 0, (events, window.GetOutput())
    assert window.GetOutput() == "", window.GetOutput()
    poly = reader.GetOutput()
    return PolyData(
        points=vtk_to_numpy(poly.GetPoints().GetData()).copy()
        if poly.GetNumberOfPoints()
        else np.zeros((0, 3)),
        point_data=_arrays(poly.GetPointData()),
        cell_data=_arrays(poly.GetCellData()),
        field_data=_arrays(poly.GetFieldData()),
        verts=_cells(poly.GetVerts()),
        lines=_cells(poly.GetLines()),
        n_polys=poly.GetNumberOfPolys(),
        n_strips=poly.GetNumberOfStrips(),
    )


def assert_same(actual: np.ndarray, expected: np.ndarray, *, bits: bool = False) -> None:
    """Equal values, NaN where NaN, same kind of dtype; with ``bits`` the same bytes."""
    expected = np.asarray(expected)
    assert actual.shape == expected.shape
    assert actual.dtype.kind == expected.dtype.kind, (actual.dtype, expected.dtype)
    np.testing.assert_array_equal(actual, expected)
    if bits:
        assert actual.astype(expected.dtype).tobytes() == expected.tobytes()


# ------------------------------------------------------------------ a small run
def _lattice(nx: int = 16, ny: int = 16) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    grains = np.c_[((i + 0.5 * (j % 2)) * D).ravel(), (j * D * np.sqrt(3) / 2).ravel()]
    lo, hi = grains.min(axis=0) - 0.75 * D, grains.max(axis=0) + 0.75 * D
    ys = np.arange(lo[1], hi[1], 0.5 * D)
    membrane = np.r_[np.c_[np.full_like(ys, lo[0]), ys], np.c_[np.full_like(ys, hi[0]), ys]]
    pos = np.vstack([grains, membrane])
    rad = np.r_[np.full(len(grains), 0.5 * D), np.full(len(membrane), 0.25 * D)]
    kind = np.r_[np.zeros(len(grains), np.int8), np.ones(len(membrane), np.int8)]
    return pos, rad, kind


def _sheared(pos: np.ndarray, gamma: float) -> np.ndarray:
    """Horizontal band of simple shear gamma, 4 D thick, through the middle."""
    y0 = pos[:, 1].mean()
    out = pos.copy()
    out[:, 0] += gamma * np.clip(pos[:, 1] - y0, -2 * D, 2 * D)
    return out


def write_tiny_run(folder: Path, *, velocity: bool = True, strains=STRAINS) -> Path:
    """A biaxial-like run.h5: a sheared lattice with membrane disks, one wall contact.

    Later snapshots store the particles shuffled; contacts carry forces and the
    engine's contact fields (overlap, sliding, bonded).
    """
    folder.mkdir(parents=True, exist_ok=True)
    pos0, rad, kind = _lattice()
    n = len(rad)
    ids = np.arange(100, 100 + n)
    order = np.random.default_rng(3).permutation(n)
    with ResultsWriter(folder / "run.h5", kind="biaxial", overwrite=True) as writer:
        writer.append_rows({"axial_strain": np.array(strains)})
        for k, e in enumerate(strains):
            pos = _sheared(pos0, 10.0 * e)
            sel = np.arange(n) if k == 0 else order
            extra = (
                {"particle_fields": {"velocity": np.tile([e, -e], (n, 1))[sel]}} if velocity else {}
            )
            snap = Snapshot.from_geometry(
                pos[sel],
                rad[sel],
                ids[sel],
                kind=kind[sel],
                rotations=np.full(n, e) + np.arange(n) * 1e-3,
                tolerance=0.02 * D,
                axial_strain=e,
                time=float(k),
                **extra,
            )
            nc = snap.n_contacts
            ci = np.r_[snap.contact_i, 0]
            cj = np.r_[snap.contact_j, -1]  # one wall contact: no line for it
            cp = np.r_[np.zeros((nc, 2)), [[0.0, -D]]]
            writer.write_snapshot(
                snapshot_name(e, digits=6) if len(set(strains)) == len(strains) else f"s{k}",
                snap.with_contacts(
                    ci,
                    cj,
                    normal_force=np.r_[np.arange(nc) + 0.5 + k / 3, 1e6],
                    shear_force=np.r_[-np.arange(nc) / 7, 2e6],
                    contact_point=cp,
                    contact_fields={
                        "overlap": np.r_[np.arange(nc) * 1e-9, 3e-6],
                        "sliding": np.r_[np.arange(nc) % 3 == 0, True],
                        "bonded": np.r_[np.zeros(nc, bool), False],
                    },
                ),
            )
    return folder


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    run = write_tiny_run(tmp_path_factory.mktemp("run"))
    return run, export_vtk(run)


# ------------------------------------------------------------------ the writer
AWKWARD = np.array([1 / 3, np.pi, 1e-300, -0.0, np.nextafter(1.0, 2.0), 5e-324, -1.5e300])


@pytest.mark.parametrize("binary", [True, False], ids=["binary", "ascii"])
def test_writer_round_trip_is_exact(tmp_path, binary):
    n = len(AWKWARD)
    pts = np.c_[AWKWARD, AWKWARD[::-1]]
    radius = AWKWARD.copy()
    radius[1] = np.inf
    radius[-1] = np.nan  # last: VTK's ASCII parser needs whitespace after it
    vec = np.c_[AWKWARD, -AWKWARD, AWKWARD[::-1] / 3]
    big = np.array([2**62, -(2**62), 0, 1, -1, 7, 2**40], np.int64)
    flag = np.arange(n) % 2 == 0
    lines = np.array([[0, 1], [1, 2], [6, 0]])
    force = np.array([5.0, 1 / 7, np.nan])
    count = np.array([1, 2, 3], np.uint32)
    path = write_vtp(
        tmp_path / "t.vtp",
        pts,
        lines=lines,
        point_data={"radius": radius, "v": vec, "id": big, "flag": flag},
        line_data={"f": force, "sliding": [True, False, True], "count": count},
        field_data={"axial_strain": [1 / 3], "n": [4]},
        binary=binary,
    )
    got = read_vtp(path)
    assert_same(got.points[:, :2], pts, bits=binary)
    assert_same(got.points[:, 2], np.zeros(n), bits=binary)
    assert_same(got.point_data["radius"], radius, bits=binary)
    assert_same(got.point_data["v"], vec, bits=binary)
    assert_same(got.point_data["id"], big)
    assert_same(got.point_data["flag"], flag.astype(np.int32))
    assert got.point_data["flag"].dtype == np.int32
    # cells: one vertex per point, then the lines
    assert_same(got.verts[0], np.arange(n))
    assert_same(got.verts[1], np.arange(n + 1))
    assert_same(got.lines[0], lines.ravel())
    assert_same(got.lines[1], [0, 2, 4, 6])
    assert got.n_polys == got.n_strips == 0
    nan_v = np.full(n, np.nan)
    assert_same(got.cell_data["cell_kind"], np.r_[np.zeros(n, np.int32), np.ones(3, np.int32)])
    assert_same(got.cell_data["f"], np.r_[nan_v, force], bits=binary)
    assert_same(got.cell_data["sliding"], np.r_[np.full(n, -1), 1, 0, 1].astype(np.int32))
    assert_same(got.cell_data["count"], np.r_[np.full(n, -1), 1, 2, 3].astype(np.int64))
    assert_same(got.field_data["axial_strain"], [1 / 3])
    assert_same(got.field_data["n"], np.array([4]))
    assert CELL_PARTICLE == 0 and CELL_CONTACT == 1


def test_negative_infinity_only_in_binary(tmp_path):
    value = np.array([1.0, -np.inf])
    got = read_vtp(write_vtp(tmp_path / "b.vtp", np.zeros((2, 2)), point_data={"r": value}))
    assert_same(got.point_data["r"], value, bits=True)
    with pytest.raises(ValueError, match="r: -inf cannot be written as ASCII"):
        write_vtp(tmp_path / "a.vtp", np.zeros((2, 2)), point_data={"r": value}, binary=False)


def test_writer_with_no_lines(tmp_path):
    got = read_vtp(write_vtp(tmp_path / "t.vtp", [[0.0, 1.0]], point_data={"r": [2.0]}))
    assert_same(got.points, np.array([[0.0, 1.0, 0.0]]))
    assert_same(got.lines[0], np.zeros(0, np.int64))
    assert_same(got.cell_data["cell_kind"], np.zeros(1, np.int32))
    assert got.field_data == {}


def test_writer_rejects_bad_input(tmp_path):
    out = tmp_path / "x.vtp"
    with pytest.raises(ValueError, match="lines: point index out of range"):
        write_vtp(out, np.zeros((2, 2)), lines=[[0, 2]])
    with pytest.raises(ValueError, match="lines: expected shape"):
        write_vtp(out, np.zeros((2, 2)), lines=[0, 1])
    with pytest.raises(ValueError, match="points"):
        write_vtp(out, np.zeros((2, 4)))
    with pytest.raises(ValueError, match="r:"):
        write_vtp(out, np.zeros((2, 2)), point_data={"r": [1.0]})
    with pytest.raises(ValueError, match="f:"):
        write_vtp(out, np.zeros((2, 2)), lines=[[0, 1]], line_data={"f": [1.0, 2.0]})
    with pytest.raises(ValueError, match="cell_kind"):
        write_vtp(out, np.zeros((2, 2)), lines=[[0, 1]], line_data={"cell_kind": [1]})
    with pytest.raises(ValueError, match="s: unsupported dtype"):
        write_vtp(out, np.zeros((2, 2)), point_data={"s": np.array(["a", "b"])})
    assert not out.exists()


def test_write_pvd_relative_paths(tmp_path):
    pvd = write_pvd(tmp_path / "a" / "s.pvd", [(0.5, tmp_path / "a" / "b" / "x.vtp")])
    data_set = ET.parse(pvd).getroot().find("./Collection/DataSet")
    assert data_set.get("file") == "b/x.vtp" and data_set.get("timestep") == "0.5"


# ------------------------------------------------------------------ a run exported
def test_pvd_lists_every_snapshot_with_its_axial_strain(exported):
    run, done = exported
    assert done.time_quantity == "axial_strain"
    assert done.pvd == run / "vtk" / "run.pvd"
    assert [f.name for f in done.files] == [f"snapshot_{k:04d}.vtp" for k in range(3)]
    root = ET.parse(done.pvd).getroot()
    assert root.get("type") == "Collection"
    sets = root.findall("./Collection/DataSet")
    assert [float(s.get("timestep")) for s in sets] == list(STRAINS)
    n = len(_lattice()[1])
    for s, written in zip(sets, done.files, strict=True):
        path = done.pvd.parent / s.get("file")
        assert path == written and path.is_file()
        assert read_vtp(path).points.shape == (n, 3)


def test_every_file_holds_its_snapshot_exactly(exported):
    run, done = exported
    results = read_results(run / "run.h5")
    snaps = [results.snapshot(name) for name in results.snapshot_names]
    assert len(snaps) == len(done.files) == 3
    for k, (snap, path) in enumerate(zip(snaps, done.files, strict=True)):
        got = read_vtp(path)
        n = snap.n_particles
        assert_same(got.points, np.c_[snap.positions, np.zeros(n)], bits=True)
        pd = got.point_data
        assert set(pd) == {
            "id",
            "kind",
            "radius",
            "displacement",
            "rotation",
            "n_contacts",
            "stability_index",
            "local_shear_strain",
            "in_shear_band",
            "velocity",
        }
        assert_same(pd["id"], np.asarray(snap.ids))
        assert_same(pd["kind"], np.asarray(snap.kind, np.int32))
        assert_same(pd["radius"], snap.radii, bits=True)
        assert_same(pd["rotation"], snap.rotations, bits=True)
        v = snap.particle_fields["velocity"]
        assert_same(pd["velocity"], np.c_[v, np.zeros(n)], bits=True)
        # n_contacts counted here one contact at a time, the wall contact included
        expected_counts = np.zeros(n, np.int32)
        for i, j in zip(snap.contact_i, snap.contact_j, strict=True):
            expected_counts[i] += 1
            if j >= 0:
                expected_counts[j] += 1
        assert_same(pd["n_contacts"], expected_counts)
        assert np.all(np.isnan(pd["stability_index"][snap.kind == 1]))
        lam = pd["stability_index"][snap.kind == 0]
        assert np.all((lam >= 0) & (lam <= 1))
        assert set(np.unique(pd["in_shear_band"])) <= {0, 1, 2}  # outside, dominant, conjugate
        # contacts: one line per particle-particle contact, in order, with its data
        pp = np.asarray(snap.contact_j) >= 0
        assert pp.sum() == snap.n_contacts - 1
        lines = np.c_[snap.contact_i[pp], snap.contact_j[pp]]
        m = len(lines)
        assert_same(got.lines[0], lines.ravel())
        assert_same(got.lines[1], 2 * np.arange(m + 1))
        assert_same(got.verts[0], np.arange(n))
        cd = got.cell_data
        assert set(cd) == {
            "cell_kind",
            "normal_force",
            "shear_force",
            "overlap",
            "sliding",
            "bonded",
        }
        assert_same(cd["cell_kind"], np.r_[np.zeros(n), np.ones(m)].astype(np.int32))
        nan = np.full(n, np.nan)
        assert_same(cd["normal_force"], np.r_[nan, snap.normal_force[pp]], bits=True)
        assert_same(cd["normal_force"][n:], np.arange(m) + 0.5 + k / 3)
        assert_same(cd["shear_force"], np.r_[nan, snap.shear_force[pp]], bits=True)
        assert_same(cd["overlap"], np.r_[nan, snap.contact_fields["overlap"][pp]], bits=True)
        sliding = np.asarray(snap.contact_fields["sliding"])[pp].astype(np.int32)
        assert_same(cd["sliding"], np.r_[np.full(n, -1, np.int32), sliding])
        assert_same(cd["bonded"], np.r_[np.full(n, -1, np.int32), np.zeros(m, np.int32)])
        assert 1e6 not in cd["normal_force"]  # the wall contact has no line
        assert_same(got.field_data["n_wall_contacts"], np.array([1]))
        assert_same(got.field_data["n_periodic_contacts"], np.array([0]))
        assert_same(got.field_data["axial_strain"], [STRAINS[k]])
        assert_same(got.field_data["time"], [float(k)])


def test_derived_fields_follow_the_imposed_shear(exported):
    _, done = exported
    pos0, rad, kind = _lattice()
    n = len(rad)
    pd = read_vtp(done.files[0]).point_data
    assert np.all(np.isnan(pd["local_shear_strain"]))
    assert not pd["in_shear_band"].any()
    assert_same(pd["displacement"], np.zeros((n, 3)))
    assert np.all(pd["n_contacts"][kind == 0] >= 2)

    got = read_vtp(done.files[-1])
    pd = got.point_data
    idx = pd["id"] - 100  # index in the first snapshot
    np.testing.assert_allclose(got.points[:, :2], _sheared(pos0, 0.2)[idx])
    expected = np.c_[(_sheared(pos0, 0.2) - pos0)[idx], np.zeros(n)]
    np.testing.assert_allclose(pd["displacement"], expected, rtol=0, atol=1e-15)
    assert np.any(pd["displacement"][:, 0] > 0.1 * D)
    gamma = pd["local_shear_strain"]
    y = pos0[idx, 1] - pos0[:, 1].mean()
    grains = pd["kind"] == 0
    inside = grains & (np.abs(y) < 1.2 * D)
    outside = grains & (np.abs(y) > 4 * D)
    assert np.nanmean(gamma[inside]) > 5 * np.nanmean(gamma[outside])
    band = pd["in_shear_band"] == 1  # the one imposed band is the dominant, accepted one
    assert band[inside].mean() > 0.9 and band[outside].mean() < 0.1
    assert not (pd["in_shear_band"] == 2).any()  # no conjugate band was imposed
    lines = got.lines[0].reshape(-1, 2)
    d = np.hypot(*(got.points[lines[:, 0], :2] - got.points[lines[:, 1], :2]).T)
    assert np.all(d < pd["radius"][lines[:, 0]] + pd["radius"][lines[:, 1]] + 0.05 * D)


def test_cli_export_ascii_matches_binary(exported, tmp_path, capsys):
    run, done = exported
    out = tmp_path / "pv"
    assert main(["export", str(run), "--vtk", "--out", str(out), "--ascii"]) == 0
    assert "3 snapshot(s)" in capsys.readouterr().out
    sets = ET.parse(out / "run.pvd").getroot().findall("./Collection/DataSet")
    assert [s.get("file") for s in sets] == [path.name for path in done.files]
    for path in done.files:
        assert 'format="ascii"' in (out / path.name).read_text()
        a, b = read_vtp(out / path.name), read_vtp(path)
        assert_same(a.points, b.points, bits=True)
        for name in ("point_data", "cell_data", "field_data"):
            da, db = getattr(a, name), getattr(b, name)
            assert list(da) == list(db)
            for key in da:
                assert da[key].dtype == db[key].dtype
                assert_same(da[key], db[key])
        assert_same(a.lines[0], b.lines[0])


def test_cli_export_without_velocity(tmp_path, capsys):
    run = write_tiny_run(tmp_path / "run", velocity=False, strains=(0.0, 0.01))
    assert main(["export", str(run / "run.h5"), "--vtk"]) == 0
    assert "time = axial_strain" in capsys.readouterr().out
    got = read_vtp(run / "vtk" / "snapshot_0001.vtp")
    assert "velocity" not in got.point_data and "rotation" in got.point_data
    assert main(["export", str(run)]) == 2  # no format chosen


def test_repeated_strain_falls_back_to_time(tmp_path):
    run = write_tiny_run(tmp_path / "run", strains=(0.0, 0.0))
    done = export_vtk(run, tmp_path / "out")
    assert done.time_quantity == "time" and done.times == (0.0, 1.0)
    sets = ET.parse(done.pvd).getroot().findall("./Collection/DataSet")
    assert [s.get("timestep") for s in sets] == ["0.0", "1.0"]


def test_wall_and_periodic_contacts_have_no_line(tmp_path):
    # a row of disks across a periodic x boundary: 0-1, 1-2 inside, 2-0 across
    box = [[0.0, 3.0], [-1.0, 1.0]]
    snap = Snapshot(
        positions=[[0.5, 0.0], [1.5, 0.0], [2.5, 0.0]],
        radii=[0.5, 0.5, 0.5],
        contact_i=[0, 1, 2, 1],
        contact_j=[1, 2, 0, -3],
        normal_force=[1.0, 2.0, 3.0, 4.0],
        contact_point=[[1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [1.5, 0.5]],
        box=box,
        periodic=(True, False),
        time=0.25,
    )
    lines, data, left_out = contact_lines(snap)
    assert_same(lines, np.array([[0, 1], [1, 2]]))
    assert_same(data["normal_force"], [1.0, 2.0])
    assert left_out == {"n_wall_contacts": 1, "n_periodic_contacts": 1}

    with ResultsWriter(tmp_path / "run.h5", kind="biaxial", overwrite=True) as writer:
        writer.write_snapshot("only", snap)
    done = export_vtk(tmp_path)
    assert done.time_quantity == "time" and done.times == (0.25,)
    got = read_vtp(done.files[0])
    assert_same(got.lines[0], np.array([0, 1, 1, 2]))
    assert_same(got.cell_data["normal_force"][3:], [1.0, 2.0])
    assert_same(got.point_data["n_contacts"], np.array([2, 3, 2], np.int32))
    assert_same(got.field_data["n_periodic_contacts"], np.array([1]))
    assert_same(got.field_data["n_wall_contacts"], np.array([1]))
    assert "axial_strain" not in got.field_data


def test_empty_run_is_refused(tmp_path):
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial", overwrite=True):
        pass
    with pytest.raises(ValueError, match="no snapshots"):
        export_vtk(tmp_path)


# ------------------------------------------------------------------ the ParaView recipe
def test_documented_paraview_recipe(exported):
    """The docs' setup, with the VTK filters behind ParaView's Glyph and Threshold."""
    from vtkmodules.vtkCommonDataModel import vtkDataObject
    from vtkmodules.vtkFiltersCore import vtkCellDataToPointData, vtkGlyph3D, vtkThreshold
    from vtkmodules.vtkFiltersGeneral import vtkShrinkFilter
    from vtkmodules.vtkFiltersSources import vtkGlyphSource2D

    _, done = exported
    reader = vtk_xml.vtkXMLPolyDataReader()
    reader.SetFileName(str(done.files[-1]))
    reader.Update()
    got = read_vtp(done.files[-1])

    circle = vtkGlyphSource2D()  # ParaView's "2D Glyph", type Circle: unit diameter
    circle.SetGlyphTypeToCircle()
    circle.SetResolution(64)
    glyph = vtkGlyph3D()
    glyph.SetInputConnection(reader.GetOutputPort())
    glyph.SetSourceConnection(circle.GetOutputPort())
    # Scale Array: radius, Scale Factor: 2
    glyph.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_POINTS, "radius")
    glyph.SetScaleModeToScaleByScalar()
    glyph.SetScaleFactor(2.0)
    glyph.OrientOff()
    glyph.Update()
    xmin, xmax, ymin, ymax, _, _ = glyph.GetOutput().GetBounds()
    r = got.point_data["radius"]
    x, y = got.points[:, 0], got.points[:, 1]
    tol = 1e-6 * D  # the glyph filter works in float32
    np.testing.assert_allclose([xmin, ymin], [(x - r).min(), (y - r).min()], rtol=0, atol=tol)
    np.testing.assert_allclose([xmax, ymax], [(x + r).max(), (y + r).max()], rtol=0, atol=tol)

    threshold = vtkThreshold()  # Threshold on normal_force drops the vertex cells (NaN)
    threshold.SetInputConnection(reader.GetOutputPort())
    threshold.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_CELLS, "normal_force")
    threshold.SetThresholdFunction(vtkThreshold.THRESHOLD_UPPER)
    threshold.SetUpperThreshold(0.0)
    threshold.Update()
    contacts = threshold.GetOutput()
    m = len(got.lines[0]) // 2
    assert contacts.GetNumberOfCells() == m
    kinds = vtk_to_numpy(contacts.GetCellData().GetArray("cell_kind"))
    assert np.all(kinds == CELL_CONTACT)

    # Threshold cell_kind 1..1, Shrink (factor 1), Cell Data to Point Data: every line
    # end carries its own line's force, ready for Tube's "Vary Radius: By Scalar"
    lines_only = vtkThreshold()
    lines_only.SetInputConnection(reader.GetOutputPort())
    lines_only.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_CELLS, "cell_kind")
    lines_only.SetThresholdFunction(vtkThreshold.THRESHOLD_BETWEEN)
    lines_only.SetLowerThreshold(CELL_CONTACT)
    lines_only.SetUpperThreshold(CELL_CONTACT)
    shrink = vtkShrinkFilter()
    shrink.SetShrinkFactor(1.0)
    shrink.SetInputConnection(lines_only.GetOutputPort())
    to_points = vtkCellDataToPointData()
    to_points.SetInputConnection(shrink.GetOutputPort())
    to_points.Update()
    ends = to_points.GetOutput()
    assert ends.GetNumberOfCells() == m and ends.GetNumberOfPoints() == 2 * m
    per_end = vtk_to_numpy(ends.GetPointData().GetArray("normal_force"))
    force = got.cell_data["normal_force"][len(got.points) :]
    order = [ends.GetCell(c).GetPointId(e) for c in range(m) for e in (0, 1)]
    assert_same(per_end[order], np.repeat(force, 2))
