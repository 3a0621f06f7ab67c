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
from grainlab.io.results import write_text_atomic
from grainlab.protocols.oedometer.config import OedometerConfig
from grainlab.protocols.oedometer.state import OedometerRun
from grainlab.protocols.runner import RunResult
from grainlab.protocols.specimen import run_summary, write_run_outputs

__all__ = ["FRAGMENTS_CSV", "K0_FROM_STRESS_RATIO", "OedometerResult", "first_loading", "k0_loading", "summarise",
           "fragment_sieves", "write_outputs", "yield_stress"]

#: A sample of agglomerates' fragment grading at each load step.
FRAGMENTS_CSV = "fragments.csv"
#: The yield stress's rule (fixed before any run of agglomerates was seen).
YIELD_RULE = ("two tangents, on e against log sigma_v over first loading: the line through the first two records "
              "(sigma_0 and the first load step) meets the line through the two consecutive records of steepest "
              "descent")

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
            f"{self._agglomerates()}{s['wall_time_s']:.1f} s -> {self.out_dir}"
        )

    def _agglomerates(self) -> str:
        s = self.summary
        if "agglomerates" not in s:
            return ""
        y = "n/a" if s["yield_stress_pa"] is None else f"{s['yield_stress_pa'] / 1e3:.0f} kPa"
        g = s["fragment_grading"]
        return (f"{s['agglomerates']} agglomerates of {s['n_particles']} disks: yield stress {y}; fragments "
                f"{g[0]['fragments']} at {g[0]['vertical_stress_pa'] / 1e3:.0f} kPa, {g[-1]['fragments']} at "
                f"{g[-1]['vertical_stress_pa'] / 1e3:.0f} kPa (d50 {1e3 * g[0]['d50_m']:.2f} -> "
                f"{1e3 * g[-1]['d50_m']:.2f} mm); ")


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


def yield_stress(timeseries: dict[str, np.ndarray]) -> float | None:
    """The yield stress (Pa) by :data:`YIELD_RULE`: None with fewer than four first-loading
    records, no later stretch steeper than the first, or a crossing outside the first
    loading's stresses (docs/cemented.md, "Crushable grains in the oedometer")."""
    rows = first_loading(timeseries)
    if len(rows) < 4:
        return None
    x = np.log(np.asarray(timeseries[VERTICAL_STRESS_PA], dtype=np.float64)[rows])
    e = np.asarray(timeseries["void_ratio"], dtype=np.float64)[rows]
    slopes = np.diff(e) / np.diff(x)
    steepest = 1 + int(np.argmin(slopes[1:]))
    if not slopes[steepest] < slopes[0]:
        return None
    start = (slopes[0], e[0] - slopes[0] * x[0])
    steep = (slopes[steepest], e[steepest] - slopes[steepest] * x[steepest])
    crossing = (steep[1] - start[1]) / (start[0] - steep[0])
    return float(np.exp(crossing)) if x[0] <= crossing <= x[-1] else None


def _agglomerates(run: OedometerRun, timeseries: dict[str, np.ndarray], sieves: list[float]) -> dict[str, Any]:
    """A sample of agglomerates' summary: their count, the yield stress and the fragments'
    grading at each load step."""
    if "agglomerates" not in run.sample:
        return {}
    return {"agglomerates": run.sample["agglomerates"], "agglomerate_bonds": run.sample["agglomerate_bonds"],
            "yield_stress_pa": yield_stress(timeseries),
            "yield_rule": YIELD_RULE, "fragment_sieves_m": sieves, "fragment_grading": run.fragment_grading}


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
        **_agglomerates(run, timeseries, fragment_sieves(config)),
    }, records=len(k), load_steps=int(timeseries["step"][-1]) - run.load_start_step, wall_time_s=total_s)


def fragment_sieves(config: OedometerConfig) -> list[float]:
    """The fragment grading's sieves: 25, evenly in log size from half a disk's diameter
    to the largest grain's."""
    sieves: list[float] = np.geomspace(0.5 * config.agglomerate.disk_diameter, config.sample.d_max, 25).tolist()
    return sieves


def write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures, a sample of agglomerates' ``fragments.csv`` and
    ``summary.json`` from the finished ``run.h5``."""
    return write_run_outputs(out, _figure_tasks, files=_fragments_csv)


def _fragments_csv(out: Path, summary: dict[str, Any]) -> None:
    """One row per load step and sieve: the percent of the solid area passing it."""
    if "fragment_grading" not in summary:
        return
    lines = ["load_step,vertical_stress_pa,fragments,d50_m,sieve_m,percent_passing"]
    for g in summary["fragment_grading"]:
        lines += [f"{g['load_step']},{g['vertical_stress_pa']!r},{g['fragments']},{g['d50_m']!r},{size!r},{p!r}"
                  for size, p in zip(summary["fragment_sieves_m"], g["percent_passing"], strict=True)]
    write_text_atomic(out / FRAGMENTS_CSV, "\n".join(lines) + "\n")


def _figure_tasks(series: dict[str, np.ndarray], summary: dict[str, Any]) -> list[Any]:
    from grainlab.plot import oedometer
    from grainlab.plot.workers import FigureTask

    loading = first_loading(series)
    grading = [FigureTask("fig03_fragment_grading", oedometer.fragment_grading_figure,
                          (summary["fragment_sieves_m"], summary["fragment_grading"]))] if "fragment_grading" in summary else []
    return [
        FigureTask("fig01_lateral_stress_ratio", oedometer.lateral_stress_ratio_figure,
                   (series, loading, summary["k0_jaky"], summary["friction_angle_deg"])),
        FigureTask("fig02_compression", oedometer.compression_figure, (series, loading, summary.get("yield_stress_pa"))),
        *grading,
    ]
