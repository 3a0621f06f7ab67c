"""The periodic simple-shear test's figures, from plain data (a time series as
column -> array): the effective friction and the volume against the shear
strain, the fabric (Z, anisotropy, lambda) against it, and the
Rothenburg-Bathurst relation checked on every record."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from grainlab.columns import (
    COORDINATION_NUMBER,
    FRICTION_COEFFICIENT,
    NORMAL_STRESS_PA,
    RB_PREDICTED,
    RB_RESIDUAL,
    RB_STRESS_RATIO,
    SHEAR_STRAIN,
    SHEAR_STRESS_PA,
    VOLUMETRIC_STRAIN,
)
from grainlab.plot.files import paper_style

__all__ = ["fabric_figure", "friction_volume_figure", "mu_of_inertial_number_figure", "stress_force_fabric_figure",
           "stress_path_figure"]


def _gamma(timeseries: Mapping[str, ArrayLike]) -> np.ndarray:
    return 100.0 * np.asarray(timeseries[SHEAR_STRAIN], dtype=np.float64)


def _steady(ax: Any, steady_from: float, gamma: np.ndarray) -> None:
    """Shades the steady state, from ``steady_from`` to the last record."""
    ax.axvspan(100.0 * steady_from, float(gamma.max()), color="0.92", zorder=0)


def friction_volume_figure(timeseries: Mapping[str, ArrayLike], steady_from: float) -> Figure:
    """mu = tau / sigma_n and the volumetric strain (dilation up) against gamma; the steady state shaded."""
    gamma = _gamma(timeseries)
    with paper_style():
        fig = Figure(figsize=(3.5, 4.2), layout="constrained")
        top, bottom = fig.subplots(2, 1, sharex=True)
        top.plot(gamma, np.asarray(timeseries[FRICTION_COEFFICIENT], dtype=np.float64), linewidth=0.9)
        top.set_ylabel(r"$\mu = \tau / \sigma_n$")
        bottom.plot(gamma, -100.0 * np.asarray(timeseries[VOLUMETRIC_STRAIN], dtype=np.float64), linewidth=0.9)
        bottom.set_ylabel(r"dilation $-\varepsilon_v$ (%)")
        bottom.set_xlabel(r"shear strain $\gamma$ (%)")
        for ax in (top, bottom):
            _steady(ax, steady_from, gamma)
    return fig


def fabric_figure(timeseries: Mapping[str, ArrayLike], steady_from: float) -> Figure:
    """Z, the contact-normal anisotropy a and the mean lambda against gamma."""
    gamma = _gamma(timeseries)
    panels = ((COORDINATION_NUMBER, "Z"), ("anisotropy", "anisotropy $a$"),
              ("mean_stability_index", r"mean $\lambda$"))
    with paper_style():
        fig = Figure(figsize=(3.5, 5.0), layout="constrained")
        axes = fig.subplots(len(panels), 1, sharex=True)
        for ax, (column, label) in zip(axes, panels, strict=True):
            ax.plot(gamma, np.asarray(timeseries[column], dtype=np.float64), linewidth=0.9)
            ax.set_ylabel(label)
            _steady(ax, steady_from, gamma)
        axes[-1].set_xlabel(r"shear strain $\gamma$ (%)")
    return fig


def stress_path_figure(timeseries: Mapping[str, ArrayLike], steady_mu: float) -> Figure:
    """The stress path tau against sigma_n (kPa), with the steady state's line tau = mu sigma_n,
    and sigma_n against gamma: at constant volume, the undrained test's path."""
    tau = np.asarray(timeseries[SHEAR_STRESS_PA], dtype=np.float64) / 1e3
    sigma = np.asarray(timeseries[NORMAL_STRESS_PA], dtype=np.float64) / 1e3
    with paper_style():
        fig = Figure(figsize=(6.5, 3.0), layout="constrained")
        left, right = fig.subplots(1, 2)
        left.plot(sigma, tau, linewidth=0.9)
        left.plot(sigma[:1], tau[:1], "o", markersize=3, color="0.3")
        top = float(np.nanmax(sigma)) * 1.05
        left.plot([0.0, top], [0.0, steady_mu * top], color="0.4", linewidth=0.8, linestyle=":",
                  label=rf"steady $\mu$ = {steady_mu:.3f}")
        left.set_xlim(0.0, top)
        left.set_ylim(bottom=min(0.0, float(np.nanmin(tau))))
        left.set_xlabel(r"normal stress $\sigma_n$ (kPa)")
        left.set_ylabel(r"shear stress $\tau$ (kPa)")
        left.legend(frameon=False)
        right.plot(_gamma(timeseries), sigma, linewidth=0.9)
        right.set_xlabel(r"shear strain $\gamma$ (%)")
        right.set_ylabel(r"$\sigma_n$ (kPa)")
    return fig


def stress_force_fabric_figure(timeseries: Mapping[str, ArrayLike]) -> Figure:
    """Measured q/p against Rothenburg and Bathurst's (a + a_n + a_t)/2 on every
    record (the line is equality), and the residual against gamma."""
    measured = np.asarray(timeseries[RB_STRESS_RATIO], dtype=np.float64)
    predicted = np.asarray(timeseries[RB_PREDICTED], dtype=np.float64)
    with paper_style():
        fig = Figure(figsize=(6.5, 3.0), layout="constrained")
        left, right = fig.subplots(1, 2)
        left.plot(predicted, measured, ".", markersize=3)
        span = [float(np.nanmin([measured, predicted])), float(np.nanmax([measured, predicted]))]
        left.plot(span, span, color="0.4", linewidth=0.8, linestyle=":")
        left.set_xlabel(r"$\frac{1}{2}(a + a_n + a_t)$ projected")
        left.set_ylabel(r"measured $q/p$")
        right.plot(_gamma(timeseries), np.asarray(timeseries[RB_RESIDUAL], dtype=np.float64), linewidth=0.9)
        right.axhline(0.0, color="0.4", linewidth=0.8, linestyle=":")
        right.set_xlabel(r"shear strain $\gamma$ (%)")
        right.set_ylabel("residual (measured - predicted)")
    return fig


def mu_of_inertial_number_figure(inertial_number: ArrayLike, friction: ArrayLike, porosity: ArrayLike,
                                 fit: tuple[float, float, float, float] | None = None,
                                 fit_max: float | None = None) -> Figure:
    """Steady-state mu and solid fraction against I (log axis) over a rate sweep,
    with the fitted lines mu_min + b I and nu_max - a I (``fit = (mu_min, b, nu_max,
    a)``) drawn over the runs they were fitted to (I up to ``fit_max``)."""
    i = np.asarray(inertial_number, dtype=np.float64)
    with paper_style():
        fig = Figure(figsize=(6.5, 3.0), layout="constrained")
        left, right = fig.subplots(1, 2)
        left.plot(i, np.asarray(friction, dtype=np.float64), "o", markersize=4)
        right.plot(i, 1.0 - np.asarray(porosity, dtype=np.float64), "s", markersize=4)
        if fit is not None:
            grid = np.geomspace(i.min(), i.max() if fit_max is None else fit_max, 50)
            left.plot(grid, fit[0] + fit[1] * grid, color="0.4", linewidth=0.8,
                      label=rf"$\mu = {fit[0]:.3f} + {fit[1]:.2f}\,I$")
            right.plot(grid, fit[2] - fit[3] * grid, color="0.4", linewidth=0.8,
                       label=rf"$\nu = {fit[2]:.3f} - {fit[3]:.2f}\,I$")
            left.legend(frameon=False)
            right.legend(frameon=False)
        left.set_xscale("log")
        left.set_xlabel("inertial number $I$")
        left.set_ylabel(r"steady $\mu$")
        right.set_xscale("log")
        right.set_xlabel("inertial number $I$")
        right.set_ylabel(r"solid fraction $\nu$")
    return fig
