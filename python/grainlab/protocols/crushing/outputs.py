"""A finished crushing run's outputs: the summary (each agglomerate's peak force and
characteristic strength sigma_f = F_max / (d t), its mode; the Weibull fit of the
strengths of the agglomerates that failed, :mod:`grainlab.analysis.weibull`),
``timeseries.csv``, ``summary.json`` and the figures, all from ``run.h5``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

import grainlab
from grainlab.analysis.weibull import weibull_fit, weibull_points
from grainlab.columns import AGGLOMERATE, AXIAL_STRAIN, DIAMETER_M, PLATEN_FORCE_N
from grainlab.protocols.crushing.config import CrushingConfig
from grainlab.protocols.crushing.state import CrushingRun
from grainlab.protocols.runner import RunResult
from grainlab.protocols.specimen import write_run_outputs

__all__ = ["CrushingResult", "agglomerate_peaks", "summarise", "write_outputs"]

#: The fewest failed agglomerates a Weibull fit is made of.
MIN_FIT = 3
MODES = ("split", "fragmented", "unfailed")


@dataclass(frozen=True)
class CrushingResult(RunResult):
    """What ``grainlab run crushing`` reports: the summary and where the files are."""

    def one_line(self) -> str:
        s = self.summary
        w = s["weibull"]
        fit = "no Weibull fit (fewer than 3 failed)" if w is None else (
            f"Weibull m {w['modulus']:.2f} (95 % {w['modulus_interval'][0]:.2f}-{w['modulus_interval'][1]:.2f}), "
            f"sigma_0 {w['scale'] / 1e3:.0f} kPa, R^2 {w['r_squared']:.3f}")
        modes = ", ".join(f"{s['modes'][m]} {m}" for m in MODES)
        return (f"grainlab crushing: {s['n_agglomerates']} agglomerates of {s['mean_disks']:.0f} disks on average; "
                f"{fit}; {modes}; {s['wall_time_s']:.1f} s -> {self.out_dir}")


def agglomerate_peaks(timeseries: dict[str, NDArray[np.float64]], n: int) -> list[dict[str, float]]:
    """Each agglomerate's peak from its records: the largest platen force F_max (N per m),
    sigma_f = F_max / (d t) with t = 1 m, the strain at the peak."""
    label = np.asarray(timeseries[AGGLOMERATE])
    force, strain = timeseries[PLATEN_FORCE_N], timeseries[AXIAL_STRAIN]
    peaks = []
    for k in range(n):
        rows = np.flatnonzero(label == k)
        peak = rows[int(np.argmax(force[rows]))]
        d = float(timeseries[DIAMETER_M][peak])
        peaks.append({"peak_force_n": float(force[peak]), "strength_pa": float(force[peak]) / (d * 1.0),
                      "axial_strain_at_peak": float(strain[peak]), "records": len(rows)})
    return peaks


def summarise(run: CrushingRun, config: CrushingConfig, timeseries: dict[str, NDArray[np.float64]],
              total_s: float) -> dict[str, Any]:
    """The run's summary, as ``run.h5`` and ``summary.json`` store it."""
    per = [{"agglomerate": k, **o, **p} for k, (o, p) in
           enumerate(zip(run.agglomerates, agglomerate_peaks(timeseries, len(run.agglomerates)), strict=True))]
    failed = np.array([a["strength_pa"] for a in per if a["ended_by"] == "failure"])
    fit = weibull_fit(failed).to_dict() if len(failed) >= MIN_FIT and np.ptp(failed) > 0 else None
    return {
        "n_agglomerates": len(per), "n_failed": len(failed),
        "modes": {m: sum(a["mode"] == m for a in per) for m in MODES},
        "weibull": fit,
        "mean_strength_pa": float(failed.mean()) if len(failed) else None,
        "median_strength_pa": float(np.median(failed)) if len(failed) else None,
        "strength_rule": "sigma_f = F_max / (d t), t = 1 m, over the agglomerates that failed",
        "mode_rule": "failed: two fragments of at least 0.1 of the solid area and the force below "
                     "crushing.residual_fraction of the peak; split: two such fragments, fragmented: more",
        "mean_disks": float(np.mean([a["disks"] for a in per])), "mean_bonds": float(np.mean([a["bonds"] for a in per])),
        "diameter_range_m": [config.crushing.d_min, config.crushing.d_max],
        "strain_rate_per_s": config.crushing.strain_rate,
        "agglomerates": per, "records": len(timeseries[AGGLOMERATE]),
        "wall_time_s": total_s, "wall_time_by_phase_s": dict(run.wall_time), "grainlab_version": grainlab.__version__,
    }


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json`` from the finished ``run.h5``."""
    return write_run_outputs(out, _figure_tasks, crack_map=False)


def _figure_tasks(series: dict[str, NDArray[np.float64]], summary: dict[str, Any]) -> list[Any]:
    from grainlab.plot import crushing
    from grainlab.plot.workers import FigureTask

    per = summary["agglomerates"]
    failed = np.array([a["strength_pa"] for a in per if a["ended_by"] == "failure"])
    points = weibull_points(failed / 1e3) if len(failed) else (failed, failed)
    return [FigureTask("fig01_force_displacement", crushing.force_displacement_figure, (series, per)),
            FigureTask("fig02_weibull", crushing.weibull_figure, (points, summary["weibull"]))]
