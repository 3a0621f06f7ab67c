"""Clumps in the LAMMPS export (grainlab.io.lammps_input, docs/lammps.md, "Clumps").

Fast tests check the files written for a dimer, a trimer and a disk in a fixed
periodic cell (molecule ids, image flags, the bodies' mass and inertia) and the
refusals. The side-by-side tests run the deck in LAMMPS on 2 MPI processes and the
same bodies in grainlab, and compare centroids, pebbles and spins at every dump;
they are skipped when LAMMPS or mpirun is absent.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from grainlab import ContactModel, Simulation
from grainlab.io.lammps_input import (
    LammpsFixedCell,
    LammpsShear,
    find_lammps,
    read_lammps_run,
    run_lammps_deck,
    write_lammps_fixed_cell,
    write_lammps_shear,
)
from grainlab.shapes import shape_template

CELL = 6e-3
R = 1e-3  # the clumps' circumscribed radius


def three_bodies(**model: float) -> Simulation:
    """A dimer straddling the cell's left edge moving right, a spinning trimer moving
    left into it, and a disk falling onto the trimer, in a fixed periodic cell."""
    sim = Simulation(np.empty((0, 2)), np.empty(0), 2650.0, contact_model=ContactModel(**model), time_step=1e-7,
                     threads=1)  # fmt: skip
    dimer, trimer = shape_template("dimer", 0.3), shape_template("trimer", 0.3)
    sim.add_clumps(dimer.offsets * R, dimer.radii * R, positions=[[0.1e-3, 1e-3]], angles=[0.3], density=2650.0)
    sim.add_clumps(trimer.offsets * R, trimer.radii * R, positions=[[3e-3, 1.5e-3]], angles=[1.0], density=2650.0)
    sim.add_particles([[3.4e-3, 4.2e-3]], [0.8e-3], [2650.0])
    sim.set_periodic_cell((0.0, 0.0), (CELL, CELL))
    sim.skin = 0.1e-3
    sim.velocities = np.array([[0.0, 0.0]] * 5 + [[0.0, -0.8]])  # (setting pebbles' velocities moves clumps)
    sim.set_clump_velocities([[1.0, 0.2], [-1.0, 0.0]], [0.0, 50.0])
    return sim


def test_files_carry_the_bodies(tmp_path):
    sim = three_bodies(friction=0.5)
    out = write_lammps_fixed_cell(sim, tmp_path, LammpsFixedCell(steps=1000, dump_every=100))
    assert out.steps == 1000 and out.dump_every == 100
    text = out.data_file.read_text().splitlines()
    atoms = np.array([line.split() for line in text[text.index("Atoms # sphere") + 2 :][:6]], float)
    molecules = np.array([line.split() for line in text[text.index("Molecules") + 2 :]], int)
    assert molecules[:, 1].tolist() == (np.asarray(sim.body_of_particles) + 1).tolist() == [1, 1, 2, 2, 2, 3]
    # every atom in the cell; unwrapped by its image flags each pebble is its clump's
    assert np.all((atoms[:, 4:6] >= 0.0) & (atoms[:, 4:6] < CELL))
    unwrapped = atoms[:, 4:6] + atoms[:, 7:9] * CELL
    assert atoms[:, 7].tolist() == [-1, 0, 0, 0, 0, 0]  # the dimer's left pebble lies across x = 0
    assert np.allclose(unwrapped, sim.positions, rtol=0, atol=1e-18)
    bodies = np.array([line.split() for line in (tmp_path / "bodies.grainlab").read_text().splitlines()[2:]], float)
    clumps = sim.clumps
    assert bodies[:, 0].tolist() == [1, 2]
    assert np.array_equal(bodies[:, 1], clumps.mass_kg) and np.array_equal(bodies[:, 7], clumps.moment_of_inertia_kg_m2)
    assert np.array_equal(bodies[:, 5] + bodies[:, 6], bodies[:, 7])  # a lamina: Ixx + Iyy = Izz
    assert np.allclose(bodies[:, 2:4], clumps.centroid_m % CELL, rtol=0, atol=1e-18)
    assert np.array_equal(bodies[:, 11:13], clumps.velocity_m_per_s)
    assert np.array_equal(bodies[:, 16], clumps.moment_of_inertia_kg_m2 * clumps.angular_velocity_rad_per_s)
    # the union counted once: a clump is lighter than its pebbles' sum
    assert np.all(clumps.mass_kg < [2650.0 * np.pi * np.sum(sim.radii[sim.body_of_particles == b] ** 2) for b in (0, 1)])
    deck = out.input_file.read_text()
    for line in ("atom_modify     map array", "read_data       data.grainlab fix mol NULL Molecules",
                 "group           clumps molecule <= 2", "fix             integrate disks nve/sphere disc",
                 "fix             rigid clumps rigid/small molecule infile bodies.grainlab",
                 "neigh_modify    delay 0 every 1 check yes exclude molecule/intra clumps", "run             1000"):  # fmt: skip
        assert line in deck
    assert "deform" not in deck
    settings = json.loads(out.settings_file.read_text())
    assert settings["protocol"] == "fixed_cell" and settings["n_clumps"] == 2 and settings["shear"] is None


def test_clumps_refused_where_lammps_cannot_carry_them(tmp_path):
    sim = three_bodies()
    with pytest.raises(ValueError, match=r"2 clump\(s\) cannot be sheared in LAMMPS: fix rigid/small keeps"):
        write_lammps_shear(sim, tmp_path, LammpsShear(1.0, 0.1))
    sim.local_damping = 0.3
    with pytest.raises(ValueError, match="fix damping/cundall damps each pebble's force"):
        write_lammps_fixed_cell(sim, tmp_path, LammpsFixedCell(100, local_damping="cundall"))
    fixed = three_bodies()
    fixed.fixity = np.array([3, 3, 0, 0, 0, 0], dtype=np.uint8)
    with pytest.raises(ValueError, match="fixed degrees of freedom"):
        write_lammps_fixed_cell(fixed, tmp_path, LammpsFixedCell(100))
    with pytest.raises(ValueError, match="steps"):
        LammpsFixedCell(0)
    assert not any(tmp_path.iterdir())  # refused before anything was written
    # omitted, the local damping is named among what the deck does not carry
    out = write_lammps_fixed_cell(sim, tmp_path, LammpsFixedCell(100))
    assert any("local damping 0.3 (LAMMPS has no damping of a rigid body's resultant" in d for d in out.dropped)


def side_by_side(sim: Simulation, folder: Path, steps: int, every: int) -> dict[str, np.ndarray]:
    """Run ``sim``'s deck in LAMMPS (2 processes) and ``sim`` itself; the largest
    differences at each dump of the clumps' centroids, the pebbles' and disk's
    positions (m) and the spins (rad/s), the largest spin and whether LAMMPS had
    a contact then."""
    write_lammps_fixed_cell(sim, folder, LammpsFixedCell(steps, every))
    run_lammps_deck(folder, processes=2)
    lammps = read_lammps_run(folder)
    assert len(lammps) == steps // every + 1

    def nearest(d: np.ndarray) -> np.ndarray:
        return np.asarray(d - CELL * np.round(d / CELL))

    rows = []
    for k, snap in enumerate(lammps):
        sim.run(every - 1 if k else 0)  # (the step after the last dump is run)
        grain, centroid = snap.particle_fields["grain"], snap.particle_fields["grain_centroid"]
        assert grain.tolist() == list(sim.body_of_particles)
        first = [int(np.flatnonzero(grain == b)[0]) for b in range(len(sim.clumps))]
        centroids, positions = sim.clumps.centroid_m, sim.positions
        before = np.r_[sim.clumps.angular_velocity_rad_per_s, sim.angular_velocities[-1]]
        sim.run(1)
        # LAMMPS dumps full-step spins, grainlab keeps half-step ones: their mean is the full step's
        spin = 0.5 * (before + np.r_[sim.clumps.angular_velocity_rad_per_s, sim.angular_velocities[-1]])
        rows.append((
            np.abs(nearest(centroid[first] - centroids)).max(),
            np.abs(nearest(snap.positions - positions)).max(),
            np.abs(snap.particle_fields["omegaz"][[*first, -1]] - spin).max(),
            np.abs(spin).max(),
            snap.n_contacts > 0,
        ))  # fmt: skip
    table = np.array(rows)
    names = ("centroid", "position", "spin", "largest_spin", "touching")
    return {name: table[:, k] for k, name in enumerate(names)}


needs_lammps = pytest.mark.skipif(
    find_lammps() is None or shutil.which("mpirun") is None, reason="LAMMPS or mpirun not installed"
)


@needs_lammps
def test_damped_frictionless_collisions_agree_to_round_off(tmp_path):
    # the same law (normal spring, normal dashpot that never pulls), the same time
    # levels (velocity Verlet's positions are leapfrog's), the same mass and
    # inertia: only round-off and LAMMPS's quaternion update of the angle differ
    sim = three_bodies(friction=0.0, normal_damping_ratio=0.3)
    diff = side_by_side(sim, tmp_path, steps=20000, every=500)
    print({k: float(v.max()) for k, v in diff.items()})
    assert diff["largest_spin"].max() > 500.0  # the collisions turned the bodies
    assert diff["centroid"].max() < 1e-11 and diff["position"].max() < 1e-11  # 1e-8 of a pebble's diameter
    assert diff["spin"].max() < 1e-6 * diff["largest_spin"].max()


@needs_lammps
def test_frictional_collisions_agree_to_the_torque_arm(tmp_path):
    # friction adds one difference of the law: LAMMPS's pair granular turns a pebble
    # by its shear force at r - delta/2 (the middle of the overlap), grainlab at r
    # (docs/lammps.md). At 1 m/s these pebbles overlap by delta = v sqrt(m*/kn) =
    # 6e-6 m at most, delta / 2r = 0.4 %: each collision's spins differ by that
    # order, and the velocities by as much of their change (1 m/s), so the bodies
    # drift apart by 0.4 % x 1 m/s x 2 ms = 8e-6 m over the run. Spins compared
    # between contacts (inside one, the small offset of the overlaps shows in full).
    sim = three_bodies(friction=0.5)
    diff = side_by_side(sim, tmp_path, steps=20000, every=500)
    free = diff["touching"] == 0
    print({k: float(v.max()) for k, v in diff.items()}, "between contacts:", float(diff["spin"][free].max()))
    assert diff["largest_spin"].max() > 500.0 and diff["touching"].sum() >= 2  # two collisions, dumped within
    assert diff["spin"][free].max() < 0.01 * diff["largest_spin"].max()  # two collisions of 0.4 % each
    assert diff["position"].max() < 1e-5 and diff["centroid"].max() < 1e-5
