"""The cyclic biaxial test's figures, from plain data (a time series as column ->
array, the summary's cycle table): the stress-strain and volumetric loops, and the
fabric (Z, mean lambda, anisotropy) at the end of each cycle."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from grainlab.columns import (
    AXIAL_STRAIN,
    COORDINATION_NUMBER,
    CYCLE,
    STRESS_RATIO,
    VOLUMETRIC_STRAIN,
)
from grainlab.plot.files import paper_style

__all__ = ["fabric_figure", "loops_figure"]


def loops_figure(timeseries: Mapping[str, ArrayLike]) -> Figure:
    """sigma1/sigma3 and the volumetric strain against the axial strain (%), each cycle
    in its own shade, from light (first) to dark (last)."""
    eps = 100 * np.asarray(timeseries[AXIAL_STRAIN], dtype=np.float64)
    q = np.asarray(timeseries[STRESS_RATIO], dtype=np.float64)
    ev = 100 * np.asarray(timeseries[VOLUMETRIC_STRAIN], dtype=np.float64)
    cycle = np.asarray(timeseries[CYCLE], dtype=np.float64)
    n = max(1, int(np.ceil(cycle.max() - 1e-9)))
    with paper_style():
        fig = Figure(figsize=(7.0, 3.0), layout="constrained")
        left, right = fig.subplots(1, 2)
        for k in range(n):
            inside = (cycle >= k - 1e-3) & (cycle <= k + 1 + 1e-3)  # the end record is both cycles', to rounding
            shade = str(0.75 - 0.65 * k / max(n - 1, 1))
            label = f"cycle {k + 1}" if k in (0, n - 1) else None
            left.plot(eps[inside], q[inside], color=shade, linewidth=0.9, label=label)
            right.plot(eps[inside], ev[inside], color=shade, linewidth=0.9)
        left.set_xlabel("axial strain (%)")
        left.set_ylabel(r"$\sigma_1 / \sigma_3$ (axial / confining)")
        left.legend(frameon=False)
        right.set_xlabel("axial strain (%)")
        right.set_ylabel("volumetric strain (%), compression +")
    return fig


def fabric_figure(timeseries: Mapping[str, ArrayLike], cycles: Sequence[Mapping[str, Any]]) -> Figure:
    """Z, mean lambda and the contact-normal anisotropy a against the cycles done: every
    record as a line, each cycle's end as a marker."""
    cycle = np.asarray(timeseries[CYCLE], dtype=np.float64)
    panels = ((COORDINATION_NUMBER, "coordination number Z"), ("mean_stability_index", r"mean $\lambda$"),
              ("anisotropy", "anisotropy a"))
    ends = np.array([row["cycle"] for row in cycles], dtype=np.float64)
    with paper_style():
        fig = Figure(figsize=(7.0, 2.6), layout="constrained")
        for ax, (column, label) in zip(fig.subplots(1, 3), panels, strict=True):
            ax.plot(cycle, np.asarray(timeseries[column], dtype=np.float64), color="0.6", linewidth=0.7)
            ax.plot(np.r_[0.0, ends], [float(np.asarray(timeseries[column])[0])]
                    + [row[column] for row in cycles], "o", color="k", markersize=3)
            ax.set_xlabel("cycles")
            ax.set_ylabel(label)
    return fig
