"""Writes mu_of_i.json from a finished sweep of periodic simple shear over the
inertial number (mu_of_i_plan.toml beside this file): per run the steady state
of its summary, per inertial number the means over the seeds, and the straight
lines mu = mu_min + b I and nu = nu_max - a I fitted by least squares to every
run at I <= FIT_MAX (the dense regime, where such a line is the expected form);
with a figure path, also the figure of docs/protocols.md.

    grainlab sweep tests/data/simple_shear/mu_of_i_plan.toml --out SWEEP --workers 2
    python tests/data/simple_shear/make_mu_of_i.py SWEEP tests/data/simple_shear/mu_of_i.json [FIGURE.png]
"""

from __future__ import annotations

import json
import statistics
import sys
from pathlib import Path

import numpy as np

#: The lines are fitted to the runs at inertial numbers up to this one (the rule was fixed before the runs).
FIT_MAX = 0.1


def main(sweep: Path, out: Path, figure: Path | None) -> None:
    runs = []
    for result in sorted(sweep.glob("runs/*/result.json")):
        row = json.loads(result.read_text())["row"]
        s = json.loads((result.parent / "simple_shear" / "summary.json").read_text())
        runs.append({
            "inertial_number_set": s["inertial_number_set"], "seed": int(row["sample.seed"]),
            "n_particles": s["n_particles"],
            "inertial_number": s["inertial_number_steady"], "friction_coefficient": s["friction_coefficient_steady"],
            "friction_coefficient_sd": s["friction_coefficient_steady_sd"],
            "solid_fraction": 1.0 - s["porosity_steady"], "coordination_number": s["coordination_number_steady"],
            "mean_stability_index": s["mean_stability_index_steady"], "anisotropy": s["anisotropy_steady"],
            "kinetic_stress_share": s["kinetic_stress_share_steady"], "rb_residual_mean_abs": s["rb_residual_mean_abs"],
            "wall_time_s": s["wall_time_s"],
        })
    by_i: dict[float, list[dict]] = {}
    for r in runs:
        by_i.setdefault(r["inertial_number_set"], []).append(r)
    means = [{"inertial_number_set": i, "runs": len(rs),
              **{k: statistics.fmean(r[k] for r in rs) for k in ("inertial_number", "friction_coefficient",
                                                                 "solid_fraction", "coordination_number",
                                                                 "mean_stability_index", "anisotropy")}}
             for i, rs in sorted(by_i.items())]
    dense = [r for r in runs if r["inertial_number_set"] <= FIT_MAX]
    i = np.array([r["inertial_number"] for r in dense])
    b, mu_min = np.polyfit(i, [r["friction_coefficient"] for r in dense], 1)
    slope, nu_max = np.polyfit(i, [r["solid_fraction"] for r in dense], 1)
    fit = {"fit_max_inertial_number": FIT_MAX, "mu_min": float(mu_min), "b": float(b), "nu_max": float(nu_max),
           "a": float(-slope)}
    out.write_text(json.dumps({"runs": runs, "means": means, "fit": fit}, indent=1) + "\n")
    if figure is not None:
        from grainlab.plot.simple_shear import mu_of_inertial_number_figure

        fig = mu_of_inertial_number_figure([r["inertial_number"] for r in runs],
                                           [r["friction_coefficient"] for r in runs],
                                           [1.0 - r["solid_fraction"] for r in runs],
                                           (fit["mu_min"], fit["b"], fit["nu_max"], fit["a"]), FIT_MAX)
        fig.savefig(figure, dpi=150)


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3]) if len(sys.argv) > 3 else None)
