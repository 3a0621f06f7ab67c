"""The common throughput case, grainlab and LAMMPS side by side.

The case (``benchmarks/data/dense-4000-disks.xyr``, from the project's shared
bench notes): 4,000 dense disks in a square periodic cell, kn = ks = 8.45e7 N/m,
friction 0.9, shear history, no damping, no gravity, density 2e8 kg/m^3,
dt = 1.36e-4 s, zero initial velocities; 100 untimed warm-up steps, then 20,000
timed steps of constant-area pure shear of the cell (true strain rate 3.676e-3
1/s: x shrinks, y grows). particle-steps/s = 4000 * 20000 / wall time.

Runs alternate between engines and thread counts, so that the machine's noise
falls on all of them alike; medians of ``--repeat`` runs are reported. LAMMPS
runs when it is installed (``apt-get install lammps openmpi-bin``), with MPI
processes in place of threads. The last line printed is one JSON object with
the medians under ``grainlab_1``, ``grainlab_2``, ``lammps_1``, ``lammps_2``
(null when LAMMPS is missing).

With ``--rolling-friction MU`` each grainlab run is followed by the same run
with rolling resistance (``rolling_friction = MU``, its stiffness from the
rule, no rolling dashpot), alternated with it; the medians are added under
``grainlab_rolling_1`` and ``grainlab_rolling_2`` with their ratios to the runs
without (docs/contact-law.md, "Speed").

Usage: ``python benchmarks/throughput.py [--repeat 5] [--steps 20000]
[--no-lammps] [--rolling-friction 0.1]``
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import grainlab

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import lammps_runner  # noqa: E402

PACKING = HERE / "data" / "dense-4000-disks.xyr"
STRAIN_RATE = 3.676e-3
TIME_STEP = 1.36e-4


def tiled_packing(tiles: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions (N, 2), radii (N,) and the box ``[[xlo, xhi], [ylo, yhi]]`` of the
    common packing tiled ``tiles`` x ``tiles`` times (1: the packing itself)."""
    side, disks = lammps_runner.read_xyr(PACKING)
    disks = np.asarray(disks, dtype=float)
    ox, oy = np.meshgrid(np.arange(tiles), np.arange(tiles), indexing="ij")
    offsets = np.c_[ox.ravel(), oy.ravel()] * side
    positions = (disks[None, :, :2] + offsets[:, None, :]).reshape(-1, 2)
    radii = np.tile(disks[:, 2], tiles * tiles)
    box = np.array([[0.0, tiles * side], [0.0, tiles * side]])
    return positions, radii, box


def grainlab_run(
    threads: int, steps: int, warmup: int = 100, tiles: int = 1, rolling_friction: float = 0.0
) -> dict[str, float]:
    """``steps`` timed steps of the common case (tiled ``tiles`` x ``tiles``) after ``warmup`` untimed
    ones, with rolling resistance ``rolling_friction`` (0: none, the common case)."""
    positions, radii, box = tiled_packing(tiles)
    sim = grainlab.Simulation(
        positions,
        radii,
        2.0e8,
        contact_model=grainlab.ContactModel(8.45e7, 8.45e7, 0.9, rolling_friction=rolling_friction),
        time_step=TIME_STEP,
        threads=threads,
    )
    sim.set_periodic_cell(box[:, 0], box[:, 1] - box[:, 0])
    sim.run(warmup)
    z_start = sim.coordination_number
    sim.set_velocity_gradient([[-STRAIN_RATE, 0.0], [0.0, STRAIN_RATE]])
    start = time.perf_counter()
    sim.run(steps)
    elapsed = time.perf_counter() - start
    return {
        "particle_steps_per_s": len(radii) * steps / elapsed,
        "seconds": elapsed,
        "z_start": z_start,
        "z_end": sim.coordination_number,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--no-lammps", action="store_true", help="skip LAMMPS even if installed")
    parser.add_argument(
        "--rolling-friction", type=float, default=0.0, metavar="MU",
        help="also time each grainlab run with rolling resistance mu_r = MU, alternated (0: not)",
    )
    args = parser.parse_args(argv)
    if args.repeat < 1 or args.steps < 1:
        parser.error("--repeat and --steps must be >= 1")
    if not args.rolling_friction >= 0.0:
        parser.error(f"--rolling-friction: must be >= 0, got {args.rolling_friction}")
    rolling = args.rolling_friction > 0.0

    have_lammps = not args.no_lammps and lammps_runner.find_lammps() is not None
    names = ["grainlab_1", "grainlab_2", "lammps_1", "lammps_2"]
    if rolling:
        names += ["grainlab_rolling_1", "grainlab_rolling_2"]
    samples: dict[str, list[float]] = {k: [] for k in names}
    print(f"common case: {PACKING.name}, {args.steps} timed steps, {args.repeat} repetitions")
    if not have_lammps:
        print("LAMMPS not found: grainlab only (apt-get install lammps openmpi-bin for the comparison)")
    for rep in range(args.repeat):
        for n in (1, 2):
            g = grainlab_run(n, args.steps)
            samples[f"grainlab_{n}"].append(g["particle_steps_per_s"])
            line = f"run {rep + 1}: grainlab {n} thread(s) {g['particle_steps_per_s']:.3e} (Z {g['z_start']:.2f} -> {g['z_end']:.2f})"
            if rolling:
                r = grainlab_run(n, args.steps, rolling_friction=args.rolling_friction)
                samples[f"grainlab_rolling_{n}"].append(r["particle_steps_per_s"])
                line += f" | rolling {r['particle_steps_per_s']:.3e}"
            if have_lammps:
                lam = lammps_runner.run_lammps_throughput(PACKING, n, steps=args.steps)
                samples[f"lammps_{n}"].append(lam["particle_steps_per_s"])
                line += f" | LAMMPS {n} process(es) {lam['particle_steps_per_s']:.3e}"
            print(line, flush=True)

    medians = {k: (statistics.median(v) if v else None) for k, v in samples.items()}
    print()
    print("medians (particle-steps per second):")
    for n in (1, 2):
        g, lam = medians[f"grainlab_{n}"], medians[f"lammps_{n}"]
        ratio = f"  grainlab/LAMMPS = {g / lam:.2f}x" if lam else ""
        print(f"  {n} thread(s): grainlab {g:.3e}" + (f"  LAMMPS {lam:.3e}" if lam else "") + ratio)
    print(f"  grainlab speed-up 1 -> 2 threads: {medians['grainlab_2'] / medians['grainlab_1']:.2f}x")
    if rolling:
        for n in (1, 2):
            on, off = medians[f"grainlab_rolling_{n}"], medians[f"grainlab_{n}"]
            assert on is not None and off is not None
            medians[f"rolling_ratio_{n}"] = on / off
            print(f"  rolling_friction {args.rolling_friction}, {n} thread(s): {on:.3e}, {on / off:.3f}x without")
    print(json.dumps(medians))
    return 0


if __name__ == "__main__":
    sys.exit(main())
