"""Hertz-Mindlin step by step against LAMMPS, run live (skipped without it).

LAMMPS (``lmp`` on the path, or ``LAMMPS_BIN``) integrates the same disks with
``pair granular hertz/material E e nu damping coeff_restitution tangential
mindlin NULL 0.0 mu`` and ``fix nve/sphere disc`` in a periodic box; grainlab
runs them with ``ContactModel(law="hertz_mindlin")``. LAMMPS integrates with
velocity Verlet, grainlab with a leapfrog started from full-step velocities by
a half kick: the same positions in exact arithmetic (docs/contact-law.md).
LAMMPS keeps the tangential displacement as a vector that it turns onto the new
tangent plane keeping its length; grainlab's scalar along the current tangent is
that, and both take the torque's lever arm to the middle of the overlap
(``r - delta/2``), so positions must agree to round-off amplified by the
collisions (measured: 0 m for two disks, 3e-16 m for 200 disks after 1,000 steps;
with the full radius as lever arm the two disks were 3e-6 m apart).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from grainlab import ContactModel, Simulation

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from lammps_runner import find_lammps  # noqa: E402

LMP = find_lammps()
pytestmark = pytest.mark.skipif(LMP is None, reason="LAMMPS (lmp) is not installed")

DENSITY = 2650.0  # kg/m^3, unit thickness
YOUNG, POISSON, RESTITUTION, FRICTION = 1.0e7, 0.3, 0.8, 0.5
DT = 2.0e-5  # s; an impact at 0.2 m/s lasts ~200 steps
STEPS = (1, 10, 100, 250, 500, 750, 1000)
WALL_FIX = (
    f"fix floor all wall/gran granular hertz/material {YOUNG!r} {RESTITUTION!r} {POISSON!r}"
    f" damping coeff_restitution tangential mindlin NULL 0.0 {FRICTION!r} yplane 0.0 NULL"
)


def lammps_input(side: float, table: np.ndarray, dump_every: int, steps: int, wall: bool = False) -> str:
    atoms = "\n".join(
        f"create_atoms 1 single {x!r} {y!r} 0.0\n"
        f"set atom {i + 1} diameter {2 * r!r}\n"
        f"set atom {i + 1} density/disc {DENSITY!r}\n"
        f"set atom {i + 1} omega 0.0 0.0 {w!r}"
        for i, (x, y, r, _, _, w) in enumerate(table.tolist())
    )
    kicks = "\n".join(
        f"group g{i + 1} id {i + 1}\nvelocity g{i + 1} set {vx!r} {vy!r} 0.0\ngroup g{i + 1} delete"
        for i, (_, _, _, vx, vy, _) in enumerate(table.tolist())
    )
    return f"""units si
dimension 2
atom_style sphere
atom_modify map array
boundary p {"f" if wall else "p"} p
comm_modify vel yes
region box block 0 {side!r} 0 {side!r} -0.5 0.5 units box
create_box 1 box
{atoms}
{kicks}
pair_style granular
pair_coeff * * hertz/material {YOUNG!r} {RESTITUTION!r} {POISSON!r} damping coeff_restitution tangential mindlin NULL 0.0 {FRICTION!r}
neighbor {0.5 * float(table[:, 2].max())!r} bin
neigh_modify delay 0 every 1 check yes
fix integrate all nve/sphere disc
{WALL_FIX if wall else ""}
fix plane all enforce2d
timestep {DT!r}
thermo_modify lost error
dump out all custom {dump_every} dump.* id xu yu
dump_modify out format float %.17g sort id
run {steps}
"""


def run_lammps(tmp: Path, side: float, table: np.ndarray, wall: bool = False) -> dict[int, np.ndarray]:
    (tmp / "in.hm").write_text(lammps_input(side, table, 1, max(STEPS), wall))
    done = subprocess.run(
        [str(LMP), "-in", "in.hm", "-log", "none", "-screen", "none"], cwd=tmp, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return {step: np.loadtxt(tmp / f"dump.{step}", skiprows=9)[:, 1:3] for step in STEPS}


def run_grainlab(
    side: float, table: np.ndarray, threads: int, wall: bool = False
) -> tuple[dict[int, np.ndarray], int, int]:
    model = ContactModel(
        law="hertz_mindlin",
        youngs_modulus=YOUNG,
        poisson_ratio=POISSON,
        restitution=RESTITUTION,
        friction=FRICTION,
    )
    sim = Simulation(table[:, :2], table[:, 2], DENSITY, contact_model=model, time_step=DT, threads=threads)
    if wall:
        sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    else:
        sim.set_periodic_cell((0.0, 0.0), (side, side))
    sim.velocities = table[:, 3:5]
    sim.angular_velocities = table[:, 5]
    out, touched, slid = {}, 0, 0
    for step in range(1, max(STEPS) + 1):
        sim.run(1)
        contacts = sim.wall_contacts() if wall else sim.contacts()
        touched = max(touched, len(contacts.sliding))
        slid = max(slid, int(contacts.sliding.sum()))
        if step in STEPS:
            out[step] = sim.positions.copy()
    return out, touched, slid


def gas(count: int, side: float, seed: int) -> np.ndarray:
    """Non-overlapping disks (radii 0.8-1.2 mm) at random speeds (<= 0.3 m/s) and spins."""
    rng = np.random.default_rng(seed)
    rows: list[list[float]] = []
    while len(rows) < count:
        r = rng.uniform(0.8e-3, 1.2e-3)
        x, y = rng.uniform(0.0, side, 2)
        clear = True
        for xo, yo, ro, *_ in rows:
            d = np.array([x - xo, y - yo])
            d -= side * np.round(d / side)
            clear &= bool(np.hypot(*d) > r + ro + 1e-5)
        if clear:
            v = rng.uniform(-0.2, 0.2, 2)
            rows.append([x, y, r, v[0], v[1], rng.uniform(-50.0, 50.0)])
    return np.array(rows)


def worst(a: np.ndarray, b: np.ndarray, side: float) -> float:
    d = a - b
    d -= side * np.round(d / side)
    return float(np.abs(d).max())


def compare(tmp: Path, side: float, table: np.ndarray, threads: int, wall: bool = False) -> tuple[int, int]:
    lammps = run_lammps(tmp, side, table, wall)
    ours, touched, slid = run_grainlab(side, table, threads, wall)
    for step in STEPS:
        error = worst(ours[step], lammps[step], side)
        print(f"step {step:5d}: max |x - x_LAMMPS| = {error:.2e} m")
        assert error < 1e-9, f"step {step}: {error:.3e} m from LAMMPS"
    return touched, slid


@pytest.mark.parametrize("threads", [1, 2])
def test_two_disks_oblique_impact_matches_lammps(tmp_path, threads):
    side = 0.02
    table = np.array(
        [
            [0.0090, 0.0100, 1.0e-3, 0.15, 0.0, 0.0],
            [0.0115, 0.0104, 0.9e-3, -0.15, 0.0, 20.0],
        ]
    )
    touched, slid = compare(tmp_path, side, table, threads)
    assert touched == 1  # not vacuous: they collided


@pytest.mark.parametrize("threads", [1, 2])
def test_two_hundred_disks_match_lammps(tmp_path, threads):
    side = 0.045  # area fraction ~0.3
    table = gas(200, side, seed=7)
    touched, slid = compare(tmp_path, side, table, threads)
    assert touched > 20 and slid > 0  # collisions, some of them sliding


@pytest.mark.parametrize("threads", [1, 2])
def test_disks_on_a_wall_match_lammps(tmp_path, threads):
    # oblique, spinning impacts on the plane y = 0 (LAMMPS fix wall/gran, yplane);
    # the disks stay clear of each other and of the box's x edges
    table = np.array(
        [
            [0.004, 0.0012, 1.0e-3, 0.05, -0.15, 0.0],  # sticks, then rolls
            [0.010, 0.0015, 0.9e-3, 0.3, -0.1, -30.0],  # slides
            [0.016, 0.0011, 1.1e-3, -0.02, -0.2, 40.0],
        ]
    )
    touched, slid = compare(tmp_path, 0.02, table, threads, wall=True)
    assert touched >= 2 and slid > 0  # several at once, some sliding
