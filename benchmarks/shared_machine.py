"""The common throughput case on a shared machine: does a second thread help or hurt
when another process keeps one core busy?

Runs, alternately, ``--repeat`` times each:

* ``1 thread, quiet``: the reference, nothing else running;
* ``2 threads, one core busy``: what a run with ``run.threads = auto`` does on a
  2-core machine while another program (here a spinning Python process) holds a core;
* ``1 thread, one core busy``: the same with one thread.

The case is ``throughput.py``'s (4,000 dense disks, pure shear of a periodic cell),
``--steps`` timed steps. Prints every run, the medians and the busy 2-thread speed as
a fraction of the quiet 1-thread speed (a team that waited on its descheduled worker
would lose most of it). The last line printed is one JSON object.

    python benchmarks/shared_machine.py                 # 5 repeats, 10,000 steps
    python benchmarks/shared_machine.py --repeat 9
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from throughput import grainlab_run  # noqa: E402

CASES = ("1 thread, quiet", "2 threads, one core busy", "1 thread, one core busy")


@contextmanager
def busy_core() -> Iterator[None]:
    """A process spinning on the CPU for as long as the block runs."""
    spinner = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.5)  # let it start and be scheduled
        yield
    finally:
        spinner.kill()
        spinner.wait()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--steps", type=int, default=10_000)
    args = parser.parse_args(argv)
    if args.repeat < 1 or args.steps < 1:
        parser.error("--repeat and --steps must be positive")

    speeds: dict[str, list[float]] = {case: [] for case in CASES}
    print(f"common case, {args.steps} timed steps, {args.repeat} repetitions")
    for rep in range(args.repeat):
        for case in CASES:
            threads = 2 if case.startswith("2") else 1
            if case.endswith("quiet"):
                r = grainlab_run(threads, args.steps)
            else:
                with busy_core():
                    r = grainlab_run(threads, args.steps)
            speeds[case].append(r["particle_steps_per_s"])
            print(f"run {rep + 1}: {case}: {r['particle_steps_per_s']:.3e} particle-steps/s", flush=True)
    medians = {case: statistics.median(v) for case, v in speeds.items()}
    fraction = medians["2 threads, one core busy"] / medians["1 thread, quiet"]
    print()
    for case in CASES:
        print(f"  {case}: {medians[case]:.3e}")
    print(f"2 threads with one core busy / 1 thread quiet = {fraction:.2f}x")
    print(json.dumps({"medians": medians, "busy_2_over_quiet_1": fraction}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
