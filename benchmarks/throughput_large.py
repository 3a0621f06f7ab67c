"""The common throughput case at 100,000 and 1,024,000 disks, side by side.

The 4,000-disk packing of ``throughput.py`` (``benchmarks/data/dense-4000-disks.xyr``)
tiled ``5 x 5`` (100,000 disks) and ``16 x 16`` (1,024,000 disks) into one periodic
square cell, the same contact law, density, time step and constant-area pure shear.
Each repetition runs both sizes, alternately, on ``--threads`` threads: 100 untimed
warm-up steps, then ``--steps`` timed steps (the same strain, so the same contacts per
disk, at both sizes). Prints the particle-steps per second of every
run, the medians, the large size's speed as a fraction of the small one's (a cache
or memory-bandwidth wall shows as a fraction well below 1), and the resident memory
the first run of the large size added per disk (the engine's state and the packing's
arrays). The last line printed is one JSON object.

    python benchmarks/throughput_large.py                  # 2 threads, 3 repeats, 400 steps
    python benchmarks/throughput_large.py --threads 1 --repeat 5
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from throughput import grainlab_run  # noqa: E402

SIZES = {"100,000": 5, "1,024,000": 16}


def _rss_kib() -> int:
    """Peak resident memory of this process so far, KiB (Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


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
    # the large size first: the growth of the peak resident memory is then its run's
    order = sorted(SIZES, key=lambda name: -SIZES[name])
    for rep in range(args.repeat):
        for name in order:
            before = _rss_kib()
            r = grainlab_run(args.threads, args.steps, tiles=SIZES[name])
            speeds[name].append(r["particle_steps_per_s"])
            n_disks = int(name.replace(",", ""))
            memory.setdefault(name, max(_rss_kib() - before, 0) * 1024.0 / n_disks)
            print(
                f"run {rep + 1}: {name} disks, {args.steps} steps: {r['particle_steps_per_s']:.3e} particle-steps/s "
                f"(Z {r['z_end']:.2f})",
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
