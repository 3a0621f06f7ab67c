"""The common throughput case at 100,000 and 1,024,000 disks, side by side.

The 4,000-disk packing of ``throughput.py`` (``benchmarks/data/dense-4000-disks.xyr``)
tiled ``5 x 5`` (100,000 disks) and ``16 x 16`` (1,024,000 disks) into one periodic
square cell, the same contact law, density, time step and constant-area pure shear.
Each repetition runs both sizes, alternately, on ``--threads`` threads: 100 untimed
warm-up steps, then ``--steps`` timed steps (the same strain, so the same contacts per
disk, at both sizes). Prints the particle-steps per second of every
run, the medians, the large size's speed as a fraction of the small one's (a cache
or memory-bandwidth wall shows as a fraction well below 1), and the resident memory
the engine added per disk. The last line printed is one JSON object.

    python benchmarks/throughput_large.py                  # 2 threads, 3 repeats, 400 steps
    python benchmarks/throughput_large.py --threads 1 --repeat 5
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import sys
import time
from pathlib import Path

import grainlab

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from analysis_large import tiled_packing  # noqa: E402
from throughput import STRAIN_RATE, TIME_STEP  # noqa: E402

SIZES = {"100,000": 5, "1,024,000": 16}


def _rss_kib() -> int:
    """Peak resident memory of this process so far, KiB (Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def tiled_run(tiles: int, threads: int, steps: int, warmup: int = 100) -> dict[str, float]:
    """Particle-steps per second of ``steps`` timed steps of the tiled case."""
    positions, radii, box = tiled_packing(tiles)
    before = _rss_kib()
    sim = grainlab.Simulation(
        positions,
        radii,
        2.0e8,
        contact_model=grainlab.ContactModel(8.45e7, 8.45e7, 0.9),
        time_step=TIME_STEP,
        threads=threads,
    )
    sim.set_periodic_cell((box[0, 0], box[1, 0]), (box[0, 1] - box[0, 0], box[1, 1] - box[1, 0]))
    sim.run(warmup)
    sim.set_velocity_gradient([[-STRAIN_RATE, 0.0], [0.0, STRAIN_RATE]])
    start = time.perf_counter()
    sim.run(steps)
    elapsed = time.perf_counter() - start
    grown = max(_rss_kib() - before, 0) * 1024.0
    return {
        "particle_steps_per_s": len(radii) * steps / elapsed,
        "bytes_per_disk": grown / len(radii),
        "coordination_number": sim.coordination_number,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--steps", type=int, default=400, help="timed steps at each size")
    args = parser.parse_args(argv)
    if args.threads < 1 or args.repeat < 1 or args.steps < 1:
        parser.error("--threads, --repeat and --steps must be positive")

    speeds: dict[str, list[float]] = {name: [] for name in SIZES}
    memory: dict[str, float] = {}
    print(f"tiled common case, {args.threads} thread(s), {args.repeat} repetitions")
    # the large size first: its peak resident memory is then the engine's own growth
    order = sorted(SIZES, key=lambda name: -SIZES[name])
    for rep in range(args.repeat):
        for name in order:
            r = tiled_run(SIZES[name], args.threads, args.steps)
            speeds[name].append(r["particle_steps_per_s"])
            memory.setdefault(name, r["bytes_per_disk"])
            print(
                f"run {rep + 1}: {name} disks, {args.steps} steps: {r['particle_steps_per_s']:.3e} particle-steps/s "
                f"(Z {r['coordination_number']:.2f})",
                flush=True,
            )
    medians = {name: statistics.median(v) for name, v in speeds.items()}
    ratio = medians["1,024,000"] / medians["100,000"]
    print()
    print(f"medians: 100,000 disks {medians['100,000']:.3e}, 1,024,000 disks {medians['1,024,000']:.3e} particle-steps/s")
    print(f"1,024,000 / 100,000 = {ratio:.2f}x; memory {memory['1,024,000'] / 1024:.2f} KiB per disk at 1,024,000")
    print(json.dumps({"threads": args.threads, "medians": medians, "ratio": ratio,
                      "bytes_per_disk": memory["1,024,000"]}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
