"""Figures for papers: polar fabric diagrams, particle maps, time series.

Every function draws on a given ``Axes`` (``ax=None``: a new figure in the paper
style, without pyplot) and returns it; :func:`save_figure` writes compact PNG and
SVG files. The paper's figures each function draws: docs/analysis.md, "Figures (`grainlab.plot`)".
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib as mpl
import numpy as np
from matplotlib.collections import EllipseCollection
from matplotlib.colors import BoundaryNorm, Normalize
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from grainlab._notebook import new_figure, prepare_notebook
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO, VOLUMETRIC_STRAIN
from grainlab.plot.files import (
    FIGURE_DPI,
    PAGE_DPI,
    PAPER_STYLE,
    compact_png,
    page_png,
    paper_style,
    save_figure,
    scale_colors,
)

if TYPE_CHECKING:
    from grainlab.plot.workers import FigureTask

__all__ = [
    "FIGURE_DPI",
    "PAGE_DPI",
    "PAPER_STYLE",
    "anisotropy_series",
    "band_strata",
    "compact_png",
    "contact_count_distribution",
    "mean_lambda_series",
    "new_axes",
    "outline_shear_band",
    "page_png",
    "paper_style",
    "particle_map",
    "polar_distribution",
    "save_figure",
    "scale_colors",
    "stress_path_figure",
]


def new_axes(
    ax: Any = None, *, polar: bool = False, figsize: tuple[float, float] = (3.5, 3.0)
) -> Any:
    """``ax`` itself, or new axes on a new paper-style figure (no pyplot, except in a
    Jupyter notebook, where the figure is made through pyplot so that it is shown:
    :func:`grainlab._notebook.new_figure`)."""
    if ax is not None:
        return ax
    prepare_notebook()
    with paper_style():
        fig = new_figure(figsize=figsize, layout="constrained")
        return fig.add_subplot(projection="polar" if polar else None)


def polar_distribution(
    values: ArrayLike,
    *,
    anisotropy: float | None = None,
    direction: float | None = None,
    ax: Any = None,
    kind: str = "contacts",
    title: str | None = None,
) -> Any:
    """Rose diagram of a binned contact-normal or normal-force distribution (Figs. 6–7).

    ``values`` (ng,) are the bin contents over [0, 2 pi) (bin g starting at
    ``g * 2pi/ng``). With ``anisotropy`` a and ``direction`` theta_a (rad) the
    fitted Eq. 6 is drawn on the same scale as the bins:
    ``mean(values) * (1 + a cos 2(theta - theta_a))``.
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    ng = v.size
    ax = new_axes(ax, polar=True)
    width = 2 * np.pi / ng
    with paper_style():
        ax.bar(
            np.arange(ng) * width,
            v,
            width=width,
            align="edge",
            facecolor="0.85",
            edgecolor="0.25",
            linewidth=0.6,
            label="contacts per bin" if kind == "contacts" else "normal force per bin (N)",
        )
        if anisotropy is not None and direction is not None and np.isfinite(anisotropy):
            th = np.linspace(0.0, 2 * np.pi, 361)
            fit = v.mean() * (1.0 + anisotropy * np.cos(2.0 * (th - direction)))
            name = "E" if kind == "contacts" else r"F_n"
            sym = "a" if kind == "contacts" else "a_n"
            ax.plot(
                th,
                fit,
                color="C3",
                label=rf"${name}(\theta)$, ${sym}$ = {anisotropy:.3f}, "
                rf"$\theta_a$ = {np.degrees(direction):.1f}°",
            )
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), frameon=False)
        ax.set_theta_zero_location("E")
        ax.set_theta_direction(1)
        ax.set_thetagrids(np.arange(0, 360, 45))
        ax.tick_params(axis="y", labelsize=7)
        if title is None:
            title = (
                "Contact normal distribution"
                if kind == "contacts"
                else "Normal contact force distribution"
            )
        ax.set_title(title)
    return ax


def particle_map(
    positions: ArrayLike,
    radii: ArrayLike,
    values: ArrayLike,
    *,
    ax: Any = None,
    cmap: str = "viridis",
    label: str | None = None,
    vmin: float | None = None,
    vmax: float | None = None,
    discrete: bool = False,
    nan_color: str = "0.85",
    colorbar: bool = True,
    band: Any = None,
) -> Any:
    """Disks drawn to scale (one ``EllipseCollection``) coloured by ``values``.

    ``discrete=True`` uses one colour per integer value (contact counts,
    Fig. 13). NaN values are drawn in ``nan_color``. ``band`` (a computed
    :class:`~grainlab.analysis.shear_band.ShearBand`) is outlined on top.
    """
    pos = np.asarray(positions, dtype=np.float64)
    rad = np.asarray(radii, dtype=np.float64)
    val = np.asarray(values, dtype=np.float64)
    height = float(np.ptp(pos[:, 1])) if pos.size else 1.0
    span = float(np.ptp(pos[:, 0])) if pos.size else 1.0
    aspect = (height + 1e-300) / (span + 1e-300)
    ax = new_axes(ax, figsize=(3.5, float(np.clip(3.0 * aspect, 2.0, 7.0))))
    with paper_style():
        finite = np.isfinite(val)
        ticks: list[int] = []  # one per colour of a discrete map
        if discrete:
            lo = int(np.nanmin(val[finite])) if finite.any() else 0
            hi = int(np.nanmax(val[finite])) if finite.any() else 1
            lo = int(vmin) if vmin is not None else lo
            hi = max(int(vmax) if vmax is not None else hi, lo + 1)
            colormap = mpl.colormaps[cmap].resampled(hi - lo + 1)
            norm: Normalize = BoundaryNorm(np.arange(lo - 0.5, hi + 1.0), colormap.N)
            ticks = list(range(lo, hi + 1))
        else:
            colormap = mpl.colormaps[cmap]
            low = vmin if vmin is not None else (float(np.min(val[finite])) if finite.any() else 0.0)
            high = vmax if vmax is not None else (float(np.max(val[finite])) if finite.any() else 1.0)
            if high <= low:
                high = low + 1.0
            norm = Normalize(low, high)
        colormap = colormap.with_extremes(bad=nan_color)
        coll = EllipseCollection(
            widths=2 * rad,
            heights=2 * rad,
            angles=np.zeros_like(rad),
            units="xy",
            offsets=pos,
            offset_transform=ax.transData,
            cmap=colormap,
            norm=norm,
            edgecolors="none",
            rasterized=True,
        )
        coll.set_array(np.ma.masked_invalid(val))
        ax.add_collection(coll)
        if pos.size:
            pad = float(rad.max())
            ax.set_xlim(pos[:, 0].min() - pad, pos[:, 0].max() + pad)
            ax.set_ylim(pos[:, 1].min() - pad, pos[:, 1].max() + pad)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        if colorbar:
            cb = ax.figure.colorbar(coll, ax=ax, shrink=0.8)
            if discrete:
                cb.set_ticks(ticks)
            if label:
                cb.set_label(label)
        if band is not None:
            outline_shear_band(ax, band)
    return ax


def outline_shear_band(ax: Any, band: Any, **line_style: Any) -> Any:
    """Draw the two edges of a computed ShearBand on ``ax``; returns the axes."""
    style = {"color": "crimson", "linestyle": "--", "linewidth": 1.0}
    style.update(line_style)
    for k, seg in enumerate(band.outline()):
        ax.plot(seg[:, 0], seg[:, 1], label="shear band" if k == 0 else None, **style)
    return ax


def contact_count_distribution(fractions: ArrayLike, *, ax: Any = None) -> Any:
    """Bar chart of the fraction of particles with 0, 1, 2, ... contacts."""
    f = np.asarray(fractions, dtype=np.float64).reshape(-1)
    ax = new_axes(ax)
    with paper_style():
        ax.bar(np.arange(f.size), f, color="0.6", edgecolor="0.2", linewidth=0.6)
        ax.set_xlabel("number of contacts")
        ax.set_ylabel("fraction of particles")
        ax.set_xticks(np.arange(f.size))
    return ax


def band_strata(strata: Mapping[str, Mapping[str, float]], *, ax: Any = None,
                errors: Mapping[str, tuple[float, float]] | None = None) -> Any:
    """Mean lambda of the band's grains and of the rest, side by side for each
    contact-number stratum (``strata``: label -> ``mean_inside``, ``mean_outside``,
    ``n_inside``, ``n_outside``, as :class:`~grainlab.analysis.BandContacts` gives);
    ``errors``: optional (inside, outside) half-widths per label."""
    labels = list(strata)
    x = np.arange(len(labels), dtype=np.float64)
    ax = new_axes(ax)
    with paper_style():
        for shift, side, colour, name in ((-0.2, "inside", "C3", "band"), (0.2, "outside", "0.6", "rest")):
            values = [float(strata[k][f"mean_{side}"]) for k in labels]
            err = None if errors is None else [errors[k][0 if side == "inside" else 1] for k in labels]
            ax.bar(x + shift, values, width=0.4, color=colour, edgecolor="0.2", linewidth=0.6, label=name,
                   yerr=err, capsize=2 if err is not None else 0)
        ax.set_xticks(x)
        ax.set_xticklabels([f"n = {k}" for k in labels])
        ax.set_xlabel("contacts of the grain (as lambda counts them)")
        ax.set_ylabel(r"mean $\lambda$")
        ax.legend(frameon=False)
    return ax


def _strain_axis(ax: Any) -> None:
    ax.set_xlabel(r"axial strain $\varepsilon_{11}$ (%, compression positive)")


def _along(
    eps: NDArray[np.float64], values: ArrayLike, name: str, scale: float = 1.0
) -> NDArray[np.float64]:
    """``values`` (times ``scale``) as floats of the strain axis' shape; a ValueError
    naming ``name`` otherwise."""
    y = np.asarray(values, dtype=np.float64) * scale
    if y.shape != eps.shape:
        raise ValueError(f"{name}: expected shape {eps.shape}, got {y.shape}")
    return y


def anisotropy_series(
    axial_strain: ArrayLike,
    anisotropy: ArrayLike,
    *,
    normal_force: ArrayLike | None = None,
    ax: Any = None,
) -> Any:
    """Fabric anisotropy a (and a_n) against axial strain (Fig. 9).

    ``axial_strain`` is a fraction (0.01 = 1 %), compression positive.
    """
    eps = 100.0 * np.asarray(axial_strain, dtype=np.float64)
    a = _along(eps, anisotropy, "anisotropy")
    an = None if normal_force is None else _along(eps, normal_force, "normal_force")
    ax = new_axes(ax)
    with paper_style():
        ax.plot(eps, a, marker="o", markersize=2.5, label="$a$ (contact normals)")
        if an is not None:
            ax.plot(eps, an, marker="s", markersize=2.5, label="$a_n$ (normal forces)")
            ax.legend(frameon=False)
        _strain_axis(ax)
        ax.set_ylabel("fabric anisotropy")
    return ax


def mean_lambda_series(
    axial_strain: ArrayLike,
    mean_lambda: ArrayLike,
    *,
    mean_lambda_all: ArrayLike | None = None,
    ax: Any = None,
) -> Any:
    """Mean geometrical stability index against axial strain (Fig. 14):
    ``mean_lambda`` over grains with >= 2 contacts and, when given,
    ``mean_lambda_all`` over every grain (0- and 1-contact grains at 1), dashed."""
    eps = 100.0 * np.asarray(axial_strain, dtype=np.float64)
    lam = _along(eps, mean_lambda, "mean_lambda")
    lam_all = None if mean_lambda_all is None else _along(eps, mean_lambda_all, "mean_lambda_all")
    ax = new_axes(ax)
    with paper_style():
        ax.plot(eps, lam, marker="o", markersize=2.5, color="C2", label=r"grains with $\geq 2$ contacts")
        if lam_all is not None:
            ax.plot(eps, lam_all, ls="--", color="C4", label=r"all grains (0-1 contact: $\lambda = 1$)")
            ax.legend(frameon=False, fontsize="small")
        _strain_axis(ax)
        ax.set_ylabel(r"mean stability index $\bar\lambda$")
    return ax


def strain_series(
    axial_strain: ArrayLike,
    values: ArrayLike,
    ylabel: str,
    *,
    percent: bool = False,
    reference: float | None = None,
    ax: Any = None,
) -> Any:
    """One quantity against axial strain (the paper's Figs. 8, 10, 18).

    ``axial_strain`` is a fraction, compression positive; ``percent`` shows
    ``values`` (a fraction) in %; ``reference`` draws a horizontal line.
    """
    eps = 100.0 * np.asarray(axial_strain, dtype=np.float64)
    y = _along(eps, values, "values", 100.0 if percent else 1.0)
    ax = new_axes(ax)
    with paper_style():
        ax.plot(eps, y, color="C0")
        if reference is not None:
            ax.axhline(reference, color="0.6", linewidth=0.8, linestyle="--")
        _strain_axis(ax)
        ax.set_ylabel(ylabel)
    return ax


def _strain_figure(
    axial_strain: ArrayLike, values: ArrayLike, ylabel: str, percent: bool, reference: float | None
) -> Figure:
    """One of :func:`biaxial_curves`' figures: :func:`strain_series` on a new paper-style figure."""
    with paper_style():
        fig = Figure(figsize=(3.5, 3.0), layout="constrained")
        ax = fig.add_subplot()
    strain_series(axial_strain, values, ylabel, percent=percent, reference=reference, ax=ax)
    return fig


def stress_path_figure(axial_strain: ArrayLike, axial_stress_pa: ArrayLike, lateral_stress_pa: ArrayLike,
                       cell_pressure_pa: float) -> Figure:
    """A constant-volume biaxial run's stress path: q = (sigma_1' - sigma_3') / 2 against
    p' = (sigma_1' + sigma_3') / 2 (kPa), and the pore-pressure analogue u = sigma_0 -
    sigma_3' against the axial strain (%): the drop of the effective lateral stress
    below the cell pressure it would take to hold the volume with water."""
    s1 = np.asarray(axial_stress_pa, dtype=np.float64) / 1e3
    s3 = np.asarray(lateral_stress_pa, dtype=np.float64) / 1e3
    with paper_style():
        fig = Figure(figsize=(7.0, 3.0), layout="constrained")
        left, right = fig.subplots(1, 2)
        left.plot(0.5 * (s1 + s3), 0.5 * (s1 - s3), color="k", linewidth=1.0)
        left.set_xlabel(r"$p' = (\sigma_1' + \sigma_3')/2$ (kPa)")
        left.set_ylabel(r"$q = (\sigma_1' - \sigma_3')/2$ (kPa)")
        left.set_xlim(left=0.0)
        left.set_ylim(bottom=min(0.0, float(np.nanmin(0.5 * (s1 - s3)))))
        right.plot(100 * np.asarray(axial_strain, dtype=np.float64), cell_pressure_pa / 1e3 - s3, color="k",
                   linewidth=1.0)
        right.axhline(0.0, color="0.6", linewidth=0.6)
        right.set_xlabel("axial strain (%)")
        right.set_ylabel(r"$u = \sigma_0 - \sigma_3'$ (kPa)")
    return fig


def curve_tasks(timeseries: dict[str, Any], *, stress_path: bool = False) -> list[FigureTask]:
    """The figures of :func:`biaxial_curves` as tasks for a :class:`~grainlab.plot.workers.FigurePool`;
    with ``stress_path`` (a constant-volume run) also ``fig19_stress_path``
    (:func:`stress_path_figure`)."""
    from grainlab.plot.workers import FigureTask

    eps = np.asarray(timeseries[AXIAL_STRAIN], dtype=np.float64)
    figures = (
        ("fig08_stress_ratio", STRESS_RATIO, r"stress ratio $\sigma_1/\sigma_3$", False, 1.0),
        (
            "fig10_volumetric_strain",
            VOLUMETRIC_STRAIN,
            r"volumetric strain $\varepsilon_v$ (%, compression positive)",
            True,
            0.0,
        ),
        ("fig18_coordination_number", "coordination_number", "coordination number $Z$", False, None),
    )
    tasks = [
        FigureTask(name, _strain_figure, (eps, np.asarray(timeseries[column], dtype=np.float64), label, percent, ref))
        for name, column, label, percent, ref in figures
    ]
    if stress_path:
        cell = float(np.asarray(timeseries["confining_pressure_pa"], dtype=np.float64)[0])
        tasks.append(FigureTask("fig19_stress_path", stress_path_figure,
                                (eps, np.asarray(timeseries["axial_stress_pa"], dtype=np.float64),
                                 np.asarray(timeseries["confining_stress_felt_pa"], dtype=np.float64), cell)))
    return tasks


def biaxial_curves(timeseries: dict[str, Any], out_dir: str | Path, *, workers: int | None = None,
                   stress_path: bool = False) -> list[Path]:
    """The macro curves of a biaxial test, PNG and SVG, into ``out_dir``:
    ``stress_ratio`` (Fig. 8), ``volumetric_strain`` (Fig. 10) and
    ``coordination_number`` (Fig. 18) against axial strain (and, with
    ``stress_path``, the constant-volume run's ``fig19_stress_path``), drawn side
    by side in up to ``workers`` processes (0: here), or in the pool of an
    enclosing ``with FigurePool()`` block (:mod:`grainlab.plot.workers`)."""
    from grainlab.plot.workers import figure_pool

    tasks = curve_tasks(timeseries, stress_path=stress_path)
    with figure_pool(workers, tasks=len(tasks)) as pool:
        files = pool.draw(tasks, out_dir).result()
    return [path for paths in files.values() for path in paths]
