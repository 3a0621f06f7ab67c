"""analyze_snapshot and `grainlab analyze` end to end on small CSV files."""

from __future__ import annotations

import csv
import importlib.util
import json

import numpy as np
import pytest
from factories_analysis import hex_lattice

from grainlab import cli
from grainlab.analysis import analyze_snapshot
from grainlab.io import write_contacts_csv, write_particles_csv
from grainlab.postprocess import write_analysis
from grainlab.snapshot import Snapshot


@pytest.fixture
def run_cli(monkeypatch):
    """cli.main with the analyze command; other subcommands may not exist in this checkout yet."""
    assert "grainlab.commands.analyze" in cli.COMMAND_MODULES
    present = tuple(m for m in cli.COMMAND_MODULES if importlib.util.find_spec(m) is not None)
    monkeypatch.setattr(cli, "COMMAND_MODULES", present)
    return cli.main


def read_rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def lattice_pair(tmp_path):
    """A small triangular lattice and a sheared copy, written as particles CSV files."""
    ref = hex_lattice(10, 12)
    d = 1e-3
    y = ref.positions[:, 1]
    band = np.abs(y - y.mean()) < 2.1 * d
    u = np.zeros_like(ref.positions)
    u[:, 0] = 0.02 * np.clip(y - y.mean(), -2.1 * d, 2.1 * d)
    cur = Snapshot(ref.positions + u, ref.radii, ids=ref.ids + 100)
    ref_ids = Snapshot(ref.positions, ref.radii, ids=ref.ids + 100)
    write_particles_csv(tmp_path / "ref.csv", ref_ids)
    write_particles_csv(tmp_path / "cur.csv", cur)
    return ref, cur, band


def test_cli_end_to_end_with_reference(tmp_path, run_cli, capsys):
    ref, cur, _ = lattice_pair(tmp_path)
    out = tmp_path / "out"
    code = run_cli(
        [
            "analyze",
            str(tmp_path / "cur.csv"),
            "--reference",
            str(tmp_path / "ref.csv"),
            "--tolerance",
            "1e-9",
            "--bins",
            "12",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    assert "grainlab analyze:" in capsys.readouterr().out
    rows = read_rows(out / "particles.csv")
    assert len(rows) == cur.n_particles
    for column in (
        "id",
        "x",
        "y",
        "radius",
        "n_contacts",
        "stability_index",
        "displacement",
        "local_shear_strain",
        "in_shear_band",
    ):
        assert column in rows[0]
    n = np.array([int(r["n_contacts"]) for r in rows])
    lam = np.array([float(r["stability_index"]) for r in rows])
    disp = np.array([float(r["displacement"]) for r in rows])
    # not periodic in the file: interior disks outside the sheared rows keep 6 contacts, lambda 0
    interior = n == 6
    assert interior.sum() >= 30
    np.testing.assert_allclose(lam[interior], 0.0, atol=1e-6)
    np.testing.assert_allclose(
        disp, np.hypot(*(cur.positions - ref.positions).T), rtol=1e-9, atol=1e-15
    )
    summary = json.loads((out / "fabric.json").read_text())
    assert summary["n_particles"] == cur.n_particles
    assert summary["Z"] == pytest.approx(2 * summary["n_contacts"] / cur.n_particles)
    assert summary["bins"] == 12
    assert summary["has_reference"] is True
    assert summary["band_angle_deg"] is not None
    assert min(summary["band_angle_deg"], 180 - summary["band_angle_deg"]) < 2.0
    for name in (
        "contact_normals",
        "map_stability_index",
        "map_contacts",
        "map_displacement",
        "map_shear_strain",
    ):
        assert (out / f"{name}.png").stat().st_size > 1000
        assert (out / f"{name}.svg").stat().st_size > 1000


def test_cli_without_reference_writes_empty_strain_columns(tmp_path, run_cli):
    ref = hex_lattice(6, 6)
    write_particles_csv(tmp_path / "p.csv", ref)
    snap = Snapshot.from_geometry(ref.positions, ref.radii, tolerance=1e-9)
    forces = np.linspace(1.0, 2.0, snap.n_contacts)
    snap = Snapshot(
        snap.positions,
        snap.radii,
        contact_i=snap.contact_i,
        contact_j=snap.contact_j,
        normal_force=forces,
    )
    write_contacts_csv(tmp_path / "c.csv", snap)
    out = tmp_path / "o"
    code = run_cli(
        [
            "analyze",
            str(tmp_path / "p.csv"),
            "--contacts",
            str(tmp_path / "c.csv"),
            "--no-figures",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    rows = read_rows(out / "particles.csv")
    assert all(
        r["displacement"] == "" and r["local_shear_strain"] == "" and r["in_shear_band"] == ""
        for r in rows
    )
    summary = json.loads((out / "fabric.json").read_text())
    assert summary["has_reference"] is False
    assert any("no reference snapshot" in note for note in summary["notes"])
    assert summary["band_angle_deg"] is None
    assert summary["n_contacts"] == snap.n_contacts
    assert summary["a_n"] is not None
    assert not list(out.glob("*.png"))


def test_cli_bad_input_exits_2_with_file_and_line(tmp_path, run_cli, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("id,x,y,radius\n1,0,0,0.5e-3\n2,1e-3,0,-0.5e-3\n")
    code = run_cli(["analyze", str(bad), "--out", str(tmp_path / "o")])
    assert code == 2
    err = capsys.readouterr().err
    assert f"{bad}:3:" in err and "radius" in err
    code = run_cli(["analyze", str(tmp_path / "missing.csv"), "--out", str(tmp_path / "o")])
    assert code == 2
    assert "file not found" in capsys.readouterr().err


def test_analyze_snapshot_api(tmp_path):
    snap = hex_lattice(rotation_deg=7.0)
    result = analyze_snapshot(snap)
    written = write_analysis(result, tmp_path, figures=False)
    assert [p.name for p in written] == ["particles.csv", "fabric.json"]
    assert json.loads((tmp_path / "fabric.json").read_text())["Z"] == 6.0
    s = result.summary()
    assert s["Z"] == 6.0 and s["mechanical_Z"] == 6.0
    assert s["a"] == pytest.approx(0.0, abs=1e-12) and s["a_fourier"] == pytest.approx(
        0.0, abs=1e-12
    )
    assert s["mean_lambda"] == pytest.approx(0.0, abs=1e-9)
    assert s["a_n"] is None and any("a_n" in note for note in s["notes"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fabric.json", "particles.csv"]


def test_run_h5_as_its_own_reference_defaults_to_the_strain_zero_snapshot(tmp_path, run_cli, capsys):
    # run.h5 as --reference: its first snapshot (strain 0) by default, not the last, which is the
    # analysed one (every displacement 0, no band) and is warned about when asked for explicitly
    from grainlab.io.hdf5 import ResultsWriter

    ref, cur, _ = lattice_pair(tmp_path)
    path = tmp_path / "run.h5"
    with ResultsWriter(path, kind="biaxial") as writer:
        writer.write_snapshot("strain_0.0000", Snapshot(ref.positions, ref.radii, ids=cur.ids), step=0)
        writer.write_snapshot("strain_0.0100", cur, step=1000)
    out = tmp_path / "out"
    argv = ["analyze", str(path), "--reference", str(path), "--no-figures", "--out", str(out)]
    assert run_cli(argv) == 0
    assert capsys.readouterr().err == ""
    disp = np.array([float(r["displacement"]) for r in read_rows(out / "particles.csv")])
    np.testing.assert_allclose(np.sort(disp), np.sort(np.hypot(*(cur.positions - ref.positions).T)), atol=1e-12)
    assert disp.max() > 0.04e-3  # 0.02 x 2.1 d at the band's edges
    assert run_cli([*argv[:4], "--reference-timestep", "1000", *argv[4:]]) == 0
    err = capsys.readouterr().err
    assert "the reference is the analysed snapshot itself" in err and "--reference-timestep" in err
    assert max(float(r["displacement"]) for r in read_rows(out / "particles.csv")) == 0.0
