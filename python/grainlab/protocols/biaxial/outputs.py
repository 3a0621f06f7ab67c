"""A finished biaxial run's outputs: the summary, ``timeseries.csv`` and
``summary.json``, and the figures drawn from ``run.h5`` (with
:mod:`grainlab.plot` and :mod:`grainlab.postprocess.figures`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grainlab._interrupt import raise_if_interrupted
from grainlab.analysis.peak import peak_record
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO, VOLUMETRIC_STRAIN
from grainlab.io.results import RESULTS_FILE, timeseries_csv, write_json_atomic, write_text_atomic
from grainlab.paper import STRAIN_AT_PEAK, Z_AT_PEAK, Z_INITIAL
from grainlab.protocols.biaxial.config import BiaxialConfig
from grainlab.protocols.biaxial.state import BiaxialRun
from grainlab.protocols.cracks import crack_task
from grainlab.protocols.runner import RunResult
from grainlab.protocols.specimen import run_summary

#: The paper's reported values, for the summary and the docs.
PAPER_VALUES = {
    "coordination_number_initial": Z_INITIAL,
    "coordination_number_at_peak": Z_AT_PEAK,
    "axial_strain_at_peak": STRAIN_AT_PEAK,
}


@dataclass(frozen=True)
class BiaxialResult(RunResult):
    """What ``grainlab biaxial`` reports: the summary and where the files are."""

    def one_line(self) -> str:
        s = self.summary
        return (
            f"grainlab biaxial: {s.get('n_grains', s['n_particles'])} grains, porosity {s['porosity_initial']:.3f}, "
            f"Z0 {s['coordination_number_initial']:.2f}; peak sigma1/sigma3 {s['peak_stress_ratio']:.2f} "
            f"at {100 * s['axial_strain_at_peak']:.2f} % axial strain; {self._undrained()}strain rate "
            f"{s['strain_rate']:.3g} 1/s; {s['wall_time_s']:.1f} s -> {self.out_dir}"
        )

    def _undrained(self) -> str:
        s = self.summary
        if s.get("shear_volume") != "constant":
            return ""
        return (f"constant volume: u up to {s['pore_pressure_max_pa'] / 1e3:.1f} kPa at "
                f"{100 * s['axial_strain_at_pore_pressure_max']:.2f} %, {s['pore_pressure_final_pa'] / 1e3:.1f} kPa at "
                "the end; ")


def summarise(run: BiaxialRun, config: BiaxialConfig, timeseries: dict[str, np.ndarray], total_s: float) -> dict[str, Any]:
    shear = run.shear_plan()
    first = {k: float(v[0]) for k, v in timeseries.items()}
    last = {k: float(v[-1]) for k, v in timeseries.items()}
    k = peak_record(timeseries[AXIAL_STRAIN], timeseries[STRESS_RATIO])
    peak = {name: float(timeseries[name][k])
            for name in (STRESS_RATIO, AXIAL_STRAIN, "coordination_number", VOLUMETRIC_STRAIN)}
    return run_summary(run, {
        "n_membrane_disks": run.consolidation.get("membrane_disks", 0),
        "porosity_initial": shear.porosity_initial,
        "porosity_after_consolidation": run.consolidation["porosity"],
        "porosity_after_consolidation_overlap_corrected": run.consolidation["porosity_overlap_corrected"],
        "porosity_generated": run.sample.get("porosity"),
        "porosity_generated_overlap_corrected": run.sample.get("porosity_overlap_corrected"),
        "generation_stress_pa": run.sample.get("mean_wall_stress_pa"),
        "coordination_number_initial": first["coordination_number"],
        "coordination_number_at_peak": peak["coordination_number"],
        "coordination_number_final": last["coordination_number"],
        "peak_stress_ratio": peak[STRESS_RATIO],
        "axial_strain_at_peak": peak[AXIAL_STRAIN],
        "volumetric_strain_at_peak": peak[VOLUMETRIC_STRAIN],
        "final_stress_ratio": last[STRESS_RATIO],
        "final_volumetric_strain": last[VOLUMETRIC_STRAIN],
        "max_contraction": float(np.max(timeseries[VOLUMETRIC_STRAIN])),
        "shear_volume": config.shear.volume,
        **(_undrained(timeseries, config.consolidation.pressure) if config.shear.volume == "constant" else {}),
        "strain_rate": shear.strain_rate,
        "inertial_number": shear.inertial_number,
        "inertial_number_mean_diameter": shear.inertial_number_mean_diameter,
        "density_scaling_factor": shear.density_scaling_factor,
    }, records=len(timeseries[AXIAL_STRAIN]), wall_time_s=total_s, paper=PAPER_VALUES)


def is_constant_volume(config: dict[str, Any]) -> bool:
    """Whether a results file's configuration (nested, as ``run.h5`` stores it) is a
    constant-volume run's."""
    return bool(config.get("shear", {}).get("volume") == "constant")


def _undrained(timeseries: dict[str, np.ndarray], cell_pressure_pa: float) -> dict[str, float]:
    """A constant-volume run's pore-pressure analogue u = sigma_0 - sigma_3' (the effective
    lateral stress below the cell pressure): its largest value and the axial strain there
    (the phase transformation, where contraction turns to dilation), the final one, the
    smallest mean effective stress p' = (sigma_1' + sigma_3') / 2 and the final p' and q."""
    s1 = np.asarray(timeseries["axial_stress_pa"], dtype=np.float64)
    s3 = np.asarray(timeseries["confining_stress_felt_pa"], dtype=np.float64)
    u = cell_pressure_pa - s3
    p = 0.5 * (s1 + s3)
    k = int(np.argmax(u))
    return {
        "pore_pressure_max_pa": float(u[k]),
        "axial_strain_at_pore_pressure_max": float(timeseries[AXIAL_STRAIN][k]),
        "pore_pressure_final_pa": float(u[-1]),
        "mean_effective_stress_min_pa": float(p.min()),
        "mean_effective_stress_final_pa": float(p[-1]),
        "deviator_stress_final_pa": float(0.5 * (s1[-1] - s3[-1])),
    }


def _figures(timeseries: dict[str, np.ndarray], out: Path, constant_volume: bool) -> None:
    """Starts the macro curves (Figs. 8, 10, 18; a constant-volume run's stress path) in the
    current figure pool: they are drawn while the snapshots are measured, and finished when
    the pool closes."""
    from grainlab.plot import curve_tasks
    from grainlab.plot.workers import figure_pool

    with figure_pool(tasks=3) as pool:
        pool.draw(curve_tasks(timeseries, stress_path=constant_volume), out)


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json``, all from the finished
    ``run.h5``: a run stopped while they were written finishes them with ``--resume``.
    The figures are drawn side by side in worker processes, with their copies
    for the report, in the figure pool open around the run (``grainlab biaxial``'s,
    which then serves the report) or in one of their own
    (:class:`~grainlab.plot.workers.FigurePool`)."""
    from grainlab.io.hdf5 import read_results
    from grainlab.plot.workers import figure_pool
    from grainlab.postprocess import figures
    from grainlab.postprocess.products import store_run_products

    results = read_results(out / RESULTS_FILE)
    raise_if_interrupted()  # a Ctrl-C that h5py's clean-up swallowed stops the run here
    summary = dict(results.summary)
    write_text_atomic(out / "timeseries.csv", timeseries_csv(results.timeseries))
    with figure_pool(tasks=3 + len(figures.FIGURES), page_copies=True) as pool:
        _figures(results.timeseries, out, is_constant_volume(results.config))
        # the bands and lambda fields of every snapshot, stored in run.h5 for the figures,
        # the report, the viewer and the claims to read
        store_run_products(out / RESULTS_FILE, pool)
        raise_if_interrupted()
        # the paper's fabric figures (6, 7, 9, 11-14) from the snapshots, and their numbers
        summary["fabric"] = figures.fabric_figures(out).numbers.summary()
        cracks = crack_task(results)
        if cracks is not None:
            pool.draw([cracks], out)
    raise_if_interrupted()
    write_json_atomic(out / "summary.json", summary)
    return summary
