"""Frictional cross-code check: grainlab against its own documented law and against LAMMPS.

The reference in ``tests/data/lammps_frictional/`` (see its README) is the
300-disk periodic packing of the frictionless check with a shear spring and
Coulomb friction, run 1,000 steps by LAMMPS (``gran/hooke/history``, kt = kn,
xmu = 0.5). Two laws are written out below in plain NumPy, independently of
the engine:

- grainlab's, as ``docs/contact-law.md`` states it: one scalar shear spring along
  the current tangent (it rotates with the contact), no increment on the first
  force evaluation from full-step velocities, cap at ``mu kn overlap``;
- LAMMPS's ``gran/hooke/history``: a shear vector projected on the new tangent
  every step (so it shrinks as the contact rotates), no update during setup.

grainlab must match the first to round-off; the second checks the harness
against LAMMPS. grainlab and LAMMPS then differ only by the projection, which the
packing's chaotic dynamics amplify (the measured table is in docs/contact-law.md).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from grainlab import ContactModel, Simulation

REF = Path(__file__).resolve().parents[1] / "data" / "lammps_frictional"
STEPS = (1, 10, 100, 200, 500, 1000)


def read_case():
    header = REF.joinpath("initial.txt").read_text().splitlines()[0]
    number = r"([-+0-9.eE]+)"
    case = {k: float(re.search(k + " " + number, header).group(1)) for k in ("xhi", "density", "kn", "kt", "mu", "dt")}
    table = np.loadtxt(REF / "initial.txt", comments="#")
    return case, table[np.argsort(table[:, 0])]


def lammps_positions(step: int) -> np.ndarray:
    """Unwrapped positions (columns xu yu of ``id xu yu vx vy omegaz fx fy tqz``), by id."""
    table = np.loadtxt(REF / f"dump.{step:04d}.txt", skiprows=9)
    return table[np.argsort(table[:, 0])][:, 1:3]


def documented_law(case, table, steps, *, project_like_lammps=False, skin=2e-3):
    """Positions after each of ``steps`` steps of the law in plain NumPy (leapfrog
    from full-step velocities: half kick first, as grainlab and velocity Verlet)."""
    side, kn, ks, mu, dt = case["xhi"], case["kn"], case["kt"], case["mu"], case["dt"]
    x, r, v, w = table[:, 1:3].copy(), table[:, 3], table[:, 4:6].copy(), table[:, 6].copy()
    m = case["density"] * np.pi * r**2
    inertia = 0.5 * m * r**2
    n = len(r)
    # every pair that can touch during the run (checked at the end)
    iu, ju = np.triu_indices(n, 1)
    d = x[ju] - x[iu]
    d -= side * np.round(d / side)
    near = np.sqrt((d * d).sum(1)) < r[iu] + r[ju] + skin
    iu, ju = iu[near], ju[near]
    ri, rj = r[iu], r[ju]
    reach = ri + rj
    spring = np.zeros((len(iu), 2)) if project_like_lammps else np.zeros(len(iu))
    start = x.copy()
    out = {}
    for step in range(max(steps) + 1):
        if step in steps:
            out[step] = x.copy()
        if step == max(steps):
            break
        first = step == 0  # no displacement has happened since the velocities were set
        d = x[ju] - x[iu]
        d -= side * np.round(d / side)
        dist_sq = (d * d).sum(1)
        touching = dist_sq < reach * reach
        dist = np.sqrt(dist_sq)
        normal = d / dist[:, None]
        tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
        dv = v[ju] - v[iu]
        vt = (dv * tangent).sum(1) - (w[iu] * ri + w[ju] * rj)
        fn = kn * (reach - dist)
        cap = mu * fn
        if project_like_lammps:
            s = spring
            if not first:
                s = s - ks * dt * vt[:, None] * tangent
                s = s - (s * normal).sum(1)[:, None] * normal
            size = np.sqrt((s * s).sum(1))
            over = size > cap
            s = s * np.where(over, cap / np.where(size > 0, size, 1.0), 1.0)[:, None]
            s[~touching] = 0.0
            spring = s
            fs = (s * tangent).sum(1)
            f_on_j = fn[:, None] * normal + s
        else:
            trial = spring - ks * vt * (0.0 if first else dt)
            fs = np.where(np.abs(trial) >= cap, np.copysign(cap, trial), trial)
            fs[~touching] = 0.0
            spring = fs
            f_on_j = fn[:, None] * normal + fs[:, None] * tangent
        f_on_j[~touching] = 0.0
        force = np.column_stack(
            [np.bincount(ju, f_on_j[:, c], minlength=n) - np.bincount(iu, f_on_j[:, c], minlength=n) for c in (0, 1)]
        )
        torque = -(np.bincount(iu, ri * fs, minlength=n) + np.bincount(ju, rj * fs, minlength=n))
        kick = 0.5 * dt if first else dt
        v += kick * force / m[:, None]
        w += kick * torque / inertia
        x += dt * v
    moved = np.sqrt(((x - start) ** 2).sum(1)).max()
    assert moved < 0.5 * skin, "a pair left out of the list may have touched"
    return out


@pytest.fixture(scope="module")
def references():
    case, table = read_case()
    steps = (0, *STEPS)
    return {
        "rotating": documented_law(case, table, steps),
        "projected": documented_law(case, table, steps, project_like_lammps=True),
    }


def max_difference(a, b, side):
    d = a - b
    d -= side * np.round(d / side)  # LAMMPS unwraps, grainlab wraps at list builds
    return float(np.abs(d).max())


def test_the_numpy_harness_reproduces_lammps(references):
    # the projected-spring variant is LAMMPS's law: equal to round-off (chaos amplifies it)
    case, _ = read_case()
    for step in STEPS:
        error = max_difference(references["projected"][step], lammps_positions(step), case["xhi"])
        assert error < 1e-10, f"step {step}: NumPy gran/hooke/history vs LAMMPS {error:.3e} m"


@pytest.mark.parametrize("threads", [1, 2])
def test_grainlab_follows_its_documented_law_and_lammps_on_the_first_step(references, threads):
    case, table = read_case()
    side = case["xhi"]
    model = ContactModel(normal_stiffness=case["kn"], shear_stiffness=case["kt"], friction=case["mu"])
    sim = Simulation(table[:, 1:3], table[:, 3], case["density"], contact_model=model, time_step=case["dt"], threads=threads)
    sim.set_periodic_cell((0.0, 0.0), (side, side))
    sim.velocities = table[:, 4:6]
    sim.angular_velocities = table[:, 6]
    done, sliding, rows = 0, 0, []
    for step in STEPS:
        sim.run(step - done)
        done = step
        sliding = max(sliding, int(sim.contacts().sliding.sum()))
        to_law = max_difference(sim.positions, references["rotating"][step], side)
        to_lammps = max_difference(sim.positions, lammps_positions(step), side)
        rows.append((step, to_law, to_lammps))
        assert to_law < 1e-9, f"step {step}: {to_law:.3e} m from the documented law"
    # the first step has no shear increment in either code: the same forces, to round-off
    assert rows[0][2] < 1e-15, f"step 1: {rows[0][2]:.3e} m from LAMMPS"
    # not vacuous: contacts slid, and the disks moved a good part of their size
    assert sliding > 10
    assert np.abs(lammps_positions(1000) - lammps_positions(1)).max() > 0.1e-3
    print("step, max |x - x_documented_law| (m), max |x - x_LAMMPS| (m)")
    for step, to_law, to_lammps in rows:
        print(f"{step:5d} {to_law:.2e} {to_lammps:.2e}")
