"""Writes rolling_study.json from a finished sweep of the biaxial test over the
rolling friction (plan.toml beside this file): per run the peak and residual
stress ratios and friction angles, per mu_r their means and standard deviations.

    grainlab sweep tests/data/rolling/plan.toml --out SWEEP --workers 2
    python tests/data/rolling/make_rolling_study.py SWEEP tests/data/rolling/rolling_study.json

The residual stress ratio is the mean of sigma1/sigma3 over the records at axial
strains from 8 to 10 %; a friction angle is asin((R - 1) / (R + 1)) of a ratio R.
"""

from __future__ import annotations

import json
import math
import statistics
import sys
from pathlib import Path

import numpy as np

from grainlab.io.hdf5 import read_results

#: The residual is the mean stress ratio over these axial strains.
RESIDUAL_WINDOW = (0.08, 0.10)


def friction_angle_deg(ratio: float) -> float:
    """asin((R - 1) / (R + 1)) in degrees."""
    return math.degrees(math.asin((ratio - 1.0) / (ratio + 1.0)))


def main(sweep: Path, out: Path) -> None:
    runs = []
    for result in sorted(sweep.glob("runs/*/result.json")):
        row = json.loads(result.read_text())["row"]
        ts = read_results(result.parent / "biaxial" / "run.h5").timeseries
        eps, q = np.asarray(ts["axial_strain"]), np.asarray(ts["stress_ratio"])
        window = (eps >= RESIDUAL_WINDOW[0] - 1e-9) & (eps <= RESIDUAL_WINDOW[1] + 1e-9)
        residual = float(q[window].mean())
        runs.append({"rolling_friction": row["material.rolling_friction"], "seed": row["sample.seed"],
                     "peak_stress_ratio": row["peak_stress_ratio"], "axial_strain_at_peak": row["axial_strain_at_peak"],
                     "residual_stress_ratio": residual,
                     "peak_friction_angle_deg": friction_angle_deg(row["peak_stress_ratio"]),
                     "residual_friction_angle_deg": friction_angle_deg(residual),
                     "final_volumetric_strain": row["final_volumetric_strain"], "wall_time_s": row["wall_time_s"]})
    by_mu: dict[float, list[dict[str, float]]] = {}
    for run in runs:
        by_mu.setdefault(run["rolling_friction"], []).append(run)
    table = []
    for mu, group in sorted(by_mu.items()):
        entry: dict[str, float | int] = {"rolling_friction": mu, "seeds": len(group)}
        for key in ("peak_friction_angle_deg", "residual_friction_angle_deg", "axial_strain_at_peak",
                    "final_volumetric_strain"):
            values = [g[key] for g in group]
            entry[key] = statistics.fmean(values)
            entry[key + "_sd"] = statistics.stdev(values) if len(values) > 1 else math.nan
        table.append(entry)
    out.write_text(json.dumps({"residual_window": RESIDUAL_WINDOW, "runs": runs, "by_rolling_friction": table},
                              indent=1) + "\n")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
