#!/usr/bin/env python3
"""Regenerate the LAMMPS frictional cross-code reference in this folder.

The case is the frictionless reference's (``../lammps_frictionless/``: the same
300 jammed, jittered disks in the same periodic cell, the same velocities and
spins, the same time step) with a tangential spring and Coulomb friction:
``pair_style gran/hooke/history`` with kt = kn and xmu = MU. Steps:
  1. read ``../lammps_frictionless/initial.txt`` and write it here as
     ``initial.txt`` with the friction in its header;
  2. write ``data.frictional`` and ``in.frictional``;
  3. run LAMMPS (1 process) for N_STEPS steps, dumping at the steps
     0, 1, 10, 100, 200, 500 and 1000.

Usage:  python3 make_reference.py [--lmp /usr/bin/lmp]
Needs numpy and a LAMMPS binary with the GRANULAR package (Debian ``lammps``).
"""

import argparse
import glob
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
FRICTIONLESS = os.path.join(HERE, "..", "lammps_frictionless")
sys.path.insert(0, FRICTIONLESS)
# the frictionless reference's writers and readers (data file, dumps, LAMMPS lookup)
from make_reference import D_MAX, RHO, find_lmp, fmt, write_data  # noqa: E402
from make_reference import IN_TEMPLATE as FRICTIONLESS_INPUT  # noqa: E402

KT_OVER_KN = 1.0  # Table 1: ks = kn
MU = 0.5  # friction coefficient: some contacts stick, some slide within 1000 steps
N_STEPS = 1000

# the frictionless input with the frictional pair style and this folder's files and dumps
EDITS = [
    ("frictionless dense periodic", "frictional dense periodic"),
    ("in.frictionless", "in.frictional"),
    ("data.frictionless", "data.frictional"),
    (
        "# linear normal spring only: kn, kt, gamma_n, gamma_t, xmu, dampflag\n"
        "pair_style      gran/hooke {kn} 0.0 0.0 0.0 0.0 0",
        "# linear normal and tangential springs with shear history and a Coulomb cap:\n"
        "# kn, kt, gamma_n, gamma_t, xmu, dampflag (no damping)\n"
        "pair_style      gran/hooke/history {kn} {kt} 0.0 0.0 {mu} 0",
    ),
    (
        '# dump at steps 0, 1, 10, 100, 200, ..., {nsteps}\n'
        'variable        nextdump equal "(step<1)*1 + (step>=1)*(step<10)*10 + (step>=10)*(floor(step/100)+1)*100"\n'
        "dump            d all custom 1 dump.*.txt id x y ix iy xu yu vx vy omegaz fx fy",
        "# dump at steps 0, 1, 10, 100, 200, 500 and {nsteps}\n"
        'variable        nextdump equal "(step<1)*1 + (step>=1)*(step<10)*10 + (step>=10)*(step<100)*100'
        ' + (step>=100)*(step<200)*200 + (step>=200)*(step<500)*500 + (step>=500)*{nsteps} + (step>={nsteps})*{nsteps}"\n'
        "dump            d all custom 1 dump.*.txt id xu yu vx vy omegaz fx fy tqz",
    ),
]


def input_template():
    text = FRICTIONLESS_INPUT
    for old, new in EDITS:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def read_initial(path):
    header = open(path).readline()
    number = r"([-+0-9.eE]+)"
    values = {k: float(re.search(k + " " + number, header).group(1)) for k in ("xhi", "kn", "dt")}
    table = np.loadtxt(path, comments="#")
    return values, table


def main():
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--lmp", help="LAMMPS binary (default: lmp on PATH)")
    args = ap.parse_args()
    lmp = find_lmp(args.lmp)
    if lmp is None:
        sys.exit("no LAMMPS binary found (apt-get install lammps)")

    values, table = read_initial(os.path.join(FRICTIONLESS, "initial.txt"))
    side, kn, dt = values["xhi"], values["kn"], values["dt"]
    kt = KT_OVER_KN * kn
    x, r, v, w = table[:, 1:3], table[:, 3], table[:, 4:6], table[:, 6]
    skin = 1.0e-3
    with open(os.path.join(HERE, "initial.txt"), "w") as fh:
        fh.write(
            "# cell xlo %s xhi %s ylo %s yhi %s periodic; density %s kg/m^3 "
            "(unit thickness, m = rho*pi*r^2, I = m*r^2/2); kn %s N/m; kt %s N/m; mu %s; "
            "dt %s s; n_steps %d; from ../lammps_frictionless/initial.txt\n"
            % (fmt(0.0), fmt(side), fmt(0.0), fmt(side), fmt(RHO), fmt(kn), fmt(kt), fmt(MU), fmt(dt), N_STEPS)
        )
        fh.write("# id x y radius vx vy omega\n")
        for row in table:
            fh.write(str(int(row[0])) + " " + " ".join(fmt(c) for c in row[1:]) + "\n")
    for old in glob.glob(os.path.join(HERE, "dump.*.txt")):
        os.remove(old)
    data = os.path.join(HERE, "data.frictional")
    write_data(data, x, r, v, w, side, D_MAX / 2)
    text = open(data).read().replace("frictionless reference", "frictional reference", 1)
    open(data, "w").write(text)
    with open(os.path.join(HERE, "in.frictional"), "w") as fh:
        fh.write(
            input_template().format(
                rho=fmt(RHO), kn=fmt(kn), kt=fmt(kt), mu=fmt(MU), skin=fmt(skin), dt=fmt(dt), nsteps=N_STEPS
            )
        )
    env = dict(os.environ, OMP_NUM_THREADS="1")
    subprocess.run(
        [lmp, "-in", "in.frictional", "-log", "log.lammps", "-screen", "none"],
        cwd=HERE,
        env=env,
        check=True,
    )
    print("wrote", sorted(os.path.basename(p) for p in glob.glob(os.path.join(HERE, "dump.*.txt"))))


if __name__ == "__main__":
    main()
