"""Drawings of a packing's networks and cells: contacts as lines (force
networks, force chains, loops) and power cells coloured by a value.

As in :mod:`grainlab.plot`, each function draws on a given ``Axes`` (``None``:
a new figure in the paper style) and returns it.
"""

from __future__ import annotations

from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.collections import EllipseCollection, LineCollection, PolyCollection
from matplotlib.colors import Normalize
from numpy.typing import ArrayLike

from grainlab._notebook import new_figure, prepare_notebook
from grainlab.plot import new_axes
from grainlab.plot.files import paper_style

__all__ = ["cell_map", "contact_network", "grouped_means"]


def _frame(ax: Any, points: np.ndarray) -> None:
    if points.size:
        lo, hi = points.min(axis=0), points.max(axis=0)
        pad = 0.02 * float(np.max(hi - lo) + 1e-300)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def contact_network(
    start: ArrayLike,
    end: ArrayLike,
    width: ArrayLike,
    *,
    color: ArrayLike | str = "0.2",
    positions: ArrayLike | None = None,
    radii: ArrayLike | None = None,
    ax: Any = None,
    title: str | None = None,
    legend: list[tuple[str, Any]] | None = None,
) -> Any:
    """Segments from ``start`` (K, 2) to ``end`` (K, 2), m, with line widths
    ``width`` (K,) in points and ``color`` (one colour or (K,) colours), over
    the disks (``positions``, ``radii``) drawn as light outlines.
    ``legend``: (label, colour) pairs."""
    a = np.asarray(start, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(end, dtype=np.float64).reshape(-1, 2)
    ax = new_axes(ax, figsize=(3.5, 3.5))
    with paper_style():
        shown = [a, b]
        if positions is not None and radii is not None:
            x = np.asarray(positions, dtype=np.float64)
            d = 2.0 * np.asarray(radii, dtype=np.float64)
            ax.add_collection(
                EllipseCollection(
                    d, d, np.zeros_like(d), units="xy", offsets=x,
                    offset_transform=ax.transData, facecolors="none",
                    edgecolors="0.8", linewidths=0.3,
                )
            )
            shown.append(x)
        lines = LineCollection(
            list(np.stack([a, b], axis=1)), linewidths=np.asarray(width, dtype=np.float64),
            colors=color, capstyle="round",
        )
        ax.add_collection(lines)
        _frame(ax, np.concatenate(shown))
        if legend:
            from matplotlib.lines import Line2D

            handles = [Line2D([], [], color=c, lw=1.5, label=text) for text, c in legend]
            ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.15),
                      frameon=False, ncol=len(handles))
        if title:
            ax.set_title(title)
    return ax


def cell_map(
    vertices: ArrayLike,
    offsets: ArrayLike,
    values: ArrayLike,
    positions: ArrayLike,
    radii: ArrayLike,
    *,
    ax: Any = None,
    cmap: str = "viridis",
    label: str | None = None,
) -> Any:
    """Cells (polygon p: ``vertices[offsets[p]:offsets[p + 1]]``, m) coloured by
    ``values`` (N,) (NaN in light grey), the disks outlined on top."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 2)
    off = np.asarray(offsets, dtype=np.int64)
    val = np.asarray(values, dtype=np.float64)
    polygons = [v[off[p] : off[p + 1]] for p in range(off.size - 1) if off[p + 1] > off[p]]
    shown = val[[p for p in range(off.size - 1) if off[p + 1] > off[p]]]
    ax = new_axes(ax, figsize=(3.5, 3.5))
    with paper_style():
        finite = np.isfinite(shown)
        low = float(shown[finite].min()) if finite.any() else 0.0
        high = float(shown[finite].max()) if finite.any() else 1.0
        norm = Normalize(low, high if high > low else low + 1.0)
        colormap = mpl.colormaps[cmap]
        colours = np.where(
            finite[:, None], colormap(norm(np.where(finite, shown, low))), mpl.colors.to_rgba("0.85")
        )
        ax.add_collection(
            PolyCollection(polygons, facecolors=colours, edgecolors="0.4", linewidths=0.2)
        )
        x = np.asarray(positions, dtype=np.float64)
        d = 2.0 * np.asarray(radii, dtype=np.float64)
        ax.add_collection(
            EllipseCollection(
                d, d, np.zeros_like(d), units="xy", offsets=x, offset_transform=ax.transData,
                facecolors="none", edgecolors="k", linewidths=0.3,
            )
        )
        _frame(ax, v)
        mappable = mpl.cm.ScalarMappable(norm=norm, cmap=colormap)
        ax.figure.colorbar(mappable, ax=ax, label=label or "")
    return ax


def grouped_means(
    panels: list[tuple[str, list[str], ArrayLike, ArrayLike, ArrayLike]],
    *,
    ylabel: str,
    reference: float | None = None,
) -> Any:
    """One panel per ``(title, labels, means, standard_errors, counts)``: the mean of
    a quantity in each group with its standard error, the group's count under
    its label, and a dashed line at ``reference`` (the overall mean); returns the
    figure."""
    prepare_notebook()
    with paper_style():
        fig = new_figure(figsize=(2.4 * len(panels), 2.8), layout="constrained")
        axes = fig.subplots(1, len(panels), sharey=True, squeeze=False)[0]
        for ax, (title, labels, means, errors, counts) in zip(axes, panels, strict=True):
            m = np.asarray(means, dtype=np.float64)
            e = np.asarray(errors, dtype=np.float64)
            x = np.arange(m.size)
            ax.errorbar(x, m, yerr=e, fmt="o", color="k", ms=4, capsize=2, lw=0.8)
            n = np.asarray(counts, dtype=np.int64)
            ax.set_xticks(x, [f"{t}\n({int(c)})" for t, c in zip(labels, n, strict=True)], fontsize=6)
            ax.set_xlim(-0.5, m.size - 0.5)
            if reference is not None:
                ax.axhline(reference, color="0.5", lw=0.6, ls="--")
            ax.set_title(title, fontsize=8)
        axes[0].set_ylabel(ylabel)
    return fig
