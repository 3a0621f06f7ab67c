"""Analyse a LAMMPS dump: coordination number, fabric anisotropy, stability index, polar plots.

Reads an atoms dump (``dump custom ... id type x y radius ...``) and the matching
contacts dump (``dump local`` of ``compute property/local patom1 patom2`` and
``compute pair/local dist force fx fy p1 p2 p4``), then runs grainlab's
fabric measures on it (docs/fabric.md) and saves the rose diagrams of the
contact normals and normal forces (the paper's Figs. 6-7).

By default it reads the LAMMPS-written pile in ``tests/data/lammps_dump``
(250 frictional disks settled under gravity in a box of 65 frozen wall disks
of type 2; its README says how it was made). The wall disks bound the sample
but are not part of it (``boundary_types=(2,)``): they count as boundary
contacts, like grainlab's walls and membrane.

Run it::

    python examples/06_lammps_dump.py                       # the test fixture
    python examples/06_lammps_dump.py ATOMS CONTACTS --out DIR

``grainlab analyze ATOMS --contacts CONTACTS --boundary-types 2 --contact-columns ...``
does the same and more from the command line (docs/cli.md).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from grainlab.analysis import ContactAnisotropy, CoordinationNumber, StabilityIndex
from grainlab.io import read_lammps_dump
from grainlab.plot import save_figure

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "lammps_dump"

#: Which column of the contacts dump plays which role (the 2021 LAMMPS names
#: its columns after the computes: c_cpl[k] is the k-th value of pair/local).
#: The pair's atom ids (c_cid[1], c_cid[2]) are recognised without being named.
COLUMNS = {
    "dist": "c_cpl[1]",  # centre distance: pairs that do not touch are dropped
    "normal_force": "c_cpl[2]",  # pair/local force: normal force, repulsion positive
    "shear_x": "c_cpl[5]",  # p1 p2: tangential force on the first atom
    "shear_y": "c_cpl[6]",
}

#: Atom types that bound the sample (the frozen wall disks).
BOUNDARY_TYPES = (2,)


def main(
    out: Path, atoms: Path = DATA / "atoms.dump", contacts: Path = DATA / "contacts.dump"
) -> dict[str, float]:
    snap = read_lammps_dump(
        atoms, contacts=contacts, columns=COLUMNS, boundary_types=BOUNDARY_TYPES
    )
    print(
        f"{atoms.name}, timestep {snap.metadata['timestep']}: {int(snap.is_sample.sum())} grains, "
        f"{snap.n_particles - int(snap.is_sample.sum())} boundary disks, {snap.n_contacts} contacts"
    )

    z = CoordinationNumber().compute(snap)  # grain-grain contacts only (Z = 2 Nc / Np)
    z_all = CoordinationNumber(include_boundary=True).compute(snap)  # walls counted too
    normals = ContactAnisotropy(bins=18).compute(snap)
    forces = ContactAnisotropy(bins=18, weight="normal_force").compute(snap)
    lam = StabilityIndex().compute(snap)  # all active contacts, walls included (paper Sec. 5)

    print(f"coordination number Z = {z.coordination_number:.4f} (grain-grain contacts)")
    print(
        f"contacts per grain, walls included = {z_all.coordination_number:.4f} "
        "(what LAMMPS's compute contact/atom averages)"
    )
    print(
        f"mechanical coordination number Z_m = {z.mechanical_coordination_number:.4f} "
        f"({int(z.rattlers.sum())} rattlers with < {z.min_contacts} contacts removed)"
    )
    print(
        f"contact-normal anisotropy a = {normals.anisotropy:.4f} (exact, unbinned), "
        f"theta_a = {np.degrees(normals.direction):.1f} deg; "
        f"Eq. 7 on 18 bins a = {normals.anisotropy_binned:.4f}"
    )
    print(
        f"normal-force anisotropy a_n = {forces.anisotropy:.4f} (exact), "
        f"theta_n = {np.degrees(forces.direction):.1f} deg; Eq. 7 a_n = {forces.anisotropy_binned:.4f}"
    )
    print(
        f"mean stability index lambda = {lam.mean:.4f} (grains with >= 2 contacts), "
        f"{lam.mean_all:.4f} (all grains, 0/1 contact counted as 1)"
    )

    out.mkdir(parents=True, exist_ok=True)
    figures = save_figure(normals.plot(), out / "contact_normals", formats=("png",))
    figures += save_figure(forces.plot(), out / "normal_forces", formats=("png",))
    print("polar plots: " + ", ".join(str(p) for p in figures))
    return {
        "Z": z.coordination_number,
        "Z_with_walls": z_all.coordination_number,
        "mechanical_Z": z.mechanical_coordination_number,
        "n_rattlers": int(z.rattlers.sum()),
        "a": normals.anisotropy,
        "theta_a_deg": float(np.degrees(normals.direction)),
        "a_binned": normals.anisotropy_binned,
        "theta_a_binned_deg": float(np.degrees(normals.direction_binned)),
        "a_fourier": normals.anisotropy_fourier,
        "a_n": forces.anisotropy,
        "theta_n_deg": float(np.degrees(forces.direction)),
        "a_n_binned": forces.anisotropy_binned,
        "theta_n_binned_deg": float(np.degrees(forces.direction_binned)),
        "mean_lambda": lam.mean,
        "mean_lambda_all": lam.mean_all,
        "figures": [str(p) for p in figures],
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("atoms", nargs="?", type=Path, default=DATA / "atoms.dump")
    parser.add_argument("contacts", nargs="?", type=Path, default=DATA / "contacts.dump")
    parser.add_argument("--out", type=Path, default=None, help="folder for the figures")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="grainlab_lammps_"))
    main(out, args.atoms, args.contacts)
