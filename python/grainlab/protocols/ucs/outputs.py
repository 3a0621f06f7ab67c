"""A finished unconfined compression run's outputs: the summary (the unconfined
strength q_u, Young's modulus, Poisson's ratio, the bonds and cracks), ``timeseries.csv``,
``summary.json`` and the figures, all from ``run.h5``.

Young's modulus E is the least-squares slope of the axial stress against the axial
strain over the records before the peak whose axial stress lies between
:data:`FIT_FROM` and :data:`FIT_TO` of q_u; Poisson's ratio is the slope of the
lateral strain (extension positive) against the axial strain (compression positive)
over the same records, i.e. minus the ratio of the two strains in one sign
convention. With fewer than two such records both are None. The rule was fixed
before any run was seen.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.columns import AXIAL_STRAIN, AXIAL_STRESS_PA, CEMENT_BONDS_BROKEN, LATERAL_STRAIN
from grainlab.protocols.runner import RunResult
from grainlab.protocols.specimen import run_summary, write_run_outputs
from grainlab.protocols.ucs.config import UcsConfig
from grainlab.protocols.ucs.state import UcsRun

__all__ = ["FIT_FROM", "FIT_TO", "UcsResult", "elastic_fit", "summarise", "write_outputs"]

#: The records E and nu are fitted on: axial stress from this fraction of q_u ...
FIT_FROM = 0.1
#: ... to this one, before the peak.
FIT_TO = 0.5


@dataclass(frozen=True)
class UcsResult(RunResult):
    """What ``grainlab run ucs`` reports: the summary and where the files are."""

    def one_line(self) -> str:
        s = self.summary
        e = "n/a" if s["youngs_modulus_pa"] is None else f"{s['youngs_modulus_pa'] / 1e6:.1f} MPa"
        nu = "n/a" if s["poisson_ratio"] is None else f"{s['poisson_ratio']:.3f}"
        return (
            f"grainlab ucs: {s['n_particles']} grains, {s['cement_bonds']} cement bonds; q_u "
            f"{s['unconfined_strength_pa'] / 1e3:.0f} kPa at {100 * s['axial_strain_at_peak']:.3f} % axial strain; "
            f"E {e}, nu {nu}; {s['cracks_at_peak']} cracks at the peak, {s['cracks_final']} at the end "
            f"({100 * s['axial_strain_final']:.3f} %, {s['ended_by']}); {s['wall_time_s']:.1f} s -> {self.out_dir}"
        )


def elastic_fit(timeseries: dict[str, NDArray[np.float64]]) -> tuple[NDArray[np.int64], float | None, float | None]:
    """The records of the fit (indices), E (Pa) and nu by the module's rule."""
    stress = np.asarray(timeseries[AXIAL_STRESS_PA], dtype=np.float64)
    strain = np.asarray(timeseries[AXIAL_STRAIN], dtype=np.float64)
    lateral = np.asarray(timeseries[LATERAL_STRAIN], dtype=np.float64)
    peak = int(np.argmax(stress))
    q_u = stress[peak]
    before = np.arange(len(stress)) < peak
    rows = np.flatnonzero(before & (stress >= FIT_FROM * q_u) & (stress <= FIT_TO * q_u))
    if len(rows) < 2:
        return rows, None, None
    youngs, _ = np.polyfit(strain[rows], stress[rows], 1)
    poisson, _ = np.polyfit(strain[rows], lateral[rows], 1)
    return rows, float(youngs), float(poisson)


def summarise(run: UcsRun, config: UcsConfig, timeseries: dict[str, NDArray[np.float64]],
              total_s: float) -> dict[str, Any]:
    """The run's summary, as ``run.h5`` and ``summary.json`` store it."""
    stress = np.asarray(timeseries[AXIAL_STRESS_PA], dtype=np.float64)
    strain = np.asarray(timeseries[AXIAL_STRAIN], dtype=np.float64)
    broken = np.asarray(timeseries[CEMENT_BONDS_BROKEN], dtype=np.float64)
    peak = int(np.argmax(stress))
    rows, youngs, poisson = elastic_fit(timeseries)
    return run_summary(run, {
        "unconfined_strength_pa": float(stress[peak]),
        "axial_strain_at_peak": float(strain[peak]),
        "youngs_modulus_pa": youngs,
        "poisson_ratio": poisson,
        "elastic_fit_rule": f"least squares over the records before the peak with {FIT_FROM:g} q_u <= sigma_1 <= "
                            f"{FIT_TO:g} q_u",
        "elastic_fit_records": len(rows),
        "elastic_fit_strains": [float(strain[rows[0]]), float(strain[rows[-1]])] if len(rows) else None,
        "cracks_at_peak": int(broken[peak]),
        "cracks_final": int(broken[-1]),
        "axial_stress_final_pa": float(stress[-1]),
        "axial_strain_final": float(strain[-1]),
        "ended_by": run.ended,
        "height0_m": run.height0,
        "width0_m": run.width0,
        "strain_rate_per_s": config.ucs.strain_rate,
    }, records=len(stress), release_steps=run.release_steps, seating_steps=run.seating_steps,
        load_steps=int(timeseries["step"][-1]) - run.start_step, wall_time_s=total_s)


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json`` from the finished ``run.h5``."""
    return write_run_outputs(out, _figure_tasks)


def _figure_tasks(series: dict[str, NDArray[np.float64]], summary: dict[str, Any]) -> list[Any]:
    from grainlab.plot import ucs
    from grainlab.plot.workers import FigureTask

    return [FigureTask("fig01_stress_strain", ucs.stress_strain_figure,
                       (series, summary["elastic_fit_strains"], summary["youngs_modulus_pa"]))]
