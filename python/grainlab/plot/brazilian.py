"""The Brazilian test's figure, from plain data (a time series as column -> array):
the platen force and the indirect tensile stress, and the bonds broken, against the
platens' displacement."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from grainlab.columns import (
    CEMENT_BONDS_BROKEN,
    PLATEN_DISPLACEMENT_M,
    PLATEN_FORCE_N_PER_M,
    TENSILE_STRESS_PA,
)
from grainlab.plot.files import paper_style

__all__ = ["force_displacement_figure"]


def force_displacement_figure(timeseries: Mapping[str, ArrayLike], diameter_m: float) -> Figure:
    """Above, the platen force F (kN/m) against the platens' displacement (um), the
    indirect tensile stress 2 F / (pi D t) on the right axis (t = 1 m) and the peak
    marked; below, the cement bonds broken so far."""
    displacement = 1e6 * np.asarray(timeseries[PLATEN_DISPLACEMENT_M], dtype=np.float64)
    force = np.asarray(timeseries[PLATEN_FORCE_N_PER_M], dtype=np.float64) / 1e3
    stress = np.asarray(timeseries[TENSILE_STRESS_PA], dtype=np.float64) / 1e3
    broken = np.asarray(timeseries[CEMENT_BONDS_BROKEN], dtype=np.float64)
    peak = int(np.argmax(stress))
    kpa_per_kn = 2.0 / (math.pi * diameter_m)  # kPa of stress per kN/m of force
    with paper_style():
        fig = Figure(figsize=(4.0, 5.0), layout="constrained")
        top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
        top.plot(displacement, force, "-", color="tab:blue", linewidth=1.0)
        top.plot(displacement[peak], force[peak], "o", color="tab:red", markersize=4,
                 label=rf"$\sigma_t$ = {stress[peak]:.0f} kPa, $F_{{max}}$ = {force[peak]:.2f} kN/m")
        top.secondary_yaxis("right", functions=(lambda f: f * kpa_per_kn, lambda s: s / kpa_per_kn)).set_ylabel(
            r"$2F/(\pi D t)$ (kPa)")
        top.set_ylabel("platen force F (kN/m)")
        top.legend(frameon=False)
        bottom.plot(displacement, broken, "-", color="tab:gray", linewidth=1.0)
        bottom.set_xlabel(r"platen displacement $\delta$ ($\mu$m)")
        bottom.set_ylabel("bonds broken")
    return fig
