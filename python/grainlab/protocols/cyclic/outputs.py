"""A finished cyclic run's outputs: the summary (each cycle's stress ratios at its
turning points, and its end state: volumetric strain, Z, mean lambda, anisotropy),
``timeseries.csv``, ``summary.json`` and the figures, all from ``run.h5``. The
cycle table's rule (:func:`cycle_table`): docs/protocols.md, "The cyclic biaxial test".
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grainlab.columns import (
    AXIAL_STRAIN,
    COORDINATION_NUMBER,
    CYCLE,
    STRESS_RATIO,
    VOLUMETRIC_STRAIN,
)
from grainlab.protocols.biaxial.state import BiaxialRun
from grainlab.protocols.cyclic.config import CyclicConfig
from grainlab.protocols.runner import RunResult
from grainlab.protocols.specimen import run_summary, write_run_outputs

__all__ = ["CyclicResult", "cycle_table", "summarise", "write_outputs"]

#: What a cycle's row reports, each from its end record.
_END_COLUMNS = (VOLUMETRIC_STRAIN, COORDINATION_NUMBER, "mean_stability_index", "anisotropy", "force_anisotropy")


@dataclass(frozen=True)
class CyclicResult(RunResult):
    """What ``grainlab run cyclic`` reports: the summary and where the files are."""

    def one_line(self) -> str:
        s = self.summary
        if not s["cycles"]:
            return (f"grainlab cyclic: {s.get('n_grains', s['n_particles'])} grains, porosity {s['porosity_initial']:.3f}; no cycle "
                    f"completed: the axial strain reached +/-{100 * s['strain_limit']:.1f} % in the first; "
                    f"{s['wall_time_s']:.1f} s -> {self.out_dir}")
        first, last = s["cycles"][0], s["cycles"][-1]
        amplitude = (f"+/-{100 * s['strain_amplitude']:.2f} %" if s.get("control", "strain") == "strain"
                     else f"q +/-{s['stress_amplitude_pa'] / 1e3:.1f} kPa")
        failed = (f" (of {s['cycles_asked']}: the axial strain reached +/-{100 * s['strain_limit']:.1f} %)"
                  if s.get("stopped_at_strain_limit") else "")
        return (
            f"grainlab cyclic: {s.get('n_grains', s['n_particles'])} grains, porosity {s['porosity_initial']:.3f}; "
            f"{len(s['cycles'])} cycles{failed} of {amplitude}: sigma1/sigma3 at +A "
            f"{first['stress_ratio_compression']:.2f} -> {last['stress_ratio_compression']:.2f}, volumetric strain "
            f"{100 * last[VOLUMETRIC_STRAIN]:.3f} %, Z {s['coordination_number_initial']:.2f} -> "
            f"{last[COORDINATION_NUMBER]:.2f}; {self._undrained()}{s['wall_time_s']:.1f} s -> {self.out_dir}"
        )

    def _undrained(self) -> str:
        s = self.summary
        if s.get("shear_volume") != "constant":
            return ""
        return (f"constant volume: p' {s['cycles'][0]['mean_effective_stress_pa'] / 1e3:.1f} -> "
                f"{s['mean_effective_stress_after_cycles_pa'] / 1e3:.1f} kPa at the cycles' ends, u "
                f"{s['pore_pressure_after_cycles_pa'] / 1e3:.1f} kPa; ")


def cycle_table(timeseries: dict[str, np.ndarray], cell_pressure_pa: float | None = None) -> list[dict[str, float]]:
    """One row per complete cycle (module docstring): ``cycle``, the stress ratio and
    axial strain at its compression and extension turning points, and the end
    record's :data:`_END_COLUMNS`; at constant volume (``cell_pressure_pa`` given) also
    the end record's mean effective stress p' = (sigma_1' + sigma_3') / 2 and the
    pore-pressure analogue u = sigma_0 - sigma_3'."""
    cycle = np.asarray(timeseries[CYCLE], dtype=np.float64)
    eps = np.asarray(timeseries[AXIAL_STRAIN], dtype=np.float64)
    q = np.asarray(timeseries[STRESS_RATIO], dtype=np.float64)
    rows = []
    for k in range(1, int(np.floor(cycle.max() + 1e-3)) + 1):  # the last record is the end, to rounding
        inside = np.flatnonzero((cycle >= k - 1 - 1e-9) & (cycle <= k + 1e-9))
        end = int(np.argmin(np.abs(cycle - k)))
        top, bottom = inside[np.argmax(eps[inside])], inside[np.argmin(eps[inside])]
        row = {"cycle": k, "stress_ratio_compression": float(q[top]), "axial_strain_compression": float(eps[top]),
               "stress_ratio_extension": float(q[bottom]), "axial_strain_extension": float(eps[bottom])}
        row.update({str(c): float(timeseries[c][end]) for c in _END_COLUMNS if c in timeseries})
        if cell_pressure_pa is not None:
            s1, s3 = float(timeseries["axial_stress_pa"][end]), float(timeseries["confining_stress_felt_pa"][end])
            row["mean_effective_stress_pa"] = 0.5 * (s1 + s3)
            row["pore_pressure_pa"] = cell_pressure_pa - s3
        rows.append(row)
    return rows


def summarise(run: BiaxialRun, config: CyclicConfig, timeseries: dict[str, np.ndarray], total_s: float) -> dict[str, Any]:
    """The run's summary, as ``run.h5`` and ``summary.json`` store it."""
    plan = run.shear_plan()
    constant_volume = config.shear.volume == "constant"
    cycles = cycle_table(timeseries, config.consolidation.pressure if constant_volume else None)
    last = cycles[-1] if cycles else {}
    return run_summary(run, {
        "n_membrane_disks": run.consolidation.get("membrane_disks", 0),
        "porosity_initial": plan.porosity_initial,
        "porosity_after_consolidation": run.consolidation["porosity"],
        "coordination_number_initial": float(timeseries[COORDINATION_NUMBER][0]),
        "mean_stability_index_initial": float(timeseries["mean_stability_index"][0]),
        "anisotropy_initial": float(timeseries["anisotropy"][0]),
        "control": config.cyclic.control,
        "strain_amplitude": config.cyclic.strain_amplitude if config.cyclic.control == "strain" else None,
        "stress_amplitude_pa": None if config.cyclic.control == "strain" else config.cyclic.stress_amplitude,
        "strain_limit": config.cyclic.strain_limit,
        "cycles_asked": config.cyclic.cycles,
        "stopped_at_strain_limit": len(cycles) < config.cyclic.cycles,
        "shear_volume": config.shear.volume,
        "strain_rate": plan.strain_rate,
        "inertial_number": plan.inertial_number,
        "cycles": cycles,
        # the last cycle's, as scalars (a sweep's row holds the summary's scalars)
        "stress_ratio_compression_last_cycle": last.get("stress_ratio_compression"),
        "stress_ratio_extension_last_cycle": last.get("stress_ratio_extension"),
        "volumetric_strain_after_cycles": last.get(VOLUMETRIC_STRAIN),
        "coordination_number_after_cycles": last.get(COORDINATION_NUMBER),
        "mean_stability_index_after_cycles": last.get("mean_stability_index"),
        "anisotropy_after_cycles": last.get("anisotropy"),
        "mean_effective_stress_after_cycles_pa": last.get("mean_effective_stress_pa"),
        "pore_pressure_after_cycles_pa": last.get("pore_pressure_pa"),
    }, records=len(timeseries[AXIAL_STRAIN]), wall_time_s=total_s)


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json`` from the finished ``run.h5``."""
    return write_run_outputs(out, _figure_tasks)


def _figure_tasks(series: dict[str, np.ndarray], summary: dict[str, Any]) -> list[Any]:
    from grainlab.plot import cyclic
    from grainlab.plot.workers import FigureTask

    return [
        FigureTask("fig01_cycles", cyclic.loops_figure, (series,)),
        FigureTask("fig02_fabric_over_cycles", cyclic.fabric_figure, (series, summary["cycles"])),
    ]
