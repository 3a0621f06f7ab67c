"""ParaView export (grainlab.io.vtk, ``grainlab export --vtk``) read back by meshio and ElementTree."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from grainlab.cli import main
from grainlab.io.hdf5 import ResultsWriter, snapshot_name
from grainlab.io.vtk import VTK_LINE, VTK_VERTEX, export_vtk, write_pvd, write_vtu
from grainlab.snapshot import Snapshot

meshio = pytest.importorskip("meshio")

D = 1.0e-3
STRAINS = (0.0, 0.01, 0.02)


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


def write_tiny_run(folder: Path, *, velocity: bool = True) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    pos0, rad, kind = _lattice()
    n = len(rad)
    ids = np.arange(100, 100 + n)
    order = np.random.default_rng(3).permutation(n)  # later snapshots store particles shuffled
    with ResultsWriter(folder / "run.h5", kind="biaxial", overwrite=True) as writer:
        writer.append_rows({"axial_strain": np.array(STRAINS)})
        for k, e in enumerate(STRAINS):
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
                rotations=np.full(n, e),
                tolerance=0.02 * D,
                axial_strain=e,
                time=float(k),
                **extra,
            )
            ci = np.r_[snap.contact_i, 0]
            cj = np.r_[snap.contact_j, -1]  # one wall contact: no line for it
            cp = np.r_[np.zeros((snap.n_contacts, 2)), [[0.0, -D]]]
            force = np.r_[np.arange(snap.n_contacts, dtype=float), 1e6]
            writer.write_snapshot(
                snapshot_name(e),
                snap.with_contacts(ci, cj, normal_force=force, contact_point=cp),
            )
    return folder


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    run = write_tiny_run(tmp_path_factory.mktemp("run"))
    return run, export_vtk(run)


def test_writer_round_trip_ascii_and_binary(tmp_path):
    pts = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, -1.0]])
    for binary in (True, False):
        path = write_vtu(
            tmp_path / f"t{binary}.vtu",
            pts,
            lines=[[0, 1], [1, 2]],
            point_data={"r": [0.1, 0.2, np.nan], "v": np.ones((3, 3)), "k": np.array([0, 1, 2])},
            line_data={"f": [5.0, 6.0]},
            binary=binary,
        )
        m = meshio.read(path)
        np.testing.assert_array_equal(m.points[:, :2], pts)
        np.testing.assert_array_equal(m.points[:, 2], 0.0)
        np.testing.assert_array_equal(m.point_data["r"], [0.1, 0.2, np.nan])
        np.testing.assert_array_equal(m.point_data["v"], np.ones((3, 3)))
        np.testing.assert_array_equal(m.point_data["k"], [0, 1, 2])
        blocks = {c.type: c.data for c in m.cells}
        np.testing.assert_array_equal(blocks["vertex"].ravel(), [0, 1, 2])
        np.testing.assert_array_equal(blocks["line"], [[0, 1], [1, 2]])
        f = np.concatenate(m.cell_data["f"])
        np.testing.assert_array_equal(f, [np.nan, np.nan, np.nan, 5.0, 6.0])
        assert VTK_VERTEX == 1 and VTK_LINE == 3


def test_writer_rejects_bad_input(tmp_path):
    with pytest.raises(ValueError, match="lines"):
        write_vtu(tmp_path / "x.vtu", np.zeros((2, 2)), lines=[[0, 2]])
    with pytest.raises(ValueError, match="r:"):
        write_vtu(tmp_path / "x.vtu", np.zeros((2, 2)), point_data={"r": [1.0]})


def test_pvd_lists_files_with_axial_strain(exported):
    run, done = exported
    assert done.time_quantity == "axial_strain"
    assert done.pvd == run / "vtk" / "run.pvd"
    root = ET.parse(done.pvd).getroot()
    assert root.get("type") == "Collection"
    sets = root.findall("./Collection/DataSet")
    assert [float(s.get("timestep")) for s in sets] == list(STRAINS)
    assert [(done.pvd.parent / s.get("file")).is_file() for s in sets] == [True] * 3


def test_snapshot_files_round_trip(exported):
    run, done = exported
    pos0, rad, kind = _lattice()
    n = len(rad)
    first = meshio.read(done.files[0])
    assert first.points.shape == (n, 3)
    pd = first.point_data
    np.testing.assert_array_equal(pd["radius"], rad)
    np.testing.assert_array_equal(pd["kind"], kind)
    np.testing.assert_array_equal(pd["id"], np.arange(100, 100 + n))
    assert np.all(np.isnan(pd["local_shear_strain"]))
    assert not pd["in_shear_band"].any()
    np.testing.assert_array_equal(pd["displacement"], 0.0)
    assert np.all(np.isnan(pd["stability_index"][kind == 1]))
    assert np.all(pd["n_contacts"][kind == 0] >= 2)

    last = meshio.read(done.files[-1])
    pd = last.point_data
    ids = pd["id"] - 100  # index in the first snapshot
    np.testing.assert_allclose(last.points[:, :2], _sheared(pos0, 0.2)[ids])
    np.testing.assert_allclose(pd["displacement"][:, :2], (_sheared(pos0, 0.2) - pos0)[ids])
    np.testing.assert_allclose(pd["velocity"], np.tile([0.02, -0.02, 0.0], (n, 1)))
    np.testing.assert_allclose(pd["rotation"], 0.02)
    gamma = pd["local_shear_strain"]
    y = pos0[ids, 1] - pos0[:, 1].mean()
    grains = pd["kind"] == 0
    inside = grains & (np.abs(y) < 1.2 * D)
    outside = grains & (np.abs(y) > 4 * D)
    assert np.nanmean(gamma[inside]) > 5 * np.nanmean(gamma[outside])
    band = pd["in_shear_band"].astype(bool)
    assert band[inside].mean() > 0.9 and band[outside].mean() < 0.1
    # contact lines: particle-particle only, with their forces; the wall contact skipped
    lines = np.concatenate([c.data for c in last.cells if c.type == "line"])
    force = np.concatenate(last.cell_data["normal_force"])[n:]
    assert len(lines) == len(force) > n
    np.testing.assert_array_equal(force, np.arange(len(force), dtype=float))
    assert 1e6 not in force
    d = np.hypot(*(last.points[lines[:, 0], :2] - last.points[lines[:, 1], :2]).T)
    assert np.all(d < pd["radius"][lines[:, 0]] + pd["radius"][lines[:, 1]] + 0.05 * D)


def test_cli_export_without_velocity(tmp_path, capsys):
    run = write_tiny_run(tmp_path / "run", velocity=False)
    assert main(["export", str(run), "--vtk", "--out", str(tmp_path / "pv"), "--ascii"]) == 0
    assert "time = axial_strain" in capsys.readouterr().out
    m = meshio.read(tmp_path / "pv" / "snapshot_0002.vtu")
    assert "velocity" not in m.point_data and "rotation" in m.point_data
    assert main(["export", str(run)]) == 2  # no format chosen


def test_write_pvd_relative_paths(tmp_path):
    pvd = write_pvd(tmp_path / "a" / "s.pvd", [(0.5, tmp_path / "a" / "b" / "x.vtu")])
    assert ET.parse(pvd).getroot().find("./Collection/DataSet").get("file") == "b/x.vtu"
