"""The biaxial run's micro-scale figures drawn from plain data (the paper's Figs. 6, 7, 9, 11-14).

Each function takes panels (positions, values, titles, band outlines) that
:mod:`grainlab.postprocess.figures` assembles from a run, and returns a
matplotlib ``Figure`` drawn without pyplot. Maps are drawn in millimetres
(a sample is a few centimetres across); the disks of each panel are one
collection, rasterised in vector files (:func:`grainlab.plot.particle_map`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import EngFormatter, MaxNLocator
from numpy.typing import NDArray

from grainlab import plot

__all__ = [
    "COUNT_CAP",
    "MM",
    "BandOutline",
    "MapPanel",
    "PolarPanel",
    "anisotropy_figure",
    "displacement_figure",
    "mean_lambda_figure",
    "polar_figure",
    "series_figure",
    "shared_map_figure",
]

#: Maps are drawn in millimetres.
MM = 1.0e3
#: Contact counts at or above this share the top colour of Fig. 13.
COUNT_CAP = 6


@dataclass(frozen=True)
class BandOutline:
    """The edges of one band on a map: segments (each (2, 2), m), line style and legend label."""

    segments: Sequence[NDArray[np.float64]]
    linestyle: str
    label: str


@dataclass(frozen=True)
class MapPanel:
    """One particle map: disks (m) coloured by ``values``, a title and the bands to outline.

    ``note`` is added under the title (the band's inclination and thickness,
    or "no shear band found").
    """

    positions: NDArray[np.float64]
    radii: NDArray[np.float64]
    values: NDArray[np.float64]
    title: str
    note: str = ""
    outlines: tuple[BandOutline, ...] = field(default_factory=tuple)


@dataclass(frozen=True)
class PolarPanel:
    """One rose diagram: ``fabric`` has ``plot(ax=, title=)`` (a computed
    :class:`~grainlab.analysis.ContactAnisotropy`), or is None when the
    snapshot has no forces."""

    title: str
    fabric: Any


def _new_figure(figsize: tuple[float, float]) -> Figure:
    with plot.paper_style():
        return Figure(figsize=figsize, layout="constrained")


def polar_figure(panels: Sequence[PolarPanel], forces: bool) -> Figure:
    """Figs. 6 (``forces=False``: contacts per bin, one radial scale) and 7 (summed normal force per bin)."""
    fig = _new_figure((3.3 * len(panels), 3.6))
    axes = []
    with plot.paper_style():
        for k, panel in enumerate(panels):
            ax = fig.add_subplot(1, len(panels), k + 1, projection="polar")
            if panel.fabric is None:
                ax.set_title(panel.title + "\nno contact forces recorded")
                ax.set_yticks([])
            else:
                panel.fabric.plot(ax=ax, title=panel.title)
            axes.append(ax)
        if not forces:
            # contact counts compare directly: one radial scale for both states
            top = max(ax.get_ylim()[1] for ax in axes)
            for ax in axes:
                ax.set_ylim(0.0, top)
        for ax in axes:
            ax.yaxis.set_major_locator(MaxNLocator(4, integer=not forces))
            if forces:
                ax.yaxis.set_major_formatter(EngFormatter(unit="N", places=0))
        fig.suptitle(
            "Normal contact force distribution (summed normal force per bin)"
            if forces
            else "Contact normal distribution (contacts per bin)"
        )
    return fig


def _annotate(ax: Any, panel: MapPanel) -> None:
    if panel.note:
        ax.set_title(ax.get_title() + "\n" + panel.note)
    for outline in panel.outlines:
        for k, seg in enumerate(outline.segments):
            ax.plot(
                MM * seg[:, 0],
                MM * seg[:, 1],
                color="crimson",
                linestyle=outline.linestyle,
                linewidth=1.0,
                label=outline.label if k == 0 else None,
            )


def _map_size(positions: NDArray[np.float64], n: int, colorbars: int) -> tuple[float, float]:
    pos = positions
    aspect = float(np.ptp(pos[:, 1]) / max(np.ptp(pos[:, 0]), 1e-300)) if len(pos) else 1.0
    panel_w = 2.2 if n > 1 else 2.8
    width = n * panel_w + 0.8 * colorbars + 0.4
    height = float(np.clip(panel_w * aspect, 1.8, 6.0)) + 1.1
    return (min(width, 10.0), height)


def _draw_map(ax: Any, k: int, panel: MapPanel, values: NDArray[np.float64], **kwargs: Any) -> None:
    plot.particle_map(MM * panel.positions, MM * panel.radii, values, ax=ax, **kwargs)
    ax.set_title(panel.title)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)" if k == 0 else "")


def displacement_figure(panels: Sequence[MapPanel], initial_name: str) -> Figure:
    """Fig. 11: displacement magnitude (``values`` in m) since the initial state, each panel on its own scale."""
    fig = _new_figure(_map_size(panels[0].positions, len(panels), len(panels)))
    with plot.paper_style():
        for k, panel in enumerate(panels):
            ax = fig.add_subplot(1, len(panels), k + 1)
            # each state on its own scale: displacements grow by an order of magnitude
            _draw_map(ax, k, panel, MM * panel.values, vmin=0.0, label="displacement magnitude (mm)")
            _annotate(ax, panel)
        fig.suptitle(f"Particle displacements since the initial state ({initial_name})")
    return fig


def shared_map_figure(
    panels: Sequence[MapPanel],
    *,
    label: str,
    suptitle: str,
    discrete: bool = False,
    vmin: float | None = None,
    vmax: float | None = None,
    cmap: str = "viridis",
) -> Figure:
    """Figs. 12 and 13: the panels side by side on one colour scale with one colour bar.

    The scale runs from ``vmin`` / ``vmax`` (default the finite values' range);
    ``discrete`` gives one colour per integer and labels the top one
    "≥ :data:`COUNT_CAP`" when it reaches the cap.
    """
    vals = [np.asarray(p.values, dtype=np.float64) for p in panels]
    finite = np.concatenate([v[np.isfinite(v)] for v in vals])
    lo = vmin if vmin is not None else (float(finite.min()) if finite.size else 0.0)
    hi = vmax if vmax is not None else (float(finite.max()) if finite.size else 1.0)
    fig = _new_figure(_map_size(panels[0].positions, len(panels), 1))
    with plot.paper_style():
        axes = [fig.add_subplot(1, len(panels), k + 1) for k in range(len(panels))]
        for k, (ax, panel, v) in enumerate(zip(axes, panels, vals, strict=True)):
            _draw_map(ax, k, panel, v, cmap=cmap, vmin=lo, vmax=hi, discrete=discrete, colorbar=False)
            _annotate(ax, panel)
        cb = fig.colorbar(axes[0].collections[0], ax=axes, shrink=0.8, label=label)
        if discrete:
            ticks = list(range(round(lo), round(hi) + 1))
            cb.set_ticks(ticks)
            names = [str(t) for t in ticks]
            if hi >= COUNT_CAP:
                names[-1] = f"≥ {ticks[-1]}"
            cb.set_ticklabels(names)
            cb.minorticks_off()
        fig.suptitle(suptitle)
    return fig


def series_figure(
    axial_strain: NDArray[np.float64],
    draw: Callable[[Any], Any],
    peak_axial_strain: float,
) -> Figure:
    """Figs. 9 and 14: ``draw(ax)`` plots the series against ``axial_strain``
    (a fraction); the peak of the stress ratio is marked with a dotted line."""
    eps = np.asarray(axial_strain, dtype=np.float64)
    fig = _new_figure((4.2, 3.0))
    with plot.paper_style():
        ax = fig.add_subplot()
        draw(ax)
        if len(eps) > 60:  # markers only clutter a long record
            for line in ax.get_lines():
                line.set_marker("")
        ax.axvline(
            100 * peak_axial_strain,
            color="0.5",
            linestyle=":",
            linewidth=0.9,
            label=rf"peak $\sigma_1/\sigma_3$ ({100 * peak_axial_strain:.2f} %)",
        )
        ax.legend(frameon=False)
        ax.set_xlim(left=min(0.0, 100 * float(np.nanmin(eps))))
    return fig


def anisotropy_figure(
    axial_strain: NDArray[np.float64],
    anisotropy: NDArray[np.float64],
    force_anisotropy: NDArray[np.float64],
    peak_axial_strain: float,
) -> Figure:
    """Fig. 9: a and a_n against axial strain (:func:`grainlab.plot.anisotropy_series`), the peak marked."""

    def draw(ax: Any) -> Any:
        return plot.anisotropy_series(axial_strain, anisotropy, normal_force=force_anisotropy, ax=ax)

    return series_figure(axial_strain, draw, peak_axial_strain)


def mean_lambda_figure(
    axial_strain: NDArray[np.float64],
    mean_lambda: NDArray[np.float64],
    mean_lambda_all: NDArray[np.float64] | None,
    peak_axial_strain: float,
) -> Figure:
    """Fig. 14: mean lambda (and over every grain, when given) against axial strain
    (:func:`grainlab.plot.mean_lambda_series`), the peak marked."""

    def draw(ax: Any) -> Any:
        return plot.mean_lambda_series(axial_strain, mean_lambda, mean_lambda_all=mean_lambda_all, ax=ax)

    return series_figure(axial_strain, draw, peak_axial_strain)
