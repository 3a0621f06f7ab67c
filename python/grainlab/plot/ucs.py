"""The unconfined compression test's figure, from plain data (a time series as
column -> array): the axial stress and the lateral strain against the axial strain."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from grainlab.columns import AXIAL_STRAIN, AXIAL_STRESS_PA, LATERAL_STRAIN
from grainlab.plot.files import paper_style

__all__ = ["stress_strain_figure"]


def stress_strain_figure(timeseries: Mapping[str, ArrayLike], fit_strains: Sequence[float] | None,
                         youngs_modulus_pa: float | None) -> Figure:
    """Above, the axial stress against the axial strain, its peak q_u marked and the
    range of Young's modulus fit shaded (``fit_strains``, None: no fit); below, the
    lateral strain against the axial strain over the same range (both in %)."""
    strain = 100 * np.asarray(timeseries[AXIAL_STRAIN], dtype=np.float64)
    stress = np.asarray(timeseries[AXIAL_STRESS_PA], dtype=np.float64) / 1e3
    lateral = 100 * np.asarray(timeseries[LATERAL_STRAIN], dtype=np.float64)
    peak = int(np.argmax(stress))
    with paper_style():
        fig = Figure(figsize=(4.0, 5.0), layout="constrained")
        top, bottom = fig.subplots(2, 1, sharex=True)
        top.plot(strain, stress, "-", color="tab:blue", linewidth=1.0)
        top.plot(strain[peak], stress[peak], "o", color="tab:red", markersize=4,
                 label=f"$q_u$ = {stress[peak]:.0f} kPa")
        bottom.plot(strain, lateral, "-", color="tab:green", linewidth=1.0)
        if fit_strains is not None:
            for ax in (top, bottom):
                ax.axvspan(100 * fit_strains[0], 100 * fit_strains[1], color="0.88", zorder=0)
            top.plot([], [], "s", color="0.88", label=(
                "E fit" if youngs_modulus_pa is None else f"E fit: {youngs_modulus_pa / 1e6:.0f} MPa"))
        top.set_ylabel(r"axial stress $\sigma_1$ (kPa)")
        top.legend(frameon=False)
        bottom.set_xlabel(r"axial strain $\varepsilon_a$ (%)")
        bottom.set_ylabel(r"lateral strain $\varepsilon_l$ (%)")
    return fig
