"""Figures of a reproduction: every seed, their mean and the 95 % interval over
seeds against axial strain (PNG for ``reproduction.html``; docs/reproduction.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from grainlab import plot
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO, VOLUMETRIC_STRAIN
from grainlab.io.hdf5 import snapshot_strain
from grainlab.reproduction.runs import ReproductionPlan, rate_family, variant_folder
from grainlab.reproduction.verdicts import t_interval

__all__ = ["DPI", "draw_figures"]

#: Resolution of the PNGs (the page's size matters more than print quality).
DPI = 80

Measures = Mapping[str, Any]


def _save(fig: Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with plot.paper_style():
        fig.savefig(path, format="png", dpi=DPI)
    return path


def _ensemble(runs: Sequence[Measures], key: Callable[[Mapping[str, Any]], float]
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[tuple[np.ndarray, np.ndarray]]]:
    """Per snapshot strain (rounded to 1e-4): mean, CI low, CI high over the seeds, and each seed's curve."""
    by_strain: dict[float, list[float]] = {}
    curves = []
    for m in runs:
        xs, ys = [], []
        for row in m["snapshots"]:
            value = key(row)
            x = round(float(row[AXIAL_STRAIN]), 4)
            xs.append(x)
            ys.append(value)
            if math.isfinite(value):
                by_strain.setdefault(x, []).append(value)
        curves.append((np.array(xs), np.array(ys, dtype=np.float64)))
    strains = np.array(sorted(by_strain))
    mean, low, high = [], [], []
    for x in strains:
        v = np.array(by_strain[x])
        mean.append(float(v.mean()))
        ci = t_interval(v) if v.size >= 2 else (math.nan, math.nan)
        low.append(ci[0])
        high.append(ci[1])
    return strains, np.array(mean), np.array(low), np.array(high), curves


def _value(name: str) -> Callable[[Mapping[str, Any]], float]:
    def get(row: Mapping[str, Any]) -> float:
        if (name.startswith(("inside_", "outside_", "auc_lambda")) and name != "auc_lambda_peak_band"
                and not row.get("band_found")):
            return math.nan
        value = row.get(name)
        return math.nan if value is None else float(value)

    return get


def _band_plot(ax: Any, runs: Sequence[Measures], name: str, label: str, color: str, seeds: bool = False) -> None:
    x, mean, low, high, curves = _ensemble(runs, _value(name))
    if seeds:
        for cx, cy in curves:
            ax.plot(100 * cx, cy, color=color, linewidth=0.5, alpha=0.35)
    if x.size:
        ax.plot(100 * x, mean, color=color, marker="o", markersize=2.5, linewidth=1.3, label=label)
        ok = np.isfinite(low)
        ax.fill_between(100 * x[ok], low[ok], high[ok], color=color, alpha=0.2, linewidth=0)


def _legend(ax: Any) -> None:
    """A legend of the labelled curves; none when nothing was drawn (a short run
    without an accepted band has no band curves)."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(frameon=False, fontsize=7)


def _strain_axis(ax: Any) -> None:
    ax.set_xlabel(r"axial strain $\varepsilon_{11}$ (%)")
    _limits_from_lines(ax)


def _limits_from_lines(ax: Any) -> None:
    """y limits from the plotted curves (means, seeds, marks), so that an interval
    from two or three seeds, which can be far wider, does not flatten them."""
    values = [np.asarray(line.get_ydata(), dtype=np.float64) for line in ax.get_lines()]
    finite = np.concatenate([v[np.isfinite(v)] for v in values]) if values else np.zeros(0)
    if finite.size:
        low, high = float(finite.min()), float(finite.max())
        pad = 0.15 * (high - low) if high > low else 0.05 * max(abs(high), 1e-3)
        ax.set_ylim(low - pad, high + pad)


def _macro_figure(runs: Sequence[Measures], title: str) -> Figure:
    with plot.paper_style():
        fig = Figure(figsize=(8.0, 3.2), layout="constrained")
        axes = fig.subplots(1, 2)
        for key, ax, ylabel in ((STRESS_RATIO, axes[0], r"$\sigma_1/\sigma_3$"),
                                (VOLUMETRIC_STRAIN, axes[1], "volumetric strain (%), compression +")):
            scale = 100.0 if key == VOLUMETRIC_STRAIN else 1.0
            grids = [np.asarray(m["macro"]["records"][AXIAL_STRAIN]) for m in runs]
            grid = grids[int(np.argmin([g[-1] for g in grids]))]
            stack = []
            for m in runs:
                rec = m["macro"]["records"]
                eps, y = np.asarray(rec[AXIAL_STRAIN]), np.asarray(rec[key], dtype=np.float64)
                ax.plot(100 * eps, scale * y, color="0.6", linewidth=0.6)
                stack.append(np.interp(grid, eps, y))
            values = np.array(stack)
            ax.plot(100 * grid, scale * values.mean(axis=0), color="C0", linewidth=1.4, label="mean over seeds")
            if len(runs) >= 2:
                ci = np.array([t_interval(values[:, k]) for k in range(grid.size)])
                ax.fill_between(100 * grid, scale * ci[:, 0], scale * ci[:, 1], color="C0", alpha=0.2, linewidth=0,
                                label="95 % interval")
            _strain_axis(ax)
            ax.set_ylabel(ylabel)
        axes[0].axvline(1.5, color="crimson", linestyle=":", linewidth=0.9, label="paper's peak (1.5 %)")
        axes[0].legend(frameon=False, fontsize=7)
        fig.suptitle(title, fontsize=9)
    return fig


def _fabric_figure(runs: Sequence[Measures], title: str) -> Figure:
    with plot.paper_style():
        fig = Figure(figsize=(10.0, 3.2), layout="constrained")
        axes = fig.subplots(1, 3)
        _band_plot(axes[0], runs, "a", "a (contact normals)", "C0", seeds=True)
        _band_plot(axes[0], runs, "a_n", "a_n (normal forces)", "C1")
        axes[0].plot([0.0, 0.5], [0.0034, 0.18], "x", color="crimson", label="paper")
        axes[0].set_ylabel("anisotropy")
        _band_plot(axes[1], runs, "coordination_number", "Z (grain-grain)", "C2", seeds=True)
        axes[1].plot([0.0, 1.5], [3.9, 3.0], "x", color="crimson", label="paper")
        axes[1].set_ylabel("coordination number")
        _band_plot(axes[2], runs, "mean_lambda", r"mean $\lambda$ (grains with $\geq$ 2 contacts)", "C3", seeds=True)
        _band_plot(axes[2], runs, "mean_lambda_all", r"mean $\lambda$ (every grain)", "C4", seeds=True)
        axes[2].axhspan(0.31, 0.34, color="crimson", alpha=0.08, label="paper: 0.31-0.34")
        axes[2].set_ylabel(r"mean $\lambda$")
        for ax in axes:
            _strain_axis(ax)
            _legend(ax)
        fig.suptitle(title + " (from the snapshots; line: mean over seeds, band: 95 % interval)", fontsize=9)
    return fig


def _band_figure(runs: Sequence[Measures], title: str) -> Figure:
    with plot.paper_style():
        fig = Figure(figsize=(10.0, 6.0), layout="constrained")
        axes = fig.subplots(2, 3).ravel()
        panels = (
            (axes[0], "mean_lambda", r"mean $\lambda$, grains with $\geq$ 2 contacts"),
            (axes[1], "mean_lambda_all", r"mean $\lambda$, every grain"),
            (axes[2], "coordination_number", "grain-grain contacts per grain"),
            (axes[3], "fraction_2_of_load_bearing", "share with 2 contacts (of those with $\\geq$ 2)"),
            (axes[4], "mean_abs_rotation_rad", "mean |rotation| since 0 % (rad)"),
        )
        for ax, name, ylabel in panels:
            _band_plot(ax, runs, f"inside_{name}", "inside the band", "crimson")
            _band_plot(ax, runs, f"outside_{name}", "outside", "C0")
            ax.set_ylabel(ylabel)
        for ax in axes[:2]:  # the paper's band and rest lambda
            ax.axhline(0.34, color="crimson", linestyle=":", linewidth=0.8)
            ax.axhline(0.31, color="C0", linestyle=":", linewidth=0.8)
        _band_plot(axes[5], runs, "auc_lambda", r"per-grain $\lambda$, band at this strain", "C3")
        _band_plot(axes[5], runs, "auc_lambda_field", r"$\lambda$ field (2 d), band at this strain", "C4")
        _band_plot(axes[5], runs, "auc_lambda_peak_band", r"per-grain $\lambda$, the peak's band", "C5")
        axes[5].axhline(0.5, color="0.4", linewidth=0.8, linestyle="--")
        axes[5].set_ylabel("ROC AUC for band membership")
        for ax in axes:
            _strain_axis(ax)
            _legend(ax)
        fig.suptitle(title + ": inside and outside the band the detector finds at each snapshot (dotted: the "
                     "paper's 0.34 / 0.31)", fontsize=9)
    return fig


def _peak_row(m: Measures) -> Mapping[str, Any]:
    row: Mapping[str, Any] = m["snapshots"][m["peak_snapshot"]]
    return row


def _known(name: str) -> Callable[[Mapping[str, Any]], float]:
    """A band measure of a snapshot row whose band grains are known (as the claims read them)."""
    def get(row: Mapping[str, Any]) -> float:
        value = row.get(name) if row.get("band_members_known") else None
        return math.nan if value is None else float(value)

    return get


def _strata_figure(runs: Sequence[Measures], title: str) -> Figure:
    """lambda inside and outside the band at the peak per contact-number stratum (means
    over seeds, 95 % intervals), and the AUCs of lambda, of the contact number and of both."""
    from grainlab.analysis.band_contacts import STRATA

    labels = [label for label, _, _ in STRATA]
    peaks = [_peak_row(m) for m in runs]
    strata: dict[str, dict[str, float]] = {}
    errors: dict[str, tuple[float, float]] = {}
    for label in labels:
        sides = []
        for side in ("inside", "outside"):
            v = np.array([_known(f"stratum_{label}_mean_{side}")(r) for r in peaks], dtype=np.float64)
            v = v[np.isfinite(v)]
            mean = float(v.mean()) if v.size else math.nan
            ci = t_interval(v) if v.size >= 2 else (mean, mean)
            strata.setdefault(label, {})[f"mean_{side}"] = mean
            sides.append(mean - ci[0])
        errors[label] = (sides[0], sides[1])
    with plot.paper_style():
        fig = Figure(figsize=(9.0, 3.4), layout="constrained")
        left, right = fig.subplots(1, 2)
        plot.band_strata(strata, ax=left, errors=errors)
        left.set_title("at the peak: band and rest at equal contact number", fontsize=8)
        scores = (("auc_lambda", r"$\lambda$ (every grain)"), ("auc_lambda_within_contacts", r"$\lambda$ within n"),
                  ("auc_contacts", "n alone"), ("auc_contacts_lambda", r"n and $\lambda$"))
        for k, (key, _) in enumerate(scores):
            v = np.array([_known(key)(r) for r in peaks], dtype=np.float64)
            v = v[np.isfinite(v)]
            right.plot(np.full(v.size, k) + np.linspace(-0.15, 0.15, v.size) if v.size else [], v, "o",
                       color="0.6", markersize=3)
            if v.size >= 2:
                lo, hi = t_interval(v)
                right.errorbar([k], [v.mean()], yerr=[[v.mean() - lo], [hi - v.mean()]], color="C3", marker="s",
                               capsize=3)
        right.axhline(0.5, color="0.4", linewidth=0.8, linestyle="--")
        right.set_xticks(range(len(scores)))
        right.set_xticklabels([label for _, label in scores])
        right.set_ylabel("ROC AUC for band membership (out of sample for the models)")
        right.set_title("what tells band grains from the rest (dots: seeds)", fontsize=8)
        fig.suptitle(title, fontsize=9)
    return fig


def band_readings_figure(run_dir: str | Path, title: str = "") -> Figure:
    """The band readings over one run's displacement map, at the snapshot nearest the
    stress-ratio peak and at the last one: grains coloured by their displacement since
    0 %, the displacement map's two-block split (accepted or not, with its share of the
    residual removed), and the bands accepted in the local strain and in lambda > 0.5."""
    from grainlab.postprocess.products import RunProducts
    from grainlab.reproduction.measures import macro_measures

    products = RunProducts(run_dir, per_body=True)  # a clump drawn as the disk of its area
    results = products.results

    by_name = {info.name: info for info in results.snapshots}
    infos = [by_name[name] for name in products.names_by_strain]
    peak = macro_measures(results.timeseries)["peak_axial_strain"]
    chosen = [min(infos[1:], key=lambda i: abs(snapshot_strain(i) - peak)), infos[-1]]
    with plot.paper_style():
        fig = Figure(figsize=(8.0, 7.0), layout="constrained")
        axes = fig.subplots(1, 2)
        for ax, info in zip(axes, chosen, strict=True):
            snap = products.snapshot(info.name)
            strain_band = products.band_search(info.name)
            grains = np.asarray(snap.is_sample)
            plot.particle_map(snap.positions[grains], snap.radii[grains], 1e3 * strain_band.displacement[grains],
                              ax=ax, cmap="Greys", label="displacement since 0 % (mm)")
            moved = products.displacement_zone(info.name)
            if moved is not None:
                for k, seg in enumerate(moved.zone.outline()):
                    verdict = "accepted" if moved.found else "not accepted"
                    ax.plot(seg[:, 0], seg[:, 1], color="C1", linewidth=1.4,
                            label=(f"two-block split ({verdict};\nremoves {moved.residual_reduction:.2f} "
                                   "of the residual)") if k == 0 else None)
            if strain_band.band is not None:
                plot.outline_shear_band(ax, strain_band.band, color="crimson", linestyle="--")
            field = products.lambda_band(info.name)
            if field.band is not None:
                for k, seg in enumerate(field.band.outline()):
                    ax.plot(seg[:, 0], seg[:, 1], color="C0", linestyle=":", linewidth=1.4,
                            label=r"$\lambda > 0.5$ zone (accepted)" if k == 0 else None)
            ax.set_title(f"{100 * snapshot_strain(info):.2f} % axial strain"
                         + ("" if strain_band.band is not None else "; no strain band accepted"), fontsize=8)
            ax.legend(frameon=True, framealpha=0.85, fontsize=6, loc="upper left")
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
        fig.suptitle(title or "readings of the band", fontsize=9)
    return fig


def _study_figure(studies: Sequence[Measures], title: str) -> Figure:
    with plot.paper_style():
        fig = Figure(figsize=(10.0, 3.2), layout="constrained")
        axes = fig.subplots(1, 3)
        for k, s in enumerate(studies):
            for kind, marker in (("irregular", "o"), ("hexagonal", "s")):
                rows = [r for r in s.get("rows", []) if r.get("kind") == kind]
                lam = np.array([np.nan if r["mean_stability_index"] is None else r["mean_stability_index"]
                                for r in rows], dtype=np.float64)
                for ax, key in zip(axes, ("coordination_number", "porosity", "anisotropy"), strict=True):
                    x = np.array([np.nan if r[key] is None else r[key] for r in rows], dtype=np.float64)
                    ax.plot(x, lam, marker, color=f"C{k % 10}", markersize=3.5,
                            fillstyle="full" if kind == "irregular" else "none",
                            label=f"seed {k + 1} {kind}" if ax is axes[0] else None)
        for ax, label in zip(axes, ("Z (Fig. 15)", "porosity (Fig. 16)", "anisotropy a (Fig. 17)"), strict=True):
            ax.set_xlabel(label)
            ax.set_ylabel(r"mean $\lambda$")
        axes[0].legend(frameon=False, fontsize=6, ncol=2)
        fig.suptitle(title + " (dots: irregular, squares: hexagonal; one colour per seed)", fontsize=9)
    return fig


def _rate_figure(family: Sequence[tuple[float, Sequence[Measures | None]]]) -> Figure:
    with plot.paper_style():
        fig = Figure(figsize=(5.0, 3.2), layout="constrained")
        ax = fig.add_subplot()
        for key, color, label in (("peak_stress_ratio", "C3", "peak"), ("residual_stress_ratio", "C0", "end window")):
            rates, means, lows, highs = [], [], [], []
            for rate, runs in family:
                v = np.array([m["macro"][key] for m in runs if m is not None], dtype=np.float64)
                v = v[np.isfinite(v)]
                if v.size == 0:
                    continue
                rates.append(rate * 6000.0)
                means.append(v.mean())
                ci = t_interval(v) if v.size >= 2 else (v.mean(), v.mean())
                lows.append(v.mean() - ci[0])
                highs.append(ci[1] - v.mean())
            ax.errorbar(rates, means, yerr=[lows, highs], color=color, marker="o", capsize=3, label=label)
        ax.set_xscale("log")
        ax.set_xlabel("axial strain rate (%/min)")
        ax.set_ylabel(r"$\sigma_1/\sigma_3$ (mean, 95 % interval)")
        ax.legend(frameon=False)
    return fig


def draw_figures(plan: ReproductionPlan, results: Mapping[tuple[str, str, str], Measures | None],
                 folder: str | Path, *, runs_root: str | Path | None = None) -> dict[str, Path]:
    """Draws every figure of the reproduction into ``folder``; returns name -> PNG path.
    ``runs_root`` (the reproduction folder): with a ``band:`` variant, the band readings
    over the first seed's displacement map (:func:`band_readings_figure`)."""

    out = Path(folder)
    drawn: dict[str, Path] = {}
    for v in plan.variants:
        kind = plan.reads(v)
        found = [results.get((v.name, str(s), kind)) for s in plan.seeds]
        runs = [m for m in found if m is not None]
        if not runs:
            continue
        stem = variant_folder(v.name)
        if kind == "study":
            drawn[f"study_{stem}"] = _save(_study_figure(runs, f"{v.name}: packing study"), out / f"study_{stem}.png")
            continue
        title = f"{v.name}, {len(runs)} seeds"
        for name, draw in (("macro", _macro_figure), ("fabric", _fabric_figure), ("band", _band_figure),
                           ("strata", _strata_figure)):
            drawn[f"{name}_{stem}"] = _save(draw(runs, title), out / f"{name}_{stem}.png")
    if runs_root is not None and any(v.name.startswith("band:") for v in plan.variants):
        first = plan.biaxial_folder(runs_root, plan.variant("paper"), plan.seeds[0])
        if (first / "run.h5").exists():
            drawn["bandreadings_paper"] = _save(
                band_readings_figure(first, f"paper, seed {plan.seeds[0]}: the readings of the band"),
                out / "band_readings.png")
    family = rate_family(plan)
    if len(family) >= 2:
        runs_by_rate = [(rate, [results.get((v.name, str(s), "biaxial")) for s in plan.seeds]) for rate, v in family]
        drawn["rates"] = _save(_rate_figure(runs_by_rate), out / "rates.png")
    return drawn
