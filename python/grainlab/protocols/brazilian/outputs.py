"""A finished Brazilian run's outputs: the summary (the indirect tensile strength
sigma_t = 2 F_max / (pi D t), the peak force and where it was reached, the disc, its
bonds and its cracks), ``timeseries.csv``, ``summary.json`` and the figures, all from
``run.h5``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.columns import (
    AXIAL_STRAIN,
    CEMENT_BONDS_BROKEN,
    PLATEN_DISPLACEMENT_M,
    PLATEN_FORCE_N_PER_M,
    TENSILE_STRESS_PA,
)
from grainlab.protocols.brazilian.config import BrazilianConfig
from grainlab.protocols.brazilian.state import BrazilianRun
from grainlab.protocols.runner import RunResult
from grainlab.protocols.specimen import run_summary, write_run_outputs

__all__ = ["BrazilianResult", "summarise", "write_outputs"]


@dataclass(frozen=True)
class BrazilianResult(RunResult):
    """What ``grainlab run brazilian`` reports: the summary and where the files are."""

    def one_line(self) -> str:
        s = self.summary
        return (
            f"grainlab brazilian: a disc of {1e3 * s['diameter_m']:.1f} mm, {s['n_particles']} grains, "
            f"{s['cement_bonds']} cement bonds; sigma_t {s['tensile_strength_pa'] / 1e3:.0f} kPa (F_max "
            f"{s['peak_force_n_per_m'] / 1e3:.2f} kN/m) at {1e6 * s['displacement_at_peak_m']:.1f} um "
            f"({100 * s['axial_strain_at_peak']:.3f} % of D); {s['cracks_at_peak']} cracks at the peak, "
            f"{s['cracks_final']} at the end ({100 * s['axial_strain_final']:.3f} %, {s['ended_by']}); "
            f"{s['wall_time_s']:.1f} s -> {self.out_dir}"
        )


def summarise(run: BrazilianRun, config: BrazilianConfig, timeseries: dict[str, NDArray[np.float64]],
              total_s: float) -> dict[str, Any]:
    """The run's summary, as ``run.h5`` and ``summary.json`` store it."""
    series = {name: np.asarray(timeseries[name], dtype=np.float64) for name in (
        TENSILE_STRESS_PA, PLATEN_FORCE_N_PER_M, PLATEN_DISPLACEMENT_M, AXIAL_STRAIN, CEMENT_BONDS_BROKEN)}
    peak = int(np.argmax(series[TENSILE_STRESS_PA]))
    return run_summary(run, {
        "tensile_strength_pa": float(series[TENSILE_STRESS_PA][peak]),
        "peak_force_n_per_m": float(series[PLATEN_FORCE_N_PER_M][peak]),
        "displacement_at_peak_m": float(series[PLATEN_DISPLACEMENT_M][peak]),
        "axial_strain_at_peak": float(series[AXIAL_STRAIN][peak]),
        "cracks_at_peak": int(series[CEMENT_BONDS_BROKEN][peak]),
        "cracks_final": int(series[CEMENT_BONDS_BROKEN][-1]),
        "platen_force_start_n_per_m": float(series[PLATEN_FORCE_N_PER_M][0]),
        "tensile_stress_final_pa": float(series[TENSILE_STRESS_PA][-1]),
        "displacement_final_m": float(series[PLATEN_DISPLACEMENT_M][-1]),
        "axial_strain_final": float(series[AXIAL_STRAIN][-1]),
        "ended_by": run.ended,
        "diameter_m": run.diameter_m,
        "carve_diameter_m": run.carve_diameter_m,
        "disc_centre_m": list(run.centre_m),
        "sample_particles": run.sample_particles,
        "sample_cement_bonds": run.sample_cement_bonds,
        "loose_particles": run.loose_particles,
        "strain_rate_per_s": config.brazilian.strain_rate,
    }, records=len(series[TENSILE_STRESS_PA]), release_steps=run.release_steps,
        load_steps=int(timeseries["step"][-1]) - run.start_step, wall_time_s=total_s)


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json`` from the finished ``run.h5``."""
    return write_run_outputs(out, _figure_tasks, strain="of D (platen displacement)")


def _figure_tasks(series: dict[str, NDArray[np.float64]], summary: dict[str, Any]) -> list[Any]:
    from grainlab.plot import brazilian
    from grainlab.plot.workers import FigureTask

    return [FigureTask("fig01_force_displacement", brazilian.force_displacement_figure,
                       (series, summary["diameter_m"]))]
