"""A small parameter sweep: three packings in a 20 x 40 mm box, in two local processes.

Run it again and the finished runs are skipped. The same plan as a file runs with
``grainlab sweep PLAN.toml --out DIR`` (docs/study.md); add ``--scheduler ADDRESS``
to run it on a Dask cluster.
"""

import sys
import tempfile
from pathlib import Path

from grainlab.study import parse_plan, read_table, run_sweep

PLAN = """
base = "packing"
mode = "zip"
seed = 0
[fixed]
width = 0.02      # m
height = 0.04
[vary]
kind = ["irregular", "irregular", "hexagonal"]
porosity = [0.14, 0.18, 0.12]
"""


def main(out: Path) -> None:
    plan = parse_plan(PLAN)
    result = run_sweep(plan, out, workers=2, progress=False)
    for row in read_table(out / "sweep.csv"):
        print(f"{row['name']}: {row['kind']:9s} n={float(row['porosity']):.3f} Z={float(row['coordination_number']):.2f} "
              f"lambda={float(row['mean_stability_index']):.3f} a={float(row['anisotropy']):.3f} {row['status']}")
    print(f"{len(result.executed)} run, {len(result.skipped)} skipped, {result.wall_time_s:.1f} s")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="grainlab_sweep_")))
