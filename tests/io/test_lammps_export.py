"""The LAMMPS export (grainlab.io.lammps_input) and the dumps read back.

Fast tests check the files written, the mapping of the contact law, the refusals
and the reading of a leaning (triclinic) cell. The slow test runs LAMMPS on 2 MPI
processes from the deck and compares the sheared packing with grainlab's own run
(docs/lammps.md, "Side by side"); it is skipped when LAMMPS or mpirun is absent.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from grainlab import ContactModel, Simulation
from grainlab.analysis.stress import contact_stress
from grainlab.io import read_lammps_dump
from grainlab.io.lammps_input import (
    LammpsShear,
    find_lammps,
    lammps_pair_coeff,
    read_lammps_run,
    run_lammps_deck,
    tsuji_restitution,
    write_lammps_shear,
)
from grainlab.snapshot import Snapshot, detect_contacts


def small_cell(**model: float) -> Simulation:
    """Nine disks on a square lattice, touching, in a periodic cell of 3 x 3 spacings."""
    spacing = 2e-3
    grid = np.array([(i + 0.5, j + 0.5) for i in range(3) for j in range(3)]) * spacing
    sim = Simulation(grid, 1e-3, 2650.0, contact_model=ContactModel(**model), time_step=1e-6, threads=1)
    sim.set_periodic_cell((0.0, 0.0), (3 * spacing, 3 * spacing))
    return sim


def test_tsuji_restitution_gives_the_damping_ratio():
    for zeta in (0.01, 0.05, 0.3, 0.6):
        e = tsuji_restitution(zeta)
        alpha = sum(c * e**k for k, c in enumerate((1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)))
        assert 0.0 < e < 1.0
        assert alpha == pytest.approx(2 * zeta, rel=1e-12)
    with pytest.raises(ValueError, match="normal_damping_ratio"):
        tsuji_restitution(0.7)


def test_pair_coeff_carries_the_law_and_refuses_what_lammps_cannot_say():
    plain = lammps_pair_coeff(ContactModel(normal_stiffness=1e7, shear_stiffness=5e6, friction=0.4))
    assert plain == "hooke 10000000 0 tangential linear_history 5000000 0 0.40000000000000002 damping velocity"
    damped = lammps_pair_coeff(
        ContactModel(normal_stiffness=4e6, shear_stiffness=1e6, friction=0.5, normal_damping_ratio=0.1, shear_damping_ratio=0.1)
    ).split()
    # tangential dashpot x * eta_n = 2 zeta_s sqrt(m* ks): x = sqrt(ks / kn) for equal ratios
    assert float(damped[6]) == pytest.approx(0.5, rel=1e-15)
    assert damped[-3:] == ["damping", "tsuji", "limit_damping"]
    with pytest.raises(ValueError, match="rolling"):
        lammps_pair_coeff(ContactModel(rolling_friction=0.1))
    with pytest.raises(ValueError, match="normal_damping_ratio > 0"):
        lammps_pair_coeff(ContactModel(shear_damping_ratio=0.1))


def test_data_file_and_deck(tmp_path):
    sim = small_cell(friction=0.3)
    sim.velocities = np.full((9, 2), 1e-3)
    sim.angular_velocities = np.arange(9.0)
    sim.local_damping = 0.2
    out = write_lammps_shear(sim, tmp_path, LammpsShear(shear_rate_per_s=2.0, final_strain=0.3))
    assert out.steps == round(0.3 / 2.0 / 1e-6) and out.dump_every == out.steps // 50
    text = out.data_file.read_text().splitlines()
    assert "9 atoms" in text and "0 0 0 xy xz yz" in text
    atoms = np.array([line.split() for line in text[text.index("Atoms # sphere") + 2 :][:9]], float)
    velocities = np.array([line.split() for line in text[text.index("Velocities") + 2 :]], float)
    assert np.allclose(atoms[:, 2], 2e-3) and np.allclose(atoms[:, 3], 2650.0)
    # whole velocities: the fluctuation plus the flow 2.0 * y along x
    assert np.allclose(velocities[:, 1], 1e-3 + 2.0 * atoms[:, 5], rtol=1e-15)
    assert np.allclose(velocities[:, 2], 1e-3) and np.allclose(velocities[:, 6], np.arange(9.0))
    deck = out.input_file.read_text()
    for line in ("dimension       2", "fix             integrate all nve/sphere disc", "set             type 1 density/disc 2650",
                 "fix             shear all deform 1 xy erate 2 remap v", f"run             {out.steps}"):  # fmt: skip
        assert line in deck
    assert "damping/cundall" not in deck and any("local damping 0.2" in d for d in out.dropped)
    cundall = write_lammps_shear(sim, tmp_path / "c", LammpsShear(2.0, 0.3, local_damping="cundall"))
    assert "fix             local all damping/cundall 0.20000000000000001 0.20000000000000001" in cundall.input_file.read_text()
    assert json.loads(out.settings_file.read_text())["shear"]["shear_rate_per_s"] == 2.0


def test_export_refuses_what_it_cannot_carry(tmp_path):
    with pytest.raises(ValueError, match="periodic cell"):
        write_lammps_shear(Simulation([[0.0, 0.0]], [1e-3], 2650.0), tmp_path, LammpsShear(1.0, 0.1))
    walled = small_cell()
    walled.add_line_wall((0.0, 0.0), (0.0, 1.0))
    with pytest.raises(ValueError, match="wall"):
        write_lammps_shear(walled, tmp_path, LammpsShear(1.0, 0.1))
    with pytest.raises(ValueError, match="rolling"):
        write_lammps_shear(small_cell(rolling_friction=0.1), tmp_path, LammpsShear(1.0, 0.1))
    clumped = small_cell()
    clumped.add_bodies([[0, 1]])
    with pytest.raises(ValueError, match=r"1 clump\(s\) cannot be sheared in LAMMPS: fix rigid/small keeps"):
        write_lammps_shear(clumped, tmp_path, LammpsShear(1.0, 0.1))
    with pytest.raises(ValueError, match="final_strain"):
        LammpsShear(1.0, -0.1)
    assert not any(tmp_path.iterdir())  # refused before anything was written


def test_leaning_cell_minimum_image_and_contacts():
    rng = np.random.default_rng(4)
    x, r = rng.uniform(0.0, 1.0, (300, 2)), rng.uniform(0.02, 0.04, 300)
    for tilt in (0.3, -0.45):
        a, b = np.array([1.0, 0.0]), np.array([tilt, 1.0])
        images = np.array([m * a + k * b for m in (-1, 0, 1) for k in (-1, 0, 1)])
        d = x[None, :, None, :] - x[:, None, None, :] + images[None, None]
        nearest = np.hypot(d[..., 0], d[..., 1]).min(axis=2)
        expected = {(i, j) for i, j in zip(*np.nonzero(nearest < r[:, None] + r[None, :]), strict=True) if i < j}
        i, j = detect_contacts(x, r, box=[[0, 1], [0, 1]], periodic=(True, True), tilt=tilt)
        assert set(zip(i.tolist(), j.tolist(), strict=True)) == expected
        snap = Snapshot(x, r, box=[[0, 1], [0, 1]], periodic=(True, True), tilt=tilt)
        lengths = np.hypot(*snap.minimum_image(x[j] - x[i]).T)
        assert np.all(lengths < r[i] + r[j])
    with pytest.raises(ValueError, match="y periodic"):
        Snapshot(x, r, box=[[0, 1], [0, 1]], periodic=(True, False), tilt=0.1)


def test_triclinic_dump_is_read_with_its_tilt(tmp_path):
    # two disks touching across the top edge of a cell leaning by xy = 0.3: the
    # image of disk 2 above the cell is disk 2 moved by (0.3, 1.0)
    dump = tmp_path / "atoms.dump"
    dump.write_text(
        "ITEM: TIME\n0.5\nITEM: TIMESTEP\n10\nITEM: NUMBER OF ATOMS\n2\n"
        "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 1.3 0.3\n0 1 0\n-0.1 0.1 0\n"
        "ITEM: ATOMS id x y radius\n1 0.5 0.98 0.05\n2 0.21 0.06 0.05\n"
    )
    snap = read_lammps_dump(dump)
    assert snap.tilt == 0.3 and snap.box.tolist() == [[0.0, 1.0], [0.0, 1.0]] and snap.time == 0.5
    assert snap.n_contacts == 1
    assert np.allclose(snap.minimum_image(snap.positions[1] - snap.positions[0]), [0.01, 0.08])
    dump.write_text(dump.read_text().replace("-0.1 0.1 0\n", "-0.1 0.1 0.2\n"))
    with pytest.raises(ValueError, match="out of the x-y plane"):
        read_lammps_dump(dump)


def window_medians(snapshots: list[Snapshot], windows) -> np.ndarray:
    """Median over each strain window of the stress ratio -sigma_xy / sigma_yy and of
    Z = 2 Nc / N, both from the contacts (Love-Weber over the cell's area)."""
    rows = []
    for snap in snapshots:
        stress = contact_stress(snap, area=float(np.prod(np.diff(snap.box, axis=1))))
        rows.append((snap.scalars["shear_strain"], -stress[0, 1] / stress[1, 1], 2 * snap.n_contacts / snap.n_particles))
    table = np.array(rows)
    return np.array(
        [np.median(table[(table[:, 0] >= lo - 1e-9) & (table[:, 0] <= hi + 1e-9), 1:], axis=0) for lo, hi in windows]
    )


@pytest.mark.slow
@pytest.mark.skipif(find_lammps() is None or shutil.which("mpirun") is None, reason="LAMMPS or mpirun not installed")
def test_simple_shear_in_lammps_on_two_processes_matches_grainlab(tmp_path: Path):
    from grainlab.samples.periodic import periodic_packing

    packed = periodic_packing(2000, seed=3)
    model = ContactModel(friction=0.5, normal_damping_ratio=0.05)
    sim = Simulation(packed.positions, packed.radii, packed.densities, contact_model=model,
                     time_step=packed.time_step, threads=1)  # fmt: skip
    cell = packed.cell
    assert cell is not None
    sim.set_periodic_cell(cell.origin, (cell.origin[0] + cell.a[0], cell.origin[1] + cell.b[1]))
    shear = LammpsShear(shear_rate_per_s=0.06, final_strain=0.4)  # inertial number about 2e-3
    out = write_lammps_shear(sim, tmp_path, shear)
    log = run_lammps_deck(tmp_path, processes=2)
    assert "on 2 procs" in log.read_text()
    lammps = read_lammps_run(tmp_path)
    assert len(lammps) == out.steps // out.dump_every + 1

    sim.set_velocity_gradient([[0.0, shear.shear_rate_per_s], [0.0, 0.0]])
    grainlab = []
    for k in range(len(lammps)):
        sim.run(out.dump_every if k else 0)
        grainlab.append(sim.snapshot(scalars={"shear_strain": shear.shear_rate_per_s * sim.time}))
    assert grainlab[-1].scalars["shear_strain"] == pytest.approx(lammps[-1].scalars["shear_strain"], rel=1e-12)
    assert grainlab[-1].tilt == pytest.approx(lammps[-1].tilt, rel=1e-9)

    # before the contacts' histories part (the first 1 % of strain) the codes agree closely
    early = window_medians(grainlab, [(0.004, 0.012)]) - window_medians(lammps, [(0.004, 0.012)])
    assert np.abs(early).max() < 0.02, early
    # after, medians over strain windows agree as grainlab's own runs from positions
    # moved by 1e-12 to 1e-8 m do (largest spread measured: 0.049 in the ratio, 0.064 in Z)
    windows = [(0.1, 0.25), (0.25, 0.4)]
    ours, theirs = window_medians(grainlab, windows), window_medians(lammps, windows)
    print("windows", windows, "grainlab", ours.round(3).tolist(), "LAMMPS", theirs.round(3).tolist())
    assert np.all(np.abs(ours[:, 0] - theirs[:, 0]) < 0.07), (ours, theirs)
    assert np.all(np.abs(ours[:, 1] - theirs[:, 1]) < 0.1), (ours, theirs)
    # not vacuous: the shear mobilised the packing and changed its contacts
    assert np.all(theirs[:, 0] > 0.2) and np.all(theirs[:, 1] < 3.9)


def test_grainlab_analyze_reads_the_decks_own_dumps(tmp_path, capsys):
    # the deck's `dump_modify ... time yes` opens every frame with ITEM: TIME, before
    # ITEM: TIMESTEP: format detection must take it for a LAMMPS dump, as the reader does
    from grainlab import cli
    from grainlab.io import detect_format

    side, r = 6, 0.5
    rows = "".join(
        f"{k + 1} {1.0 * (k % side) + r:.17g} {1.0 * (k // side) + r:.17g} {r}\n" for k in range(side * side)
    )
    dump = tmp_path / "atoms.dump"
    dump.write_text(
        f"ITEM: TIME\n0.25\nITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n{side * side}\n"
        f"ITEM: BOX BOUNDS pp pp pp\n0 {side}\n0 {side}\n-0.5 0.5\nITEM: ATOMS id x y radius\n{rows}"
    )
    assert detect_format(dump) == "lammps-dump"
    assert cli.main(["analyze", str(dump), "--tolerance", "1e-9", "--out", str(tmp_path / "out")]) == 0
    fabric = json.loads((tmp_path / "out" / "fabric.json").read_text())
    # a square lattice in a periodic box: four contacts per disk, two per disk in the count
    assert fabric["n_contacts"] == 2 * side * side
