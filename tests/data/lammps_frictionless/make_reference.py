#!/usr/bin/env python3
"""Regenerate the LAMMPS frictionless cross-code reference in this folder.

Steps (all deterministic for a given seed):
  1. build a dense, jammed, polydisperse periodic packing of N disks by
     minimising a harmonic overlap energy (FIRE) at a packing fraction above
     jamming, so the disks overlap and the coordination number is > 4, then
     shift each disk by a small random amount (X_JITTER) so that the initial
     net forces are not zero;
  2. give every disk a random translational velocity and spin (seeded);
  3. write initial.txt, data.frictionless and in.frictionless;
  4. run LAMMPS (1 MPI process) for N_STEPS steps, dumping at the steps
     0, 1, 10, 100, 200, ..., 1000;
  5. compute disk kinetic energies (I = m r^2 / 2) and the contact potential
     energy from the dumps and write kinetic_energy.txt.

Usage:  python3 make_reference.py [--lmp /usr/bin/lmp]
Needs numpy and a LAMMPS binary with the GRANULAR package.
"""

import argparse
import glob
import math
import os
import shutil
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

SEED = 20261121
N = 300
D_MIN, D_MAX = 0.5e-3, 3.0e-3  # diameters uniform in [D_MIN, D_MAX] (m)
PHI = 0.875  # packing fraction (disk area / cell area), above jamming
RHO = 2.0e8  # kg/m^3, disks of unit thickness: m = rho*pi*r^2
KN = 8.45e7  # N/m, contact normal stiffness
N_STEPS = 1000
V_RMS = 3.0e-3  # m/s, rms of each initial velocity component
X_JITTER = 2.0e-6  # m, rms of a random shift of each jammed position
DUMP_STEPS = [0, 1, 10] + list(range(100, N_STEPS + 1, 100))
SKIN = 1.0e-3  # neighbour skin (m)


# ---------------------------------------------------------------------------
# packing
# ---------------------------------------------------------------------------


def pair_terms(x, r, L):
    """All overlapping pairs (i<j) under the minimum-image convention.
    Returns i, j, d (x_i - x_j, minimum image), dist, overlap."""
    n = len(r)
    iu, ju = np.triu_indices(n, 1)
    d = x[iu] - x[ju]
    d -= L * np.round(d / L)
    dist = np.sqrt((d * d).sum(axis=1))
    ov = r[iu] + r[ju] - dist
    m = ov > 0
    return iu[m], ju[m], d[m], dist[m], ov[m]


def harmonic_forces(x, r, L, k=1.0):
    i, j, d, dist, ov = pair_terms(x, r, L)
    fpair = (k * ov / dist)[:, None] * d  # force on i, along x_i - x_j
    n = len(r)
    f = np.empty_like(x)
    for c in range(2):
        f[:, c] = np.bincount(i, fpair[:, c], minlength=n) - np.bincount(
            j, fpair[:, c], minlength=n
        )
    energy = 0.5 * k * (ov**2).sum()
    return f, energy, len(i)


def fire_minimise(x, r, L, ftol, max_iter=200000):
    """FIRE energy minimisation (unit masses, unit stiffness: time unit 1)."""
    dt_max = 0.2
    dt = 0.05
    alpha0, alpha = 0.1, 0.1
    n_pos = 0
    v = np.zeros_like(x)
    f, e, nc = harmonic_forces(x, r, L)
    for it in range(max_iter):
        fmax = np.abs(f).max()
        if fmax < ftol:
            break
        p = (f * v).sum()
        if p > 0:
            vn = np.linalg.norm(v)
            fn = np.linalg.norm(f)
            v = (1 - alpha) * v + alpha * vn * f / fn
            n_pos += 1
            if n_pos > 5:
                dt = min(1.1 * dt, dt_max)
                alpha *= 0.99
        else:
            n_pos = 0
            dt *= 0.5
            alpha = alpha0
            v[:] = 0.0
        v += dt * f
        x = x + dt * v
        x %= L
        f, e, nc = harmonic_forces(x, r, L)
    return x, e, nc, it, np.abs(f).max()


def make_packing(rng):
    d = rng.uniform(D_MIN, D_MAX, N)
    r = 0.5 * d
    L = math.sqrt(np.pi * (r**2).sum() / PHI)
    x = rng.uniform(0.0, L, (N, 2))
    # minimise overlaps to a force-balanced (jammed) state; the tolerance is a
    # small fraction of the typical overlap, in length units (k = 1)
    x, _e, nc, it, fres = fire_minimise(x, r, L, ftol=1e-9 * L)
    # then shift every disk a little so that the initial net forces are not zero
    # (this makes the first half step, dt/2 * F(x0)/m, matter in a comparison)
    x = (x + rng.normal(0.0, X_JITTER, x.shape)) % L
    nc = len(pair_terms(x, r, L)[0])
    return x, r, L, nc, it, fres


# ---------------------------------------------------------------------------
# files
# ---------------------------------------------------------------------------


def fmt(v):
    return f"{v:.17g}"


def write_initial(path, x, r, v, w, L, dt):
    with open(path, "w") as fh:
        fh.write(
            "# cell xlo %s xhi %s ylo %s yhi %s periodic; density %s kg/m^3 "
            "(unit thickness, m = rho*pi*r^2, I = m*r^2/2); kn %s N/m; dt %s s; "
            "n_steps %d; seed %d\n"
            % (fmt(0.0), fmt(L), fmt(0.0), fmt(L), fmt(RHO), fmt(KN), fmt(dt), N_STEPS, SEED)
        )
        fh.write("# id x y radius vx vy omega\n")
        fh.writelines(
            " ".join(
                [
                    str(k + 1),
                    fmt(x[k, 0]),
                    fmt(x[k, 1]),
                    fmt(r[k]),
                    fmt(v[k, 0]),
                    fmt(v[k, 1]),
                    fmt(w[k]),
                ]
            )
            + "\n"
            for k in range(len(r))
        )


def write_data(path, x, r, v, w, L, zhalf):
    with open(path, "w") as fh:
        fh.write("LAMMPS data file for grainlab frictionless reference (seed %d)\n\n" % SEED)
        fh.write("%d atoms\n1 atom types\n\n" % len(r))
        fh.write(f"{fmt(0.0)} {fmt(L)} xlo xhi\n")
        fh.write(f"{fmt(0.0)} {fmt(L)} ylo yhi\n")
        fh.write(f"{fmt(-zhalf)} {fmt(zhalf)} zlo zhi\n\n")
        # atom_style sphere: atom-ID atom-type diameter density x y z
        # (the density column here is overwritten by `set density/disc`)
        fh.write("Atoms # sphere\n\n")
        fh.writelines(
            "%d 1 %s %s %s %s 0\n" % (k + 1, fmt(2 * r[k]), fmt(RHO), fmt(x[k, 0]), fmt(x[k, 1]))
            for k in range(len(r))
        )
        # sphere: atom-ID vx vy vz wx wy wz
        fh.write("\nVelocities\n\n")
        fh.writelines(
            "%d %s %s 0 0 0 %s\n" % (k + 1, fmt(v[k, 0]), fmt(v[k, 1]), fmt(w[k]))
            for k in range(len(r))
        )


IN_TEMPLATE = """\
# grainlab cross-code reference: frictionless dense periodic 2D disk packing
# (generated by make_reference.py; run as: lmp -in in.frictionless -log log.lammps)
units           si
dimension       2
atom_style      sphere
boundary        p p p
atom_modify     map array
newton          on
processors      * * 1
comm_modify     vel yes

read_data       data.frictionless

# disk masses: m = rho * pi * r^2 (unit thickness); the data file density is ignored
set             type 1 density/disc {rho}

# linear normal spring only: kn, kt, gamma_n, gamma_t, xmu, dampflag
pair_style      gran/hooke {kn} 0.0 0.0 0.0 0.0 0
pair_coeff      * *

# size-based neighbour lists: a pair is listed when its gap is below the skin,
# every contact between the largest disks is covered (cutoff = 2*rmax + skin)
neighbor        {skin} bin
neigh_modify    delay 0 every 1 check yes

fix             integ all nve/sphere disc
fix             two all enforce2d

timestep        {dt}

# dump at steps 0, 1, 10, 100, 200, ..., {nsteps}
variable        nextdump equal "(step<1)*1 + (step>=1)*(step<10)*10 + (step>=10)*(floor(step/100)+1)*100"
dump            d all custom 1 dump.*.txt id x y ix iy xu yu vx vy omegaz fx fy
dump_modify     d every v_nextdump first yes pad 4 sort id format float %.17g

thermo_style    custom step atoms ke
thermo_modify   format float %.17g
thermo          100

run             {nsteps}
"""


def write_input(path, dt):
    with open(path, "w") as fh:
        fh.write(
            IN_TEMPLATE.format(rho=fmt(RHO), kn=fmt(KN), skin=fmt(SKIN), dt=fmt(dt), nsteps=N_STEPS)
        )


def read_dump(path):
    with open(path) as fh:
        lines = fh.readlines()
    step = int(lines[1])
    cols = lines[8].split()[2:]
    data = np.loadtxt(lines[9:])
    return step, {c: data[:, k] for k, c in enumerate(cols)}


def contact_energy(x, r, L):
    _, _, _, _, ov = pair_terms(x, r, L)
    return 0.5 * KN * (ov**2).sum(), len(ov)


def find_lmp(explicit=None):
    for cand in [explicit, os.environ.get("LAMMPS_BIN"), "lmp", "lmp_serial", "lmp_mpi", "lammps"]:
        if cand and shutil.which(cand):
            return shutil.which(cand)
    return None


def main():
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--lmp", help="LAMMPS binary (default: lmp on PATH)")
    args = ap.parse_args()
    lmp = find_lmp(args.lmp)
    if lmp is None:
        sys.exit("no LAMMPS binary found (apt-get install lammps)")

    rng = np.random.default_rng(SEED)
    x, r, L, nc, it, fres = make_packing(rng)
    z = 2.0 * nc / N
    print(
        "packing: N=%d L=%.6g m phi=%.4f contacts=%d Z=%.3f (FIRE %d iterations, "
        "residual %.3g)" % (N, L, np.pi * (r**2).sum() / L**2, nc, z, it, fres)
    )

    m = RHO * np.pi * r**2
    v = rng.normal(0.0, V_RMS, (N, 2))
    v -= (m[:, None] * v).sum(axis=0) / m.sum()  # zero total momentum
    w = rng.normal(0.0, 1.0, N) * V_RMS / r  # spin ~ v/r
    dt = 0.2 * math.sqrt(m.min() / KN)
    print(f"dt = 0.2*sqrt(m_min/kn) = {fmt(dt)} s (m_min = {fmt(m.min())} kg)")

    for old in glob.glob(os.path.join(HERE, "dump.*.txt")):
        os.remove(old)
    write_initial(os.path.join(HERE, "initial.txt"), x, r, v, w, L, dt)
    write_data(os.path.join(HERE, "data.frictionless"), x, r, v, w, L, D_MAX / 2)
    write_input(os.path.join(HERE, "in.frictionless"), dt)

    env = dict(os.environ, OMP_NUM_THREADS="1")
    subprocess.run(
        [lmp, "-in", "in.frictionless", "-log", "log.lammps", "-screen", "none"],
        cwd=HERE,
        env=env,
        check=True,
    )

    rows = []
    for s in DUMP_STEPS:
        step, d = read_dump(os.path.join(HERE, "dump.%04d.txt" % s))
        assert step == s, (step, s)
        rad = r[d["id"].astype(int) - 1]
        mass = RHO * np.pi * rad**2
        ke_t = 0.5 * (mass * (d["vx"] ** 2 + d["vy"] ** 2)).sum()
        ke_r = 0.5 * (0.5 * mass * rad**2 * d["omegaz"] ** 2).sum()
        pe, ncon = contact_energy(np.column_stack([d["x"], d["y"]]), rad, L)
        rows.append((s, ke_t, ke_r, pe, ke_t + ke_r + pe, ncon))
    with open(os.path.join(HERE, "kinetic_energy.txt"), "w") as fh:
        fh.write(
            "# disk energies from the dumped full-step velocities (J per unit thickness): "
            "KE_trans = sum m v^2/2, KE_rot = sum (m r^2/2) omega^2/2; "
            "PE_contact = sum over overlapping pairs kn*overlap^2/2 from dumped positions; "
            "n_contacts = overlapping pairs\n"
        )
        fh.write("# step KE_trans KE_rot PE_contact E_total n_contacts\n")
        fh.writelines(
            "%d %s %s %s %s %d\n"
            % (row[0], fmt(row[1]), fmt(row[2]), fmt(row[3]), fmt(row[4]), row[5])
            for row in rows
        )
    e0 = rows[0][4]
    for row in rows:
        print(
            "step %5d  KE_t %.6e  KE_r %.6e  PE %.6e  E %.10e  (dE/E0 %+.2e)  contacts %d"
            % (row[0], row[1], row[2], row[3], row[4], (row[4] - e0) / e0, row[5])
        )


if __name__ == "__main__":
    main()
