"""The paper's Sec. 7 packing study: 19 packings (Tables 2-3), ``study.csv``,
Figs. 15-17 and ``summary.json``."""

from __future__ import annotations

import math
import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

import grainlab
from grainlab.io.results import write_json_atomic
from grainlab.study.campaign import CampaignResult, Run, make_run, run_campaign
from grainlab.study.packing import PackingParams

#: Table 2: target nominal porosities of the irregular packings.
IRREGULAR_POROSITIES: tuple[float, ...] = (0.08, 0.09, 0.10, 0.11, 0.12, 0.13, 0.14, 0.15, 0.16, 0.161, 0.165)
#: Table 3: target porosities of the hexagonal packings.
HEXAGONAL_POROSITIES: tuple[float, ...] = (0.08, 0.09, 0.10, 0.11, 0.12, 0.13, 0.14, 0.15)

#: Columns of ``study.csv``, in order.
STUDY_COLUMNS: tuple[str, ...] = (
    "kind",
    "porosity_target",
    "porosity",
    "porosity_overlap_corrected",
    "coordination_number",
    "mechanical_coordination_number",
    "mean_stability_index",
    "mean_stability_index_all",
    "anisotropy",
    "anisotropy_binned",
    "force_anisotropy",
    "wall_time_s",
    "status",
    "note",
    "seed",
    "anisotropy_fourier",
    "n_particles",
    "mean_wall_stress_pa",
    "name",
    "error",
)


def study_runs(seed: int = 0, overrides: Mapping[str, Any] | None = None,
               irregular: Sequence[float] = IRREGULAR_POROSITIES,
               hexagonal: Sequence[float] = HEXAGONAL_POROSITIES) -> list[Run]:
    """The 19 runs (11 irregular, 8 hexagonal) with Tables 2-3 defaults; ``overrides``
    (packing parameters, e.g. a smaller box for tests) apply to all."""
    runs = []
    for kind, targets in (("irregular", irregular), ("hexagonal", hexagonal)):
        for target in targets:
            params = {**dict(overrides or {}), "kind": kind, "porosity": float(target)}
            runs.append(make_run(f"{kind}_{target:.3f}", "packing", params, seed,
                                 labels={"kind": kind, "porosity_target": float(target)}))
    return runs


def _series(rows: Sequence[Mapping[str, Any]], kind: str, x: str, y: str) -> tuple[np.ndarray, np.ndarray]:
    pts = [(float(r[x]), float(r[y])) for r in rows
           if r.get("kind") == kind and r.get("status") != "failed" and x in r and y in r]
    pts = [p for p in pts if math.isfinite(p[0]) and math.isfinite(p[1])]
    arr = np.array(pts, dtype=float).reshape(-1, 2)
    return arr[:, 0], arr[:, 1]


def linear_fit(x: np.ndarray, y: np.ndarray) -> dict[str, float]:
    """Least-squares ``y = slope x + intercept`` and its R^2 (NaN with fewer than 3 points)."""
    if len(x) < 3 or np.ptp(x) == 0:
        return {"slope": float("nan"), "intercept": float("nan"), "r2": float("nan"), "n": len(x)}
    slope, intercept = np.polyfit(x, y, 1)
    resid = y - (slope * x + intercept)
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(np.sum(resid**2)) / ss_tot if ss_tot > 0 else float("nan")
    return {"slope": float(slope), "intercept": float(intercept), "r2": r2, "n": len(x)}


_STYLE = {"irregular": dict(marker="o", color="tab:blue", label="irregular"),
          "hexagonal": dict(marker="s", color="tab:red", label="hexagonal", mfc="none")}


def study_figures(rows: Sequence[Mapping[str, Any]], out_dir: str | os.PathLike[str]) -> dict[str, Any]:
    """Figs. 15 (lambda vs Z), 16 (lambda vs porosity), 17 (lambda vs anisotropy with a
    linear fit over all packings), PNG + SVG; returns the files and the fit."""
    from grainlab.plot import new_axes, save_figure

    out = Path(out_dir)
    files: dict[str, list[str]] = {}
    specs = (
        ("fig15_lambda_vs_coordination", "coordination_number", "mean coordination number Z"),
        ("fig16_lambda_vs_porosity", "porosity", "nominal porosity n"),
        ("fig17_lambda_vs_anisotropy", "anisotropy", "fabric anisotropy a (Eq. 7)"),
    )
    fit: dict[str, float] = {}
    for name, x_key, x_label in specs:
        ax = new_axes(figsize=(3.6, 3.0))
        xs, ys = [], []
        for kind in ("irregular", "hexagonal"):
            x, y = _series(rows, kind, x_key, "mean_stability_index")
            if len(x):
                order = np.argsort(x)
                ax.plot(x[order], y[order], linestyle="none", **_STYLE[kind])
            xs.append(x)
            ys.append(y)
        if name.startswith("fig17"):
            x_all, y_all = np.concatenate(xs), np.concatenate(ys)
            fit = linear_fit(x_all, y_all)
            if math.isfinite(fit["slope"]):
                grid = np.linspace(x_all.min(), x_all.max(), 2)
                ax.plot(grid, fit["slope"] * grid + fit["intercept"], color="k", linewidth=0.8,
                        label=f"fit: λ = {fit['slope']:.3f} a + {fit['intercept']:.3f}, R² = {fit['r2']:.3f}")
        ax.set_xlabel(x_label)
        ax.set_ylabel("mean stability index λ")
        ax.legend(fontsize=7)
        files[name] = [str(p) for p in save_figure(ax, out / name)]
    return {"files": files, "fig17_fit": fit}


def trends(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The numbers behind the paper's claims: correlation of lambda with Z per series,
    and hexagonal vs irregular lambda at overlapping Z."""
    out: dict[str, Any] = {}
    for kind in ("irregular", "hexagonal"):
        z, lam = _series(rows, kind, "coordination_number", "mean_stability_index")
        fit = linear_fit(z, lam)
        out[f"{kind}_lambda_vs_z_slope"] = fit["slope"]
        out[f"{kind}_lambda_vs_z_r2"] = fit["r2"]
    for x_key in ("anisotropy", "anisotropy_fourier"):
        for kind in ("irregular", "hexagonal"):
            x, lam = _series(rows, kind, x_key, "mean_stability_index")
            out[f"{kind}_lambda_vs_{x_key}_r2"] = linear_fit(x, lam)["r2"]
        xs = [_series(rows, kind, x_key, "mean_stability_index") for kind in ("irregular", "hexagonal")]
        fit = linear_fit(np.concatenate([x for x, _ in xs]), np.concatenate([y for _, y in xs]))
        out[f"all_lambda_vs_{x_key}_slope"] = fit["slope"]
        out[f"all_lambda_vs_{x_key}_r2"] = fit["r2"]
    zi, li = _series(rows, "irregular", "coordination_number", "mean_stability_index")
    zh, lh = _series(rows, "hexagonal", "coordination_number", "mean_stability_index")
    if len(zi) >= 2 and len(zh):
        order = np.argsort(zi)
        inside = (zh >= zi.min()) & (zh <= zi.max())
        interp = np.interp(zh, zi[order], li[order])
        out["hexagonal_in_irregular_z_range"] = int(inside.sum())
        out["hexagonal_minus_irregular_lambda_at_same_z"] = (
            [float(v) for v in (lh - interp)[inside]] if inside.any() else []
        )
    return out


def run_study(
    out_dir: str | os.PathLike[str],
    *,
    seed: int = 0,
    workers: int | None = None,
    scheduler: str | Any | None = None,
    progress: bool = True,
    overrides: Mapping[str, Any] | None = None,
    irregular: Sequence[float] = IRREGULAR_POROSITIES,
    hexagonal: Sequence[float] = HEXAGONAL_POROSITIES,
    figures: bool = True,
) -> tuple[CampaignResult, dict[str, Any]]:
    """Runs (or resumes) the study into ``out_dir``; returns the campaign and ``summary.json``'s content."""
    started = time.perf_counter()
    out = Path(out_dir)
    runs = study_runs(seed, overrides, irregular, hexagonal)
    campaign = run_campaign(runs, out, workers=workers, scheduler=scheduler, progress=progress,
                            table_name="study.csv", columns=STUDY_COLUMNS)
    fig = study_figures(campaign.rows, out) if figures else {"files": {}, "fig17_fit": {}}
    statuses: dict[str, int] = {}
    for row in campaign.rows:
        statuses[row.get("status", "?")] = statuses.get(row.get("status", "?"), 0) + 1
    summary = {
        "campaign_wall_time_s": time.perf_counter() - started,
        "runs_wall_time_s_sum": float(sum(float(r.get("wall_time_s") or 0.0) for r in campaign.rows)),
        "n_runs": len(runs),
        "executed": campaign.executed,
        "skipped_finished": campaign.skipped,
        "failed": campaign.failed,
        "statuses": statuses,
        "workers": workers,
        "scheduler": scheduler if isinstance(scheduler, str) else (None if scheduler is None else "client"),
        "seed": seed,
        "overrides": dict(overrides or {}),
        # what every packing shared (PackingParams defaults with the overrides), for the report
        "packing_params": {**asdict(PackingParams()), **dict(overrides or {})},
        "fig17_fit": fig["fig17_fit"],
        "trends": trends(campaign.rows),
        "figures": fig["files"],
        "grainlab_version": grainlab.__version__,
    }
    write_json_atomic(out / "summary.json", summary)
    return campaign, summary
