"""Times the generation of the paper-scale sample (Table 1) by radius expansion.

75 x 150 mm box, the paper's grading (0.5-3 mm, uniform by number), nominal
porosity 0.12, Table 1 contact properties, generation friction 0: N from the
particle-count formula (3,518 disks). Prints each run and the median, per
thread count, side by side, and the time of the parts that are not DEM
(drawing, placement, the two porosity readings).

Run it: ``python benchmarks/sample_generation.py [--repeat 3] [--threads 1 2] [--seed 0]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from grainlab.samples import (
    PAPER_GRADING,
    expand_to_porosity,
    overlap_corrected_porosity,
    particle_count,
    random_placement,
)

BOX = (0.0, 0.0, 0.075, 0.15)
AREA = 0.075 * 0.15


def time_parts(seed: int) -> dict[str, float]:
    n = particle_count(AREA, 0.12, PAPER_GRADING)
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    d = PAPER_GRADING.sample(n, rng)
    t1 = time.perf_counter()
    xy, r = random_placement(BOX, d, rng)
    t2 = time.perf_counter()
    overlap_corrected_porosity(xy, 2 * r, BOX)  # full-size radii: thousands of overlaps
    t3 = time.perf_counter()
    return {"draw": t1 - t0, "placement": t2 - t1, "overlap-corrected porosity": t3 - t2}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    parts = time_parts(args.seed)
    print("non-DEM parts: " + ", ".join(f"{k} {1e3 * v:.1f} ms" for k, v in parts.items()))

    medians, last = {}, {}
    for threads in args.threads:
        times = []
        for _ in range(args.repeat):
            s = expand_to_porosity(BOX, 0.12, seed=args.seed, threads=threads, progress=False)
            times.append(s.wall_time_s)
            print(f"threads {threads}: {s.summary()}, {s.steps} steps")
        medians[threads] = statistics.median(times)
        last[threads] = s
        print(
            f"threads {threads}: median {medians[threads]:.2f} s of {args.repeat} "
            f"({', '.join(f'{t:.2f}' for t in times)}), "
            f"{s.n_particles * s.steps / medians[threads]:.3g} particle-steps/s"
        )
    print()
    print("| threads | N | steps | porosity nominal | overlap-corrected | wall stress (MPa) | Z | median (s) |")
    print("|---|---|---|---|---|---|---|---|")
    for threads in args.threads:
        s = last[threads]
        print(
            f"| {threads} | {s.n_particles} | {s.steps} | {s.porosity:.4f} | {s.porosity_overlap_corrected:.4f} | "
            f"{s.mean_wall_stress_pa / 1e6:.2f} | {s.coordination_number:.2f} | {medians[threads]:.2f} |"
        )


if __name__ == "__main__":
    main()
