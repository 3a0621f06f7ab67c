"""A finished oedometer run's outputs: the summary (K0 on first loading, K against
the overconsolidation ratio on unloading, Jaky's and Mayne-Kulhawy's values when a
friction angle is given), ``timeseries.csv``, ``summary.json`` and the figures, all
from ``run.h5``. The K0 rule (:func:`k0_loading`): docs/protocols.md, "The
oedometer (K0) test".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grainlab.columns import (
    HORIZONTAL_STRESS_PA,
    LATERAL_STRESS_RATIO,
    OVERCONSOLIDATION_RATIO,
    VERTICAL_STRESS_PA,
)
from grainlab.protocols.oedometer.config import OedometerConfig
from grainlab.protocols.oedometer.state import OedometerRun
from grainlab.protocols.runner import RunResult
from grainlab.protocols.specimen import run_summary, write_run_outputs

__all__ = ["K0_FROM_STRESS_RATIO", "OedometerResult", "first_loading", "k0_loading", "summarise", "write_outputs"]

#: The first-loading records that K0 is fitted on start at this many times sigma_0.
K0_FROM_STRESS_RATIO = 4.0


@dataclass(frozen=True)
class OedometerResult(RunResult):
    """What ``grainlab run oedometer`` reports: the summary and where the files are."""

    def one_line(self) -> str:
        s = self.summary
        jaky = "" if s["k0_jaky"] is None else f" (Jaky {s['k0_jaky']:.3f})"
        return (
            f"grainlab oedometer: {s.get('n_grains', s['n_particles'])} grains, porosity {s['porosity_initial']:.3f}; K0 "
            f"{s['k0_loading']:.3f}{jaky} on loading to {s['max_vertical_stress_pa'] / 1e3:.0f} kPa; "
            f"K {s['lateral_stress_ratio_final']:.3f} at OCR {s['overconsolidation_ratio_final']:.2f}; "
            f"{s['wall_time_s']:.1f} s -> {self.out_dir}"
        )


def first_loading(timeseries: dict[str, np.ndarray]) -> np.ndarray:
    """Indices of the first-loading records: each at a vertical stress above every earlier one's."""
    sigma_v = np.asarray(timeseries[VERTICAL_STRESS_PA], dtype=np.float64)
    previous = np.maximum.accumulate(np.r_[-np.inf, sigma_v[:-1]])
    return np.flatnonzero(sigma_v > previous)


def k0_loading(timeseries: dict[str, np.ndarray], consolidation_pressure_pa: float) -> float:
    """K0 on first loading by the module's rule (NaN with fewer than two records to fit)."""
    rows = first_loading(timeseries)
    sigma_v = np.asarray(timeseries[VERTICAL_STRESS_PA], dtype=np.float64)[rows]
    sigma_h = np.asarray(timeseries[HORIZONTAL_STRESS_PA], dtype=np.float64)[rows]
    far = sigma_v >= K0_FROM_STRESS_RATIO * consolidation_pressure_pa * (1.0 - 1e-9)
    if np.count_nonzero(far) < 2:
        far = np.arange(len(rows)) > 0
    if np.count_nonzero(far) < 2:
        return math.nan
    slope, _ = np.polyfit(sigma_v[far], sigma_h[far], 1)
    return float(slope)


def summarise(run: OedometerRun, config: OedometerConfig, timeseries: dict[str, np.ndarray],
              total_s: float) -> dict[str, Any]:
    """The run's summary, as ``run.h5`` and ``summary.json`` store it."""
    k = np.asarray(timeseries[LATERAL_STRESS_RATIO], dtype=np.float64)
    ocr = np.asarray(timeseries[OVERCONSOLIDATION_RATIO], dtype=np.float64)
    loading = set(first_loading(timeseries).tolist())
    angle = config.oedometer.friction_angle
    phi = None if isinstance(angle, str) else angle  # "auto": no comparison
    jaky = None if phi is None else 1.0 - math.sin(phi)
    unloading = [
        {"overconsolidation_ratio": float(ocr[r]), "lateral_stress_ratio": float(k[r]),
         "mayne_kulhawy": None if phi is None or jaky is None else jaky * float(ocr[r]) ** math.sin(phi)}
        for r in range(len(k)) if r not in loading
    ]
    return run_summary(run, {
        "porosity_initial": float(timeseries["porosity"][0]),
        "void_ratio_initial": float(timeseries["void_ratio"][0]),
        "porosity_after_consolidation": run.consolidation["porosity"],
        "coordination_number_initial": float(timeseries["coordination_number"][0]),
        "k0_loading": k0_loading(timeseries, config.consolidation.pressure),
        "k0_rule": f"slope of sigma_h on sigma_v over first loading at sigma_v >= {K0_FROM_STRESS_RATIO:g} sigma_0",
        "max_vertical_stress_pa": run.max_vertical_stress_pa,
        "void_ratio_at_max_stress": float(timeseries["void_ratio"][int(np.argmax(timeseries[VERTICAL_STRESS_PA]))]),
        "lateral_stress_ratio_final": float(k[-1]),
        "overconsolidation_ratio_final": float(ocr[-1]),
        "unloading": unloading,
        "friction_angle_deg": None if phi is None else math.degrees(phi),
        "k0_jaky": jaky,
    }, records=len(k), load_steps=int(timeseries["step"][-1]) - run.load_start_step, wall_time_s=total_s)


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json`` from the finished ``run.h5``."""
    return write_run_outputs(out, _figure_tasks)


def _figure_tasks(series: dict[str, np.ndarray], summary: dict[str, Any]) -> list[Any]:
    from grainlab.plot import oedometer
    from grainlab.plot.workers import FigureTask

    loading = first_loading(series)
    return [
        FigureTask("fig01_lateral_stress_ratio", oedometer.lateral_stress_ratio_figure,
                   (series, loading, summary["k0_jaky"], summary["friction_angle_deg"])),
        FigureTask("fig02_compression", oedometer.compression_figure, (series, loading)),
    ]
