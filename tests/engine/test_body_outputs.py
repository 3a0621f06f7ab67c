"""Bodies in the outputs: a clump run's snapshot carries every particle's grain
with its grain's centroid and angle, run.h5 keeps them to the bit, the VTK
export and the viewer's data carry them, a snapshot without them makes every
particle a grain of its own, and bad grain fields are refused."""

from __future__ import annotations

import base64
from pathlib import Path

import h5py
import numpy as np
import pytest
from clump_factories import trimer_pile

from grainlab import Simulation
from grainlab.cli import main
from grainlab.io.hdf5 import FORMAT_VERSION, ResultsFileError, ResultsWriter, read_results
from grainlab.io.vtk import clump_points, write_clumps_vtp
from grainlab.postprocess.vtk import export_vtk
from grainlab.snapshot import GRAIN_ANGLE_FIELD, GRAIN_CENTROID_FIELD, GRAIN_FIELD, Snapshot
from grainlab.viewer.data import viewer_data


def _settling_clumps() -> Simulation:
    """Six trimers and one disk falling into a box."""
    return trimer_pile(np.linspace(0.0, 2.0, 6), with_disk=True)


@pytest.fixture(scope="module")
def clump_run(tmp_path_factory) -> tuple[Path, list[Snapshot]]:
    sim = _settling_clumps()
    folder = tmp_path_factory.mktemp("clump_run")
    snaps = []
    with ResultsWriter(folder / "run.h5", kind="biaxial") as writer:
        for k in range(3):
            sim.run(5000)
            snap = sim.snapshot(axial_strain=1e-3 * k)
            writer.write_snapshot(f"s{k}", snap)
            snaps.append(snap)
    return folder, snaps


def test_a_clump_runs_snapshot_carries_each_particles_grain_centroid_and_angle():
    sim = _settling_clumps()
    sim.run(2000)
    snap = sim.snapshot()
    clumps = sim.clumps
    # the disk came first, so the clumps are grains 0-5 and the disk grain 6
    np.testing.assert_array_equal(snap.grains(), [6] + [g for g in range(6) for _ in range(3)])
    assert snap.n_grains == 7
    centroid = np.asarray(snap.particle_fields[GRAIN_CENTROID_FIELD])
    angle = np.asarray(snap.particle_fields[GRAIN_ANGLE_FIELD])
    np.testing.assert_array_equal(centroid[1::3], clumps.centroid_m)
    np.testing.assert_array_equal(angle[1::3], clumps.angle_rad)
    np.testing.assert_array_equal(centroid[0], sim.positions[0])
    assert angle[0] == sim.rotations[0]


def test_run_h5_keeps_the_grains_to_the_bit(clump_run):
    folder, snaps = clump_run
    results = read_results(folder / "run.h5")
    for k, snap in enumerate(snaps):
        back = results.snapshot(f"s{k}")
        np.testing.assert_array_equal(back.grains(), snap.grains())
        for name in (GRAIN_CENTROID_FIELD, GRAIN_ANGLE_FIELD):
            np.testing.assert_array_equal(back.particle_fields[name], snap.particle_fields[name])


def test_run_h5_stores_one_row_per_grain(clump_run):
    """Layout 3: ``grain`` per particle, ``grains/label, centroid, angle`` per grain."""
    folder, snaps = clump_run
    snap = snaps[-1]
    with h5py.File(folder / "run.h5") as f:
        assert f.attrs["format_version"] == FORMAT_VERSION == 3
        group = f["snapshots/s2"]
        np.testing.assert_array_equal(group["grain"][()], snap.grains())
        np.testing.assert_array_equal(group["grains/label"][()], np.arange(7))
        rows = {name: group[f"grains/{name}"][()] for name in ("centroid", "angle")}
        units = {name: group[f"grains/{name}"].attrs["units"] for name in ("centroid", "angle")}
        assert set(group["particle_fields"]) == {"velocity", "angular_velocity"}
    # the clumps (grains 0-5) as the engine has them, the disk (grain 6) at its centre
    centroid = np.asarray(snap.particle_fields[GRAIN_CENTROID_FIELD])
    angle = np.asarray(snap.particle_fields[GRAIN_ANGLE_FIELD])
    assert rows["centroid"].tobytes() == np.r_[centroid[1::3], centroid[:1]].tobytes()
    assert rows["angle"].tobytes() == np.r_[angle[1::3], angle[:1]].tobytes()
    assert units == {"centroid": "m", "angle": "rad"}


def test_a_layout_2_file_with_grain_fields_reads_them(clump_run, tmp_path):
    """Layout 2 kept the grains as three per-particle fields; such a file reads as it was."""
    _, snaps = clump_run
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as writer:
        writer.write_snapshot("s", snaps[0])
    with h5py.File(tmp_path / "run.h5", "r+") as f:
        f.attrs["format_version"] = 2
        group = f["snapshots/s"]
        for name in ("grain", "grains"):
            del group[name]
        for name in (GRAIN_FIELD, GRAIN_CENTROID_FIELD, GRAIN_ANGLE_FIELD):
            group["particle_fields"].create_dataset(name, data=snaps[0].particle_fields[name])
    back = read_results(tmp_path / "run.h5").snapshot("s")
    for name in (GRAIN_FIELD, GRAIN_CENTROID_FIELD, GRAIN_ANGLE_FIELD):
        np.testing.assert_array_equal(back.particle_fields[name], snaps[0].particle_fields[name])


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda g: g["grains/label"].__setitem__(6, 9), r"/grain: particle 0's grain 6 is not in grains/label"),
        (lambda g: g["grains/label"].__setitem__(0, 3), r"grains/label: the labels do not increase"),
        (lambda g: g.__delitem__("grains"), r"a 'grain' dataset without 'grains/label'"),
    ],
)
def test_a_damaged_grains_group_is_refused(clump_run, tmp_path, damage, message):
    _, snaps = clump_run
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as writer:
        writer.write_snapshot("s", snaps[0])
    with h5py.File(tmp_path / "run.h5", "r+") as f:
        damage(f["snapshots/s"])
    with pytest.raises(ResultsFileError, match=message):
        read_results(tmp_path / "run.h5").snapshot("s")


def test_the_vtk_export_and_the_viewer_carry_the_grains(clump_run):
    pytest.importorskip("vtkmodules.vtkIOXML")
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

    folder, snaps = clump_run
    export = export_vtk(folder, folder / "vtk")
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(export.files[-1]))
    reader.Update()
    points = reader.GetOutput().GetPointData()
    np.testing.assert_array_equal(vtk_to_numpy(points.GetArray(GRAIN_FIELD)), snaps[-1].grains())
    centroid = vtk_to_numpy(points.GetArray(GRAIN_CENTROID_FIELD))
    np.testing.assert_array_equal(centroid[:, :2], snaps[-1].particle_fields[GRAIN_CENTROID_FIELD])
    data = viewer_data(folder)
    grain = np.frombuffer(base64.b64decode(data["snapshots"][-1]["arrays"]["grain"]), dtype="<u4")
    np.testing.assert_array_equal(grain, snaps[-1].grains())
    # the page opens coloured by grain and outlines the clumps of 19 particles in 7 grains
    assert data["clumps"] is True
    assert [(s["n"], s["n_grains"]) for s in data["snapshots"]] == [(19, 7)] * 3


def test_the_viewer_of_a_run_of_disks_has_no_clumps(tmp_path):
    sim = Simulation([[1e-3, 1e-3], [3.5e-3, 1e-3], [6e-3, 1e-3]], np.full(3, 1e-3), 2650.0, time_step=1e-6)
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as writer:
        writer.write_snapshot("s0", sim.snapshot(axial_strain=0.0))
    data = viewer_data(tmp_path)
    assert data["clumps"] is False and data["snapshots"][0]["n_grains"] == 3
    grain = np.frombuffer(base64.b64decode(data["snapshots"][0]["arrays"]["grain"]), dtype="<u4")
    np.testing.assert_array_equal(grain, [0, 1, 2])


def test_the_vtk_export_writes_the_clumps_centroids_and_angles(clump_run):
    pytest.importorskip("vtkmodules.vtkIOXML")
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

    folder, snaps = clump_run
    export = export_vtk(folder, folder / "vtk_clumps")
    assert [f.name for f in export.clump_files] == ["clumps_0000.vtp", "clumps_0001.vtp", "clumps_0002.vtp"]
    assert export.clumps_pvd is not None and "clumps_0002.vtp" in export.clumps_pvd.read_text()
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(export.clump_files[-1]))
    reader.Update()
    out = reader.GetOutput()
    points, data = vtk_to_numpy(out.GetPoints().GetData()), out.GetPointData()
    centroid = np.asarray(snaps[-1].particle_fields[GRAIN_CENTROID_FIELD])[1::3]  # pebbles 1-3 are clump 0, ...
    angle = np.asarray(snaps[-1].particle_fields[GRAIN_ANGLE_FIELD])[1::3]
    assert points[:, :2].tobytes() == centroid.tobytes() and not points[:, 2].any()
    assert vtk_to_numpy(data.GetArray("angle")).tobytes() == angle.tobytes()
    np.testing.assert_array_equal(vtk_to_numpy(data.GetArray("grain")), np.arange(6))
    np.testing.assert_array_equal(vtk_to_numpy(data.GetArray("n_pebbles")), np.full(6, 3))
    np.testing.assert_allclose(vtk_to_numpy(data.GetArray("orientation"))[:, :2], np.c_[np.cos(angle), np.sin(angle)])
    assert vtk_to_numpy(out.GetFieldData().GetArray("n_clumps")).tolist() == [6]
    assert out.GetNumberOfVerts() == 6


def test_grainlab_export_names_the_clumps_files(clump_run, capsys):
    folder, _ = clump_run
    assert main(["export", str(folder), "--vtk", "--out", str(folder / "vtk_cli")]) == 0
    said = capsys.readouterr().out
    assert f"grainlab export: the clumps of 3 snapshot(s) -> {folder / 'vtk_cli' / 'clumps.pvd'}" in said


def test_no_clumps_file_without_clumps_or_their_centroids(tmp_path):
    disks = Snapshot([[0.0, 0.0], [3.0, 0.0]], [1.0, 1.0], rotations=[0.0, 1.0])
    labelled = Snapshot([[0.0, 0.0], [1.5, 0.0]], [1.0, 1.0], particle_fields={GRAIN_FIELD: [5, 5]})
    singles = Snapshot(
        [[0.0, 0.0], [3.0, 0.0]], [1.0, 1.0],
        particle_fields={GRAIN_FIELD: [0, 1], GRAIN_CENTROID_FIELD: [[0.0, 0.0], [3.0, 0.0]], GRAIN_ANGLE_FIELD: [0, 0]},
    )  # fmt: skip
    for snap in (disks, labelled, singles):
        assert clump_points(snap) is None
        assert write_clumps_vtp(tmp_path / "clumps.vtp", snap) is None
    assert not (tmp_path / "clumps.vtp").exists()


def test_a_snapshot_without_grains_makes_every_particle_its_own():
    snap = Snapshot([[0.0, 0.0], [3.0, 0.0]], [1.0, 1.0])
    np.testing.assert_array_equal(snap.grains(), [0, 1])
    assert snap.n_grains == 2
    # a disks-only simulation's snapshot is as it was: no grain fields at all
    sim = Simulation([[0.0, 0.0], [3e-3, 0.0]], [1e-3, 1e-3], 2650.0, time_step=1e-6)
    assert GRAIN_FIELD not in sim.snapshot().particle_fields


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({GRAIN_FIELD: [0, -1]}, r"particle_fields\['grain'\]: grain labels must be >= 0, got -1 at index 1"),
        ({GRAIN_FIELD: [0.5, 1]}, r"particle_fields\['grain'\]"),
        ({GRAIN_CENTROID_FIELD: [[0, 0], [1, 1]]}, r"'grain_centroid'\]: given without particle_fields\['grain'\]"),
        ({GRAIN_FIELD: [0, 0], GRAIN_ANGLE_FIELD: [0.0, np.nan]}, r"particle_fields\['grain_angle'\]"),
        ({GRAIN_FIELD: [0, 0], GRAIN_CENTROID_FIELD: [1.0, 2.0]}, r"particle_fields\['grain_centroid'\]"),
    ],
)
def test_bad_grain_fields_are_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        Snapshot([[0.0, 0.0], [1.5, 0.0]], [1.0, 1.0], particle_fields=fields)
