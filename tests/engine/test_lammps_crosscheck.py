"""Cross-code check against LAMMPS, a code none of us wrote.

The reference in ``tests/data/lammps_frictionless/`` (see its README) is a
300-disk dense frictionless packing in a periodic cell, no damping, run for
1,000 steps by LAMMPS (``gran/hooke``, ``nve/sphere disc``). LAMMPS integrates
with velocity Verlet; grainlab's leapfrog starts from full-step velocities with
a half kick, so positions agree to round-off, and full-step velocities are
``(v(n-1/2) + v(n+1/2)) / 2`` (docs/contact-law.md).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from grainlab import ContactModel, Simulation

REF = Path(__file__).resolve().parents[1] / "data" / "lammps_frictionless"
CHECK_STEPS = (1, 10, 100, 200, 300, 400, 500, 600, 700, 800, 900, 1000)


def read_initial():
    header = REF.joinpath("initial.txt").read_text().splitlines()[0]
    number = r"([-+0-9.eE]+)"
    hi = float(re.search(r"xhi " + number, header).group(1))
    density = float(re.search(r"density " + number, header).group(1))
    kn = float(re.search(r"kn " + number, header).group(1))
    dt = float(re.search(r"dt " + number, header).group(1))
    table = np.loadtxt(REF / "initial.txt", comments="#")
    table = table[np.argsort(table[:, 0])]
    return hi, density, kn, dt, table


def read_dump(step: int) -> np.ndarray:
    """Columns id x y ix iy xu yu vx vy omegaz fx fy, sorted by id."""
    table = np.loadtxt(REF / f"dump.{step:04d}.txt", skiprows=9)
    return table[np.argsort(table[:, 0])]


@pytest.mark.parametrize("threads", [1, 2])
def test_positions_and_kinetic_energy_match_lammps(threads):
    side, density, kn, dt, init = read_initial()
    sim = Simulation(
        init[:, 1:3],
        init[:, 3],
        density,
        contact_model=ContactModel(normal_stiffness=kn, shear_stiffness=kn, friction=0.0),
        time_step=dt,
        threads=threads,
    )
    sim.set_periodic_cell((0.0, 0.0), (side, side))
    sim.velocities = init[:, 4:6]
    sim.angular_velocities = init[:, 6]
    masses = sim.masses
    mean_diameter = 2 * init[:, 3].mean()
    done = 0
    errors = {}
    for step in CHECK_STEPS:
        sim.run(step - done)
        x = sim.positions.copy()
        v_before = sim.velocities.copy()
        sim.run(1)
        done = step + 1
        v_full = 0.5 * (v_before + sim.velocities)
        ref = read_dump(step)
        d = x - ref[:, 5:7]
        d -= side * np.round(d / side)  # LAMMPS unwraps, grainlab wraps at list builds
        position_error = np.abs(d).max() / mean_diameter
        ke = 0.5 * np.sum(masses * np.sum(v_full**2, axis=1))
        ke_ref = 0.5 * np.sum(masses * np.sum(ref[:, 7:9] ** 2, axis=1))
        errors[step] = (position_error, abs(ke / ke_ref - 1))
        assert position_error < 1e-6, f"step {step}: positions differ by {position_error:.3e} mean diameters"
        assert abs(ke / ke_ref - 1) < 1e-6, f"step {step}: kinetic energy {ke} vs LAMMPS {ke_ref}"
    # the comparison is not vacuous: the packing moved and energy changed form
    first, last = read_dump(1), read_dump(1000)
    assert np.abs(last[:, 5:7] - first[:, 5:7]).max() > 0.05 * mean_diameter
    print("step, max position difference / mean diameter, relative KE difference")
    for step, (dx, dk) in errors.items():
        print(f"{step:5d} {dx:.3e} {dk:.3e}")
