"""Wall-clock time of the default biaxial run (the paper's Table 1 test,
generation to 10 % axial strain), per phase, median of several runs.

Usage: ``python benchmarks/biaxial_default.py [--repeat 3] [--quick]``.
The goal is the whole default run in under 60 s on a 2-core machine.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path

from grainlab.protocols.biaxial import run_biaxial
from grainlab.protocols.config import resolve


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="the --quick sample instead of the default")
    args = parser.parse_args(argv)
    config = resolve(quick=args.quick)
    totals, phases = [], {}
    for k in range(args.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            result = run_biaxial(config, Path(tmp) / "run", progress=False)
        s = result.summary
        totals.append(s["wall_time_s"])
        for name, seconds in s["wall_time_by_phase_s"].items():
            phases.setdefault(name, []).append(seconds)
        print(f"run {k + 1}: {s['wall_time_s']:.1f} s, {s['n_particles']} grains, peak ratio {s['peak_stress_ratio']:.2f}")
    medians = {name: statistics.median(v) for name, v in phases.items()}
    print("median per phase (s): " + ", ".join(f"{k} {v:.1f}" for k, v in medians.items()))
    print(json.dumps({"wall_time_s": statistics.median(totals), "phases_s": medians}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
