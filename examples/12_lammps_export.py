"""Shear the same periodic packing in grainlab and in LAMMPS, side by side.

Builds a dense packing in a periodic cell (``grainlab.samples.periodic``),
writes it with a constant-area simple shear as a LAMMPS data file and input
deck (``grainlab.io.lammps_input``, the library side of ``grainlab export
--lammps``), runs LAMMPS on 2 MPI processes from the deck when it is installed,
reads its dumps back as snapshots and shears the same packing in grainlab.
Both are measured the same way, from their contacts: the stress ratio
``-sigma_xy / sigma_yy`` (Love-Weber over the cell) and Z = 2 Nc / N, as
medians over windows of shear strain (docs/lammps.md, "Side by side").

Run it::

    python examples/12_lammps_export.py                  # 500 disks to a shear strain of 0.4
    python examples/12_lammps_export.py --disks 2000 --out DIR
    python examples/12_lammps_export.py --disks 2000 --local-damping 0.8 --no-lammps
    LAMMPS_BIN=.../lmp python examples/12_lammps_export.py --disks 2000 --local-damping 0.8 --cundall

Without LAMMPS (``apt-get install lammps openmpi-bin``) it writes the deck and
says how to run it.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from grainlab import ContactModel, Simulation
from grainlab.analysis.stress import contact_stress
from grainlab.io.lammps_input import (
    LammpsShear,
    find_lammps,
    read_lammps_run,
    run_lammps_deck,
    write_lammps_shear,
)
from grainlab.samples.periodic import periodic_packing
from grainlab.snapshot import Snapshot

#: The contact law of the shear: Table 1's stiffness, friction 0.5, a light normal
#: dashpot (5 % of critical) in both codes, no local damping (LAMMPS 2021 has none).
MODEL = ContactModel(friction=0.5, normal_damping_ratio=0.05)


def stress_ratio_and_z(snapshots: list[Snapshot]) -> np.ndarray:
    """(K, 3) rows of shear strain, stress ratio -sigma_xy / sigma_yy and Z."""
    rows = []
    for snap in snapshots:
        assert snap.box is not None  # both codes' snapshots carry the cell
        stress = contact_stress(snap, area=float(np.prod(np.diff(snap.box, axis=1))))
        rows.append((snap.scalars["shear_strain"], -stress[0, 1] / stress[1, 1], 2 * snap.n_contacts / snap.n_particles))
    return np.array(rows)


def window_medians(rows: np.ndarray, windows: list[tuple[float, float]]) -> np.ndarray:
    """Median stress ratio and Z over each window of shear strain."""
    picks = [(rows[:, 0] >= lo - 1e-9) & (rows[:, 0] <= hi + 1e-9) for lo, hi in windows]
    return np.array([np.median(rows[pick, 1:], axis=0) for pick in picks])


def main(
    out: Path,
    disks: int = 500,
    strain: float = 0.4,
    shear_rate: float = 0.06,
    *,
    local_damping: float = 0.0,
    cundall: bool = False,
    lammps: bool = True,
) -> dict[str, np.ndarray]:
    """Shear ``disks`` disks to ``strain`` in both codes; grainlab with ``local_damping``,
    LAMMPS without it unless ``cundall`` (``fix damping/cundall``, LAMMPS 2023 on);
    no LAMMPS run when ``lammps`` is false. Returns the window medians of each code."""
    packed = periodic_packing(disks, seed=3)
    sim = Simulation(packed.positions, packed.radii, packed.densities, contact_model=MODEL,
                     time_step=packed.time_step, threads=1, local_damping=local_damping)  # fmt: skip
    cell = packed.cell
    assert cell is not None
    sim.set_periodic_cell(cell.origin, (cell.origin[0] + cell.a[0], cell.origin[1] + cell.b[1]))
    shear = LammpsShear(shear_rate, strain, local_damping="cundall" if cundall else "omit")
    done = write_lammps_shear(sim, out, shear)
    print(f"{disks} disks, {done.steps} steps: {done.input_file} and {done.data_file.name}")
    for item in done.dropped:
        print(f"  not carried: {item}")

    sim.set_velocity_gradient([[0.0, shear_rate], [0.0, 0.0]])
    ours = [sim.snapshot(scalars={"shear_strain": 0.0})]
    for _ in range(done.steps // done.dump_every):
        sim.run(done.dump_every)
        ours.append(sim.snapshot(scalars={"shear_strain": shear_rate * sim.time}))
    windows = [(0.25 * strain, 0.625 * strain), (0.625 * strain, strain)]
    result = {"grainlab": window_medians(stress_ratio_and_z(ours), windows)}
    if not lammps:
        pass
    elif find_lammps() is None:
        print(f"LAMMPS not found: run 'mpirun -np 2 lmp -in in.grainlab' in {out}")
    else:
        run_lammps_deck(out, processes=2)
        result["lammps"] = window_medians(stress_ratio_and_z(read_lammps_run(out)), windows)
    print("shear strain window   code      stress ratio   Z")
    for k, (lo, hi) in enumerate(windows):
        for code, medians in result.items():
            print(f"{lo:.3f} - {hi:.3f}         {code:9s} {medians[k, 0]:.3f}          {medians[k, 1]:.3f}")
    return result


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--disks", type=int, default=500)
    parser.add_argument("--strain", type=float, default=0.4)
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--local-damping", type=float, default=0.0, help="grainlab's local damping alpha")
    parser.add_argument("--cundall", action="store_true", help="LAMMPS with fix damping/cundall (2023 on)")
    parser.add_argument("--no-lammps", action="store_true", help="grainlab alone")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="grainlab_lammps_"))
    main(out, args.disks, args.strain, local_damping=args.local_damping, cundall=args.cundall, lammps=not args.no_lammps)
