"""The report's own figures (PNG bytes, nothing written to the results folder).

- :func:`grading_figure`: the generated sample's grading against the requested one.
- :func:`macro_figure`: stress ratio and volumetric strain against axial
  strain, with the peak and the dilation fit the classical angles come from.

The paper's figures are the files of the results folder; these two only show
how the report's numbers were obtained.
"""

from __future__ import annotations

import io
import math

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import FixedLocator, NullLocator, ScalarFormatter
from numpy.typing import ArrayLike

from grainlab import plot
from grainlab.report.angles import DilationFit
from grainlab.samples.grading import Grading

__all__ = ["DPI", "embedded_png", "grading_figure", "macro_figure", "png_bytes"]

#: Resolution of the report's own figures, and of the figure files' copies it embeds.
DPI = plot.PAGE_DPI


def png_bytes(fig: Figure) -> bytes:
    """The figure as compact PNG bytes (paper style, tight bounding box, :data:`DPI`,
    a 256-colour palette: :func:`grainlab.plot.compact_png`)."""
    buffer = io.BytesIO()
    with plot.paper_style():  # stored uncompressed here: re-encoded below, the pixels are the same
        fig.savefig(buffer, format="png", dpi=DPI, pil_kwargs={"compress_level": 0})
    return plot.compact_png(buffer.getvalue(), keep=plot.scale_colors(fig))


def embedded_png(png: bytes) -> bytes:
    """A figure file's PNG as the page embeds it: at most :data:`DPI` (the page
    shows figures at 1.3 x 96 pixels per inch), palette kept (:func:`grainlab.plot.page_png`:
    the copy made when the figure was drawn, if it was drawn by this process's figure pool)."""
    return plot.page_png(png)


def _cumulative(d: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(d)
    w = weights[order]
    return d[order], 100.0 * np.cumsum(w) / w.sum()


def grading_figure(diameters: ArrayLike, requested: Grading | None, label: str = "requested") -> bytes:
    """Percent passing against diameter (mm, log axis), by mass (2D: mass ~ d^2) and
    by number, for the sample's ``diameters`` (m) and the ``requested`` grading."""
    d = np.asarray(diameters, dtype=np.float64)
    d = d[np.isfinite(d) & (d > 0)]
    if d.size == 0:
        raise ValueError("diameters: no finite positive diameter")
    with plot.paper_style():
        fig = Figure(figsize=(5.2, 3.4), layout="constrained")
        ax = fig.add_subplot()
        x, mass = _cumulative(d, d**2)
        _, number = _cumulative(d, np.ones_like(d))
        ax.step(1e3 * x, mass, where="post", color="C0", label="sample, by mass")
        ax.step(1e3 * x, number, where="post", color="C0", linestyle="--", linewidth=0.9,
                label="sample, by number")
        if requested is not None:
            grid = np.geomspace(requested.d_min, requested.d_max, 200)
            ax.plot(1e3 * grid, np.asarray(requested.passing(grid)), color="C3", linewidth=1.0,
                    label=f"{label}, by mass")
            ax.plot(1e3 * grid, 100.0 * np.asarray(requested.number_cdf(grid)), color="C3",
                    linestyle="--", linewidth=0.8, label=f"{label}, by number")
        ax.set_xscale("log")
        lo, hi = 1e3 * d.min(), 1e3 * d.max()
        ticks = [t for t in (0.1, 0.2, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0) if 0.8 * lo <= t <= 1.25 * hi]
        if len(ticks) >= 2:
            ax.xaxis.set_major_locator(FixedLocator(ticks))
            ax.xaxis.set_major_formatter(ScalarFormatter())
            ax.xaxis.set_minor_locator(NullLocator())
        ax.set_xlabel("diameter d (mm)")
        ax.set_ylabel("percent finer (%)")
        ax.set_ylim(0, 100)
        ax.grid(True, color="0.9", linewidth=0.6)
        ax.legend(frameon=False, loc="upper left")
    return png_bytes(fig)


def macro_figure(
    axial_strain: ArrayLike,
    stress_ratio: ArrayLike,
    volumetric_strain: ArrayLike,
    peak_row: int,
    dilation: DilationFit,
    phi: float,
) -> bytes:
    """Two panels against axial strain (%): sigma_1/sigma_3 with the peak and phi;
    volumetric strain (%, compression positive) with the fitted line and psi."""
    eps = 100.0 * np.asarray(axial_strain, dtype=np.float64)
    q = np.asarray(stress_ratio, dtype=np.float64)
    ev = 100.0 * np.asarray(volumetric_strain, dtype=np.float64)
    with plot.paper_style():
        fig = Figure(figsize=(5.6, 5.0), layout="constrained")
        top, bottom = fig.subplots(2, 1, sharex=True)
        top.plot(eps, q, color="C0")
        top.axhline(1.0, color="0.7", linewidth=0.7, linestyle="--")
        top.plot([eps[peak_row]], [q[peak_row]], marker="o", color="C3", linestyle="none",
                 label=rf"peak {q[peak_row]:.2f} at {eps[peak_row]:.2f} %, $\varphi$ = "
                 + (f"{math.degrees(phi):.1f}°" if math.isfinite(phi) else "n/a"))
        top.set_ylabel(r"$\sigma_1/\sigma_3$")
        top.legend(frameon=False, loc="lower right")
        bottom.plot(eps, ev, color="C0")
        bottom.axhline(0.0, color="0.7", linewidth=0.7, linestyle="--")
        if math.isfinite(dilation.angle):
            x = np.array([dilation.start_strain, dilation.end_strain])
            bottom.plot(100.0 * x, 100.0 * (dilation.slope * x + dilation.intercept), color="C3",
                        linewidth=2.0, alpha=0.8,
                        label=rf"fit after the peak: d$\varepsilon_v$/d$\varepsilon_1$ = {dilation.slope:.3f},"
                        rf" $\psi$ = {math.degrees(dilation.angle):.1f}°")
            bottom.legend(frameon=False, loc="lower left")
        bottom.axvline(eps[peak_row], color="C3", linewidth=0.6, linestyle=":")
        top.axvline(eps[peak_row], color="C3", linewidth=0.6, linestyle=":")
        bottom.set_ylabel(r"$\varepsilon_v$ (%, compression +)")
        bottom.set_xlabel(r"axial strain $\varepsilon_{1}$ (%, compression +)")
        for ax in (top, bottom):
            ax.grid(True, color="0.92", linewidth=0.6)
    return png_bytes(fig)
