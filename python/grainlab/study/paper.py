"""The paper's Sec. 7 packing study: 19 packings (Tables 2-3), ``study.csv``,
Figs. 15-17 and ``summary.json``."""

from __future__ import annotations

import math
import os
import time
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

import grainlab
from grainlab.io.results import write_json_atomic
from grainlab.study.campaign import CampaignResult, Run, derive_seed, run_campaign
from grainlab.study.packing import GENERATION_FRICTION_SEARCH, PackingParams

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
    "force_anisotropy_binned",
    "wall_time_s",
    "status",
    "note",
    "seed",
    "anisotropy_fourier",
    "n_particles",
    "mean_wall_stress_pa",
    "generation_friction",
    "generation_expansions",
    "name",
    "error",
    "friction_search",
)

#: The two readings of the mean stability index (docs/fabric.md): over grains with >= 2
#: contacts, and over every grain (0- and 1-contact grains at lambda = 1).
LAMBDA_COLUMNS: dict[str, str] = {"mean_stability_index": "", "mean_stability_index_all": "_all"}


def study_runs(seed: int = 0, overrides: Mapping[str, Any] | None = None,
               irregular: Sequence[float] = IRREGULAR_POROSITIES,
               hexagonal: Sequence[float] = HEXAGONAL_POROSITIES) -> list[Run]:
    """The 19 runs (11 irregular, 8 hexagonal) with Tables 2-3 defaults; ``overrides``
    (packing parameters, e.g. a smaller box for tests) apply to all.

    The irregular runs carry their ``generation_friction`` in their parameters
    (``"search"`` unless overridden; a number fixes it); the hexagonal lattices are
    built, not generated, and do not. Each run's seed is derived from the campaign
    seed and its other parameters, not the generation friction, so the variants
    (``generation_friction`` = ``"search"``, 0, 0.9, ...) of one campaign seed start
    from the same diameters and placement. Every run's parameters are checked here,
    before any work (``ValueError`` naming the field)."""
    shared = dict(overrides or {})
    generation_friction = shared.pop("generation_friction", GENERATION_FRICTION_SEARCH)
    runs = []
    for kind, targets in (("irregular", irregular), ("hexagonal", hexagonal)):
        for target in targets:
            params = {**shared, "kind": kind, "porosity": float(target)}
            run_seed = derive_seed(seed, "packing", params)
            if kind == "irregular":
                params["generation_friction"] = generation_friction
            PackingParams.from_mapping(params)
            runs.append(Run(f"{kind}_{target:.3f}", "packing", params, run_seed,
                            {"kind": kind, "porosity_target": float(target)}))
    return runs


def number_or_nan(value: Any) -> float:
    """A table's value (a number or its text) as a float; NaN when it is none."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def packing_series(rows: Sequence[Mapping[str, Any]], kind: str | None, x: str, y: str) -> tuple[np.ndarray, np.ndarray]:
    """The finite ``(x, y)`` of the packings of ``kind`` (None: every kind) that did not
    fail, in row order: what every fit and figure of the study reads."""
    pts = [(number_or_nan(r.get(x)), number_or_nan(r.get(y))) for r in rows
           if (kind is None or r.get("kind") == kind) and r.get("status") != "failed"]
    arr = np.array([p for p in pts if math.isfinite(p[0]) and math.isfinite(p[1])], dtype=float).reshape(-1, 2)
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
#: The every-grain reading beside the >= 2 contacts one: the same colour, a lighter marker.
_STYLE_ALL = {"irregular": dict(marker="^", color="tab:blue", alpha=0.45, label="irregular, every grain"),
              "hexagonal": dict(marker="D", color="tab:red", alpha=0.45, mfc="none", label="hexagonal, every grain")}


def _pooled(rows: Sequence[Mapping[str, Any]], x: str, y: str) -> tuple[np.ndarray, np.ndarray]:
    xs = [packing_series(rows, kind, x, y) for kind in ("irregular", "hexagonal")]
    return np.concatenate([a for a, _ in xs]), np.concatenate([b for _, b in xs])


def study_figures(rows: Sequence[Mapping[str, Any]], out_dir: str | os.PathLike[str]) -> dict[str, Any]:
    """Figs. 15 (lambda vs Z), 16 (lambda vs porosity), 17 (lambda vs anisotropy with a
    linear fit over all packings), PNG + SVG, each with both readings of lambda (over
    grains with >= 2 contacts, filled markers; over every grain, lighter markers);
    returns the files and the Fig. 17 fits (``fig17_fit``: lambda over >= 2 contacts,
    ``fig17_fit_all``: over every grain)."""
    from grainlab.plot import new_axes, save_figure

    out = Path(out_dir)
    files: dict[str, list[str]] = {}
    specs = (
        ("fig15_lambda_vs_coordination", "coordination_number", "mean coordination number Z"),
        ("fig16_lambda_vs_porosity", "porosity", "nominal porosity n"),
        ("fig17_lambda_vs_anisotropy", "anisotropy", "fabric anisotropy a"),
    )
    fits: dict[str, dict[str, float]] = {"fig17_fit": {}, "fig17_fit_all": {}}
    for name, x_key, x_label in specs:
        ax = new_axes(figsize=(3.6, 3.0))
        for lam_key, suffix in LAMBDA_COLUMNS.items():
            style = _STYLE if not suffix else _STYLE_ALL
            for kind in ("irregular", "hexagonal"):
                x, y = packing_series(rows, kind, x_key, lam_key)
                if len(x):
                    order = np.argsort(x)
                    ax.plot(x[order], y[order], linestyle="none", **style[kind])
            if name.startswith("fig17"):
                x_all, y_all = _pooled(rows, x_key, lam_key)
                fit = linear_fit(x_all, y_all)
                fits[f"fig17_fit{suffix}"] = fit
                if math.isfinite(fit["slope"]):
                    grid = np.linspace(x_all.min(), x_all.max(), 2)
                    ax.plot(grid, fit["slope"] * grid + fit["intercept"], color="k", linewidth=0.8,
                            linestyle="-" if not suffix else "--",
                            label=f"fit{' (every grain)' if suffix else ''}: λ = {fit['slope']:.3f} a + "
                                  f"{fit['intercept']:.3f}, R² = {fit['r2']:.3f}")
        ax.set_xlabel(x_label)
        ax.set_ylabel("mean stability index λ")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=6)
        files[name] = [str(p) for p in save_figure(ax, out / name)]
    return {"files": files, **fits}


def trends(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The numbers behind the paper's claims, for both readings of lambda (keys with
    ``lambda_all``: over every grain; ``lambda``: over grains with >= 2 contacts):
    linear fits of lambda against Z, porosity and the anisotropy (exact, and Eq. 7 binned) per series
    and pooled, and hexagonal minus irregular lambda at the same Z (the irregular
    series interpolated at the hexagonal packings' Z, where their ranges overlap)."""
    out: dict[str, Any] = {}
    anisotropies = [k for k in ("anisotropy", "anisotropy_binned") if any(k in r for r in rows)]
    for lam_key, suffix in LAMBDA_COLUMNS.items():
        lam = f"lambda{suffix}"
        for x_key, x_name in (("coordination_number", "z"), ("porosity", "porosity"),
                              *((a, a) for a in anisotropies)):
            for kind in ("irregular", "hexagonal"):
                fit = linear_fit(*packing_series(rows, kind, x_key, lam_key))
                out[f"{kind}_{lam}_vs_{x_name}_slope"] = fit["slope"]
                out[f"{kind}_{lam}_vs_{x_name}_r2"] = fit["r2"]
            fit = linear_fit(*_pooled(rows, x_key, lam_key))
            out[f"all_{lam}_vs_{x_name}_slope"] = fit["slope"]
            out[f"all_{lam}_vs_{x_name}_r2"] = fit["r2"]
        zi, li = packing_series(rows, "irregular", "coordination_number", lam_key)
        zh, lh = packing_series(rows, "hexagonal", "coordination_number", lam_key)
        if len(zi) >= 2 and len(zh):
            order = np.argsort(zi)
            inside = (zh >= zi.min()) & (zh <= zi.max())
            interp = np.interp(zh, zi[order], li[order])
            out["hexagonal_in_irregular_z_range"] = int(inside.sum())
            out[f"hexagonal_minus_irregular_{lam}_at_same_z"] = (
                [float(v) for v in (lh - interp)[inside]] if inside.any() else []
            )
    return out


def run_study(
    out_dir: str | os.PathLike[str],
    *,
    seed: int = 0,
    workers: int | None = None,
    scheduler: str | Any | None = None,
    progress: bool = False,
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
    no_figures: dict[str, Any] = {"files": {}, "fig17_fit": {}, "fig17_fit_all": {}}
    fig = study_figures(campaign.rows, out) if figures else no_figures
    statuses = dict(Counter(row.get("status", "?") for row in campaign.rows))
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
        "fig17_fit_all": fig["fig17_fit_all"],
        "generation_friction": {r["name"]: r.get("generation_friction") for r in campaign.rows
                                if r.get("kind") == "irregular" and "name" in r},
        "trends": trends(campaign.rows),
        "figures": fig["files"],
        "grainlab_version": grainlab.__version__,
    }
    write_json_atomic(out / "summary.json", summary)
    return campaign, summary
