"""The crushing test's figures, from plain data: every agglomerate's force against
the platen's displacement, and the Weibull plot of their strengths with its fit."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from grainlab.columns import AGGLOMERATE, AXIAL_STRAIN, PLATEN_FORCE_N
from grainlab.plot.files import paper_style

__all__ = ["MODE_COLOURS", "force_displacement_figure", "weibull_figure"]

#: Each mode's colour.
MODE_COLOURS = {"split": "tab:red", "fragmented": "tab:orange", "unfailed": "tab:blue"}


def force_displacement_figure(timeseries: Mapping[str, ArrayLike], agglomerates: Sequence[Mapping[str, Any]]) -> Figure:
    """Each agglomerate's platen force against the platen's displacement over d (%), thin
    grey lines, its peak marked in its mode's colour."""
    label = np.asarray(timeseries[AGGLOMERATE])
    strain = 100 * np.asarray(timeseries[AXIAL_STRAIN], dtype=np.float64)
    force = np.asarray(timeseries[PLATEN_FORCE_N], dtype=np.float64)
    with paper_style():
        fig = Figure(figsize=(4.0, 3.0), layout="constrained")
        ax = fig.add_subplot()
        for k, a in enumerate(agglomerates):
            rows = label == k
            ax.plot(strain[rows], force[rows], "-", color="0.6", linewidth=0.6)
            ax.plot(100 * a["axial_strain_at_peak"], a["peak_force_n"], "o", markersize=3,
                    color=MODE_COLOURS[a["mode"]])
        for mode, colour in MODE_COLOURS.items():
            ax.plot([], [], "o", markersize=3, color=colour, label=f"peak ({mode})")
        ax.set_xlabel(r"platen displacement / $d$ (%)")
        ax.set_ylabel(r"platen force $F$ (N per m)")
        ax.legend(frameon=False)
    return fig


def weibull_figure(points: tuple[ArrayLike, ArrayLike], fit: Mapping[str, Any] | None) -> Figure:
    """The Weibull plot's ``points`` (``ln sigma_f`` with sigma_f in kPa, ``ln(-ln P_s)``
    of the median ranks: :func:`grainlab.analysis.weibull.weibull_points`) and the fitted
    line ``m (ln sigma - ln sigma_0)`` with m, sigma_0 and R^2 in its label."""
    x, y = (np.asarray(p, dtype=np.float64) for p in points)
    with paper_style():
        fig = Figure(figsize=(3.5, 3.0), layout="constrained")
        ax = fig.add_subplot()
        if len(x):
            ax.plot(x, y, "o", markersize=3, color="tab:blue", label=f"{len(x)} agglomerates")
        if len(x) and fit is not None:
            line = np.linspace(x[0], x[-1], 2)
            ax.plot(line, fit["modulus"] * (line - np.log(fit["scale"] / 1e3)), "-", color="tab:red",
                    label=(f"m = {fit['modulus']:.2f}, " + r"$\sigma_0$" + f" = {fit['scale'] / 1e3:.0f} kPa, "
                           f"$R^2$ = {fit['r_squared']:.3f}"))
        ax.set_xlabel(r"$\ln(\sigma_f$ / 1 kPa)")
        ax.set_ylabel(r"$\ln(-\ln P_s)$")
        ax.legend(frameon=False, loc="upper left")
    return fig
