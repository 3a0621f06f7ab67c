"""The readers and `grainlab analyze` on dumps written by LAMMPS itself.

Fixture: tests/data/lammps_dump (see make_fixture.py there): 250 frictional
disks settled under gravity in a box of 65 frozen wall disks (type 2),
gran/hooke/history, `units si`; contacts from `compute property/local patom1
patom2` and `compute pair/local dist force fx fy p1 p2 p4`.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from grainlab import cli
from grainlab.io import FileFormatError, list_timesteps, read_lammps_dump, read_snapshot

DATA = Path(__file__).resolve().parents[1] / "data" / "lammps_dump"
COLUMNS = {
    "dist": "c_cpl[1]",
    "normal_force": "c_cpl[2]",
    "shear_x": "c_cpl[5]",
    "shear_y": "c_cpl[6]",
}
RHO, G, KN = 2650.0, 9.81, 8.45e7


@pytest.fixture(scope="module")
def snap():
    return read_lammps_dump(DATA / "atoms.dump", contacts=DATA / "contacts.dump", columns=COLUMNS)


def test_reads_atoms_and_all_listed_contacts(snap):
    assert snap.n_particles == 315
    assert snap.metadata["timestep"] == 650000
    assert snap.periodic == (False, False)  # boundary ff ff pp
    assert snap.n_contacts == 424  # every listed pair overlaps (checked by make_fixture.py)
    assert snap.metadata["contact_columns"]["i"] == "c_cid[1]"  # ids found without being named
    mobile = snap.particle_fields["type"] == 1
    assert mobile.sum() == 250
    # LAMMPS's own `compute contact/atom` averaged over the mobile disks (log.lammps): 3.208
    assert snap.contact_counts()[mobile].mean() == pytest.approx(3.208, abs=1e-12)


def test_contacts_agree_with_the_geometry(snap):
    geo = read_lammps_dump(DATA / "atoms.dump")

    def pairs(s):
        return {tuple(sorted(p)) for p in np.c_[s.ids[s.contact_i], s.ids[s.contact_j]].tolist()}

    assert pairs(geo) == pairs(snap)
    d = snap.positions[snap.contact_j] - snap.positions[snap.contact_i]
    overlap = snap.radii[snap.contact_i] + snap.radii[snap.contact_j] - np.hypot(d[:, 0], d[:, 1])
    np.testing.assert_allclose(snap.normal_force, KN * overlap, rtol=1e-6)


def test_force_signs_balance_the_dumped_atom_forces(snap):
    """Sum over contacts of (-Fn n + Fs t) on i (minus on j) plus gravity = dumped f."""
    n = snap.contact_normals()
    t = np.c_[-n[:, 1], n[:, 0]]
    f_on_i = -snap.normal_force[:, None] * n + snap.shear_force[:, None] * t
    total = np.zeros((snap.n_particles, 2))
    for axis in (0, 1):
        total[:, axis] = np.bincount(
            snap.contact_i, f_on_i[:, axis], snap.n_particles
        ) - np.bincount(snap.contact_j, f_on_i[:, axis], snap.n_particles)
    mobile = snap.particle_fields["type"] == 1
    total[:, 1] -= RHO * np.pi * snap.radii**2 * G
    scale = np.abs(snap.normal_force).max()
    residual = np.abs(total[mobile] - snap.particle_fields["force"][mobile]).max() / scale
    assert residual < 1e-9
    # the same normal forces from the pair force components fx fy (force on atom i)
    alt = read_lammps_dump(
        DATA / "atoms.dump",
        contacts=DATA / "contacts.dump",
        columns={"fx": "c_cpl[3]", "fy": "c_cpl[4]"},
    )
    np.testing.assert_allclose(alt.normal_force, snap.normal_force, rtol=1e-9)
    # p4 is the magnitude of the tangential force
    mag = read_lammps_dump(
        DATA / "atoms.dump", contacts=DATA / "contacts.dump", columns={"shear_force": "c_cpl[7]"}
    )
    np.testing.assert_allclose(mag.shear_force, np.abs(snap.shear_force), rtol=1e-9, atol=1e-15)


def test_two_frames(tmp_path):
    path = DATA / "atoms_2frames.dump"
    assert list_timesteps(path) == [650000, 652000]
    first = read_snapshot(path, timestep=650000, contacts=DATA / "contacts_2frames.dump")
    last = read_snapshot(path, contacts=DATA / "contacts_2frames.dump")
    assert first.metadata["timestep"] == 650000 and last.metadata["timestep"] == 652000
    assert "timestep 652000" in last.metadata["contacts"]
    assert last.n_contacts > 400


def test_grainlab_analyze_on_the_lammps_fixture(tmp_path, monkeypatch, capsys):
    present = tuple(m for m in cli.COMMAND_MODULES if importlib.util.find_spec(m) is not None)
    monkeypatch.setattr(cli, "COMMAND_MODULES", present)
    out = tmp_path / "out"
    columns = ",".join(f"{k}={v}" for k, v in COLUMNS.items())
    code = cli.main(
        [
            "analyze", str(DATA / "atoms_2frames.dump"),
            "--contacts", str(DATA / "contacts_2frames.dump"),
            "--reference", str(DATA / "atoms_2frames.dump"),
            "--reference-timestep", "650000",
            "--contact-columns", columns,
            "--out", str(out),
        ]
    )  # fmt: skip
    assert code == 0, capsys.readouterr().err
    summary = json.loads((out / "fabric.json").read_text())
    last = read_lammps_dump(
        DATA / "atoms_2frames.dump", contacts=DATA / "contacts_2frames.dump", columns=COLUMNS
    )
    first = read_lammps_dump(DATA / "atoms_2frames.dump", timestep=650000)
    assert summary["timestep"] == 652000
    assert summary["n_particles"] == 315
    assert summary["n_contacts"] == last.n_contacts
    assert summary["Z"] == pytest.approx(2 * last.n_contacts / 315)
    assert summary["a_n"] is not None and 0 <= summary["a_n"] < 1
    assert 0 < summary["mean_lambda"] < 0.5
    lines = (out / "particles.csv").read_text().splitlines()
    header = lines[0].split(",")
    rows = [ln.split(",") for ln in lines[1:]]
    col = {name: k for k, name in enumerate(header)}
    disp = np.array([float(r[col["displacement"]]) for r in rows])
    expected = np.hypot(*(last.positions - first.positions).T)
    np.testing.assert_allclose(disp, expected, rtol=1e-9, atol=1e-20)
    n_contacts = np.array([int(r[col["n_contacts"]]) for r in rows])
    np.testing.assert_array_equal(n_contacts, last.contact_counts())
    for name in ("contact_normals", "normal_forces", "map_stability_index", "map_displacement"):
        assert (out / f"{name}.png").exists() and (out / f"{name}.svg").exists()


def test_wall_disks_as_boundary_types(tmp_path, monkeypatch):
    snap = read_lammps_dump(
        DATA / "atoms.dump", contacts=DATA / "contacts.dump", columns=COLUMNS, boundary_types=(2,)
    )
    mobile = snap.particle_fields["type"] == 1
    np.testing.assert_array_equal(snap.is_sample, mobile)
    wall_pairs = ~mobile[snap.contact_i] | ~mobile[snap.contact_j]
    np.testing.assert_array_equal(snap.is_boundary_contact, wall_pairs)
    from grainlab.analysis import CoordinationNumber, StabilityIndex

    z = CoordinationNumber().compute(snap)
    assert z.n_particles == 250
    assert z.coordination_number == pytest.approx(2 * (~wall_pairs).sum() / 250)
    lam = StabilityIndex().compute(snap)
    assert np.isnan(lam.stability_index[~mobile]).all()
    # by default lambda counts the wall contacts: the mean contact count is LAMMPS's 3.208
    assert lam.n_contacts[mobile].mean() == pytest.approx(3.208, abs=1e-12)
    with pytest.raises(FileFormatError, match="boundary_types needs a 'type' column"):
        read_lammps_dump(_without_type(tmp_path), boundary_types=(2,))
    present = tuple(m for m in cli.COMMAND_MODULES if importlib.util.find_spec(m) is not None)
    monkeypatch.setattr(cli, "COMMAND_MODULES", present)
    code = cli.main(
        ["analyze", str(DATA / "atoms.dump"), "--boundary-types", "2", "--no-figures",
         "--out", str(tmp_path / "o")]
    )  # fmt: skip
    assert code == 0
    assert json.loads((tmp_path / "o" / "fabric.json").read_text())["n_particles"] == 250
    assert cli.main(["analyze", str(DATA / "atoms.dump"), "--boundary-types", "wall"]) == 2


def _without_type(tmp_path):
    text = (
        (DATA / "atoms.dump").read_text().replace("ITEM: ATOMS id type x", "ITEM: ATOMS id kind x")
    )
    p = tmp_path / "notype.dump"
    p.write_text(text)
    return p
