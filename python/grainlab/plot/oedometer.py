"""The oedometer's figures, from plain data (a time series as column -> array):
the lateral stress ratio K along the load path, and the compression curve."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from grainlab.columns import LATERAL_STRESS_RATIO, VERTICAL_STRESS_PA, VOID_RATIO
from grainlab.plot.files import paper_style

__all__ = ["compression_figure", "fragment_grading_figure", "lateral_stress_ratio_figure"]


def _branches(timeseries: Mapping[str, ArrayLike], loading: ArrayLike, y: str) -> list[tuple[str, str, np.ndarray,
                                                                                                np.ndarray]]:
    sigma_v = np.asarray(timeseries[VERTICAL_STRESS_PA], dtype=np.float64) / 1e3
    values = np.asarray(timeseries[y], dtype=np.float64)
    first = np.zeros(len(sigma_v), dtype=bool)
    first[np.asarray(loading, dtype=np.int64)] = True
    later = np.flatnonzero(~first)
    if len(later) and later[0] > 0:  # the unloading line starts where the loading turned
        later = np.r_[later[0] - 1, later]
    return [("loading", "o-", sigma_v[first], values[first]),
            ("unloading", "s--", sigma_v[later], values[later])]


def _against_vertical_stress(
    timeseries: Mapping[str, ArrayLike], loading: ArrayLike, y: str, ylabel: str,
    line: tuple[float, str] | None = None,
) -> Figure:
    """Column ``y`` against sigma_v (log axis), loading and unloading, with a horizontal
    ``line`` (value, label) when given."""
    with paper_style():
        fig = Figure(figsize=(3.5, 3.0), layout="constrained")
        ax = fig.add_subplot()
        for label, style, x, values in _branches(timeseries, loading, y):
            if len(x):
                ax.plot(x, values, style, markersize=3, label=label)
        if line is not None:
            ax.axhline(line[0], color="0.4", linewidth=0.8, linestyle=":", label=line[1])
        ax.set_xscale("log")
        ax.set_xlabel(r"vertical stress $\sigma_v$ (kPa)")
        ax.set_ylabel(ylabel)
        ax.legend(frameon=False)
    return fig


def lateral_stress_ratio_figure(timeseries: Mapping[str, ArrayLike], loading: ArrayLike, k0_jaky: float | None,
                                friction_angle_deg: float | None) -> Figure:
    """K = sigma_h / sigma_v against sigma_v (log axis), loading and unloading, with
    Jaky's 1 - sin phi' as a line when a friction angle is given."""
    jaky = None if k0_jaky is None else (k0_jaky, f"Jaky, phi' = {friction_angle_deg:.1f} deg")
    k = r"$K = \sigma_h / \sigma_v$"
    return _against_vertical_stress(timeseries, loading, LATERAL_STRESS_RATIO, k, jaky)


def compression_figure(timeseries: Mapping[str, ArrayLike], loading: ArrayLike,
                       yield_stress_pa: float | None = None) -> Figure:
    """Void ratio against sigma_v (log axis): the compression and swelling lines, and the
    yield stress of a sample of agglomerates as a vertical line when given."""
    fig = _against_vertical_stress(timeseries, loading, VOID_RATIO, "void ratio e")
    if yield_stress_pa is not None:
        ax = fig.axes[0]
        with paper_style():
            ax.axvline(yield_stress_pa / 1e3, color="tab:red", linewidth=0.8, linestyle="--",
                       label=f"yield stress {yield_stress_pa / 1e3:.0f} kPa")
            ax.legend(frameon=False)
    return fig


def fragment_grading_figure(sieves: Sequence[float], grading: Sequence[Mapping[str, Any]]) -> Figure:
    """The fragments' grading at each load step: percent of the solid area passing
    against the sieve size (log axis, mm), one line per step coloured by its sigma_v."""
    from matplotlib import colormaps
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

    with paper_style():
        fig = Figure(figsize=(4.0, 3.0), layout="constrained")
        ax = fig.add_subplot()
        colours = colormaps["viridis"](np.linspace(0.0, 0.9, max(len(grading), 1)))
        for g, colour in zip(grading, colours, strict=False):
            ax.plot(1e3 * np.asarray(sieves), g["percent_passing"], "-", color=colour, linewidth=1.0,
                    label=f"{g['vertical_stress_pa'] / 1e3:.0f} kPa ({g['fragments']} fragments)")
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("fragment size (equivalent-area diameter, mm)")
        ax.set_ylabel("percent passing (by area)")
        ax.legend(frameon=False, fontsize=6)
    return fig
