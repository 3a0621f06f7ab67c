"""Bodies in the outputs: a clump run's snapshot carries every particle's grain
with its grain's centroid and angle, run.h5 keeps them to the bit, the VTK
export and the viewer's data carry them, a snapshot without them makes every
particle a grain of its own, and bad grain fields are refused."""

from __future__ import annotations

import base64
from pathlib import Path

import numpy as np
import pytest
from clump_factories import trimer_pile

from grainlab import Simulation
from grainlab.io.hdf5 import ResultsWriter, read_results
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
