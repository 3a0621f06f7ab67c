"""A finished simple-shear run's outputs: the summary (the peak and the steady
state, the mean over the records from :data:`STEADY_FROM` of the final strain on;
the dilatancy, the Rothenburg-Bathurst residual over every record),
``timeseries.csv``, ``summary.json`` and the figures, all from ``run.h5``
(docs/protocols.md, "Periodic simple shear")."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grainlab.columns import (
    COORDINATION_NUMBER,
    FRICTION_COEFFICIENT,
    INERTIAL_NUMBER,
    NORMAL_STRESS_PA,
    POROSITY,
    RB_RESIDUAL,
    SHEAR_STRAIN,
    VOLUMETRIC_STRAIN,
)
from grainlab.protocols.runner import RunResult
from grainlab.protocols.simple_shear.config import SimpleShearConfig
from grainlab.protocols.simple_shear.state import SimpleShearRun
from grainlab.protocols.specimen import run_summary, write_run_outputs

__all__ = ["STEADY_FROM", "SimpleShearResult", "steady_rows", "summarise", "write_outputs"]

#: The steady state is averaged over the records at gamma >= this x the final strain.
STEADY_FROM = 0.5


@dataclass(frozen=True)
class SimpleShearResult(RunResult):
    """What ``grainlab run simple_shear`` reports: the summary and where the files are."""

    def one_line(self) -> str:
        s = self.summary
        return (
            f"grainlab simple_shear ({s['volume']} volume): {s.get('n_grains', s['n_particles'])} grains, I {s['inertial_number_set']:.1e}; "
            f"peak mu {s['friction_coefficient_peak']:.3f} at {100 * s['shear_strain_at_peak']:.1f} %, steady mu "
            f"{s['friction_coefficient_steady']:.3f}, porosity {s['porosity_steady']:.4f}, Z "
            f"{s['coordination_number_steady']:.2f} at gamma >= {100 * s['steady_from_strain']:.0f} %; "
            f"{s['wall_time_s']:.1f} s -> {self.out_dir}"
        )


def steady_rows(timeseries: dict[str, np.ndarray], final_strain: float) -> np.ndarray:
    """Indices of the steady-state records (the module's rule)."""
    gamma = np.asarray(timeseries[SHEAR_STRAIN], dtype=np.float64)
    return np.flatnonzero(gamma >= STEADY_FROM * final_strain * (1.0 - 1e-9))


def _mean(values: np.ndarray, rows: np.ndarray) -> float:
    return float(np.mean(values[rows])) if len(rows) else math.nan


def summarise(run: SimpleShearRun, config: SimpleShearConfig, timeseries: dict[str, np.ndarray],
              total_s: float) -> dict[str, Any]:
    """The run's summary, as ``run.h5`` and ``summary.json`` store it."""
    ts = {k: np.asarray(v, dtype=np.float64) for k, v in timeseries.items()}
    final = config.simple_shear.final_strain
    rows = steady_rows(ts, final)
    mu = ts[FRICTION_COEFFICIENT]
    peak = int(np.nanargmax(mu))
    residual = np.abs(ts[RB_RESIDUAL])
    steady = {f"{name}_steady": _mean(ts[name], rows) for name in
              (FRICTION_COEFFICIENT, POROSITY, COORDINATION_NUMBER, "mechanical_coordination_number",
               "mean_stability_index", "anisotropy", "force_anisotropy", INERTIAL_NUMBER, NORMAL_STRESS_PA,
               VOLUMETRIC_STRAIN, "kinetic_stress_share")}
    return run_summary(run, {
        "volume": config.simple_shear.volume,
        "inertial_number_set": config.simple_shear.inertial_number,
        "shear_rate_per_s": run.shear_rate_per_s,
        "normal_stress_set_pa": run.normal_stress_pa,
        "mean_diameter_m": run.mean_diameter_m,
        "cell_width_m": float(run.consolidation["width_m"]),
        "porosity_initial": float(ts[POROSITY][0]),
        "coordination_number_initial": float(ts[COORDINATION_NUMBER][0]),
        "final_strain": final,
        "friction_coefficient_peak": float(mu[peak]),
        "shear_strain_at_peak": float(ts[SHEAR_STRAIN][peak]),
        "steady_from_strain": STEADY_FROM * final,
        "steady_records": len(rows),
        "steady_rule": f"mean over the records at gamma >= {STEADY_FROM:g} x the final strain",
        **steady,
        "friction_coefficient_steady_sd": float(np.std(mu[rows])) if len(rows) else math.nan,
        "volumetric_strain_final": float(ts[VOLUMETRIC_STRAIN][-1]),
        "volumetric_strain_min": float(np.min(ts[VOLUMETRIC_STRAIN])),
        "normal_stress_final_pa": float(ts[NORMAL_STRESS_PA][-1]),
        "rb_residual_max_abs": float(np.nanmax(residual)),
        "rb_residual_mean_abs": float(np.nanmean(residual)),
    }, records=len(mu), shear_steps=int(ts["step"][-1] - ts["step"][0]), wall_time_s=total_s)


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json`` from the finished ``run.h5``."""
    return write_run_outputs(out, _figure_tasks)


def _figure_tasks(series: dict[str, np.ndarray], summary: dict[str, Any]) -> list[Any]:
    from grainlab.plot import simple_shear
    from grainlab.plot.workers import FigureTask

    steady = summary["steady_from_strain"]
    return [
        FigureTask("fig01_friction_and_volume", simple_shear.friction_volume_figure, (series, steady)),
        FigureTask("fig02_fabric", simple_shear.fabric_figure, (series, steady)),
        FigureTask("fig03_stress_force_fabric", simple_shear.stress_force_fabric_figure, (series,)),
        FigureTask("fig04_stress_path", simple_shear.stress_path_figure,
                   (series, summary["friction_coefficient_steady"])),
    ]
