"""The cost of cement bonds: the common 4,000-disk packing with every touching pair
cemented beside the same packing without cement, alternated, and the ratio of
their step times.

The case is ``throughput.py``'s (dense periodic packing, kn = ks = 8.45e7 N/m,
friction 0.9, pure shear of the cell at 3.676e-3 1/s, dt = 1.36e-4 s). After the
warm-up steps the cemented sample gets a parallel bond on every contact
(``lambda_b = 1``, ``kn_bar A = ks_bar A = kn / 2`` for the mean radius, strengths
too high to break, so the same bonds are evaluated at every step; the contact
law still runs on every pair beside them). Both samples then run ``--steps``
timed steps. Runs alternate (plain, cemented, plain, ...) so that the machine's
noise falls on both alike; medians of ``--repeat`` pairs; the load average
(``os.getloadavg``) is printed before and after. The last line printed is one
JSON object.

Usage: ``python benchmarks/bond_cost.py [--repeat 3] [--steps 3000] [--threads 1]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import grainlab

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from throughput import STRAIN_RATE, TIME_STEP, tiled_packing  # noqa: E402

KN = 8.45e7


def one_run(cemented: bool, steps: int, threads: int, warmup: int = 100) -> dict[str, float]:
    """Seconds of ``steps`` timed steps of the sheared packing, with or without cement."""
    positions, radii, box = tiled_packing(1)
    sim = grainlab.Simulation(
        positions,
        radii,
        2.0e8,
        contact_model=grainlab.ContactModel(KN, KN, 0.9),
        time_step=TIME_STEP,
        threads=threads,
    )
    sim.set_periodic_cell(box[:, 0], box[:, 1] - box[:, 0])
    sim.run(warmup)
    if cemented:
        c = sim.contacts()
        kn_bar = 0.5 * KN / (2.0 * float(np.mean(radii)))
        sim.add_cement_bonds(
            c.i, c.j, normal_stiffness=kn_bar, shear_stiffness=kn_bar, tensile_strength=1e30, cohesion=1e30
        )
    sim.set_velocity_gradient([[-STRAIN_RATE, 0.0], [0.0, STRAIN_RATE]])
    start = time.perf_counter()
    sim.run(steps)
    elapsed = time.perf_counter() - start
    return {"seconds": elapsed, "bonds": float(sim.n_cement_bonds), "contacts": float(len(sim.contacts().i))}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args(argv)
    load_before = os.getloadavg()
    print(f"load average before: {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}", flush=True)
    times: dict[str, list[float]] = {"plain": [], "cemented": []}
    bonds = 0.0
    for k in range(args.repeat):
        for name in ("plain", "cemented"):
            r = one_run(name == "cemented", args.steps, args.threads)
            times[name].append(r["seconds"])
            bonds = max(bonds, r["bonds"])
            print(f"{name} run {k + 1}: {r['seconds']:.3f} s for {args.steps} steps, "
                  f"{r['bonds']:.0f} cement bonds, {r['contacts']:.0f} contacts", flush=True)
    median = {name: statistics.median(t) for name, t in times.items()}
    ratio = median["cemented"] / median["plain"]
    load_after = os.getloadavg()
    print(f"load average after: {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f}")
    print(f"median step time: plain {1e6 * median['plain'] / args.steps:.1f} us, cemented "
          f"{1e6 * median['cemented'] / args.steps:.1f} us ({bonds:.0f} bonds): ratio {ratio:.3f}")
    print(json.dumps({"plain_s": median["plain"], "cemented_s": median["cemented"], "ratio": ratio,
                      "bonds": bonds, "steps": args.steps, "threads": args.threads, "repeat": args.repeat,
                      "load_before": load_before[0], "load_after": load_after[0]}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
