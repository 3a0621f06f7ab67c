"""The crack map and the rose of crack orientations of a cemented sample
(docs/cemented.md, "Crack records"): :func:`crack_figure`."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from numpy.typing import NDArray

from grainlab import plot
from grainlab.cement import crack_orientations

__all__ = ["ROSE_BINS", "crack_figure"]

#: Bins of the rose over [0, 180) degrees.
ROSE_BINS = 18
_MM = 1e3
_MODES = (("tension", 1, "tab:blue"), ("shear", 0, "tab:red"))


def crack_figure(positions: NDArray[np.float64], radii: NDArray[np.float64],
                 cracks: Mapping[str, NDArray[np.generic]], title: str) -> Figure:
    """Left, the grains at ``positions`` (m; the run's last snapshot) in grey and each
    crack as a segment across its bond's centre, along its orientation, one grain radius
    long, blue in tension and red in shear; right, the rose of the crack orientations,
    the two modes stacked (each bin drawn on both halves)."""
    x, y = np.asarray(cracks["x_m"], np.float64), np.asarray(cracks["y_m"], np.float64)
    angle = crack_orientations(np.asarray(cracks["normal_x"], np.float64), np.asarray(cracks["normal_y"], np.float64))
    tension = np.asarray(cracks["tension"]) == 1
    half = 0.5 * float(np.median(radii))
    with plot.paper_style():
        fig = Figure(figsize=(8.0, 5.0), layout="constrained")
        ax = fig.add_subplot(1, 2, 1)
        plot.particle_map(_MM * positions, _MM * radii, np.full(len(radii), np.nan), ax=ax, colorbar=False,
                          nan_color="0.88")
        d = half * np.column_stack([np.cos(angle), np.sin(angle)])
        centre = np.column_stack([x, y])
        for name, flag, colour in _MODES:
            keep = tension == bool(flag)
            segments = _MM * np.stack([centre[keep] - d[keep], centre[keep] + d[keep]], axis=1)
            ax.add_collection(LineCollection(list(segments), colors=colour, linewidths=1.4,
                                             label=f"{name} ({int(keep.sum())})"))
        ax.legend(loc="upper right", fontsize="small", framealpha=0.85)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_title(f"{len(x)} cracks")
        rose = fig.add_subplot(1, 2, 2, projection="polar")
        edges = np.linspace(0.0, np.pi, ROSE_BINS + 1)
        width = np.pi / ROSE_BINS
        bottom = np.zeros(ROSE_BINS)
        for name, flag, colour in _MODES:
            counts, _ = np.histogram(angle[tension == bool(flag)], bins=edges)
            for offset in (0.0, np.pi):
                rose.bar(edges[:-1] + offset, counts, width=width, bottom=bottom, align="edge", color=colour,
                         edgecolor="white", linewidth=0.5, label=name if offset == 0.0 else None)
            bottom = bottom + counts
        rose.set_title("crack orientations (cracks per bin)")
        rose.yaxis.set_major_locator(MaxNLocator(4, integer=True))
        fig.suptitle(title)
    return fig
