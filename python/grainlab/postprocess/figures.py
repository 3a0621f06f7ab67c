"""The paper's Figs. 6, 7, 9, 11, 12, 13 and 14 of a biaxial run, as PNG + SVG files.

:func:`fabric_figures` measures the run (:func:`~grainlab.postprocess.biaxial.analyse_run`),
turns its states into panels and draws them with :mod:`grainlab.plot.biaxial`.
Maps draw the membrane disks light grey (NaN); a found band is outlined
dashed (its second, conjugate band dotted) and the panel title gives its
inclination to the horizontal and thickness; a band that was searched and
not found leaves the maps without an outline and the title says so.
"""

from __future__ import annotations

import math
import string
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from grainlab import plot
from grainlab.plot.biaxial import (
    COUNT_CAP,
    BandOutline,
    MapPanel,
    PolarPanel,
    displacement_figure,
    polar_figure,
    series_figure,
    shared_map_figure,
)
from grainlab.postprocess.band import BandSearch
from grainlab.postprocess.biaxial import FabricNumbers, RunAnalysis, RunState, analyse_run

__all__ = ["FIGURES", "FabricFigures", "fabric_figures"]

#: Figure names (file stems), in the paper's order.
FIGURES: tuple[str, ...] = (
    "fig06_contact_normals",
    "fig07_normal_forces",
    "fig09_anisotropy",
    "fig11_displacement",
    "fig12_stability_index",
    "fig13_contact_count",
    "fig14_mean_stability_index",
)


class FabricFigures(dict[str, list[Path]]):
    """Figure name -> files written (PNG, SVG), with the numbers in :attr:`numbers`.

    A plain dict of the figures (equality compares the files only) that also
    carries the :class:`FabricNumbers` the figures show.
    """

    def __init__(self, files: dict[str, list[Path]], numbers: FabricNumbers) -> None:
        super().__init__(files)
        self.numbers = numbers

    @property
    def paths(self) -> list[Path]:
        """Every file written, in figure order."""
        return [p for files in self.values() for p in files]


def _percent(strain: float) -> str:
    return (
        "unknown strain"
        if not math.isfinite(strain)
        else rf"$\varepsilon_{{11}}$ = {100 * strain:.2f} %"
    )


def _title(k: int, st: RunState) -> str:
    return f"({string.ascii_lowercase[k]}) {st.label}, {_percent(st.strain)}"


def _distinct(states: Sequence[RunState]) -> list[RunState]:
    seen: set[str] = set()
    out = []
    for st in states:
        if st.name not in seen:
            seen.add(st.name)
            out.append(st)
    return out


def _band_note(band: BandSearch | None) -> tuple[str, tuple[BandOutline, ...]]:
    """The title line and outlines of a map at a state where ``band`` was searched."""
    if band is None:
        return "", ()
    if band.band is None:
        return "no shear band found", ()
    b = band.numbers
    text = f"band {b.inclination_deg:.0f}° to horizontal, {b.thickness_diameters:.1f} d"
    if band.second is not None:
        text += f"\nsecond band {b.second_inclination_deg:.0f}°, {b.second_thickness_diameters:.1f} d"
    outlines = tuple(
        BandOutline(tuple(found.outline()), style, label)
        for found, style, label in ((band.band, "--", "shear band"), (band.second, ":", "second band"))
        if found is not None
    )
    return text, outlines


def _panel(analysis: RunAnalysis, k: int, st: RunState, values: NDArray[np.float64]) -> MapPanel:
    note, outlines = _band_note(analysis.band_of(st))
    return MapPanel(st.snap.positions, st.snap.radii, values, _title(k, st), note, outlines)


def _displacements(analysis: RunAnalysis) -> Figure | None:
    states = _distinct([analysis.states["peak"], analysis.states["final"]])
    searched = [(st, b) for st in states if (b := analysis.band_of(st)) is not None]
    if not searched:
        return None
    panels = [_panel(analysis, k, st, b.displacement) for k, (st, b) in enumerate(searched)]
    return displacement_figure(panels, analysis.states["initial"].name)


def _maps(analysis: RunAnalysis, values: Any, **style: Any) -> Figure:
    states = _distinct([analysis.states[r] for r in ("initial", "peak", "final")])
    panels = [
        _panel(analysis, k, st, np.asarray(values(st), dtype=np.float64)) for k, st in enumerate(states)
    ]
    return shared_map_figure(panels, **style)


def _contact_counts(st: RunState) -> NDArray[np.float64]:
    counts = np.minimum(st.stability.n_contacts, COUNT_CAP).astype(np.float64)
    return np.where(st.snap.is_sample, counts, np.nan)


def _series(analysis: RunAnalysis, which: str) -> Figure:
    ts = analysis.results.timeseries
    eps = ts["axial_strain"]

    def draw(ax: Any) -> Any:
        if which == "anisotropy":
            return plot.anisotropy_series(eps, ts["anisotropy"], normal_force=ts["force_anisotropy"], ax=ax)
        return plot.mean_lambda_series(
            eps, ts["mean_stability_index"], mean_lambda_all=ts.get("mean_stability_index_all"), ax=ax
        )

    return series_figure(eps, draw, analysis.numbers.peak_axial_strain)


def fabric_figures(
    run_dir: str | Path,
    out_dir: str | Path | None = None,
    *,
    peak_snapshot: str | int | None = None,
) -> FabricFigures:
    """Draw the paper's Figs. 6, 7, 9, 11, 12, 13, 14 of a biaxial run, PNG + SVG.

    Parameters
    ----------
    run_dir
        A run folder holding ``run.h5``, or the ``run.h5`` file itself.
    out_dir
        Where to write the figures; default the run folder.
    peak_snapshot
        The snapshot standing for the peak state, by name or position;
        default the snapshot (other than the first) closest in axial strain
        to the peak of ``stress_ratio``.

    Returns
    -------
    FabricFigures
        ``{figure name: [png, svg]}`` for the names in :data:`FIGURES`
        (``fig11_displacement`` is absent when the run has a single snapshot),
        with the numbers in ``.numbers`` (:class:`FabricNumbers`).

    Raises
    ------
    MissingColumnError
        A column of :data:`~grainlab.postprocess.biaxial.REQUIRED_COLUMNS` is
        missing from the time series.
    ValueError
        No snapshots, no finite stress ratio, or an unknown ``peak_snapshot``.
    """
    analysis = analyse_run(run_dir, peak_snapshot)
    out = Path(out_dir) if out_dir is not None else analysis.results.path.parent
    out.mkdir(parents=True, exist_ok=True)
    states = analysis.states
    polar = [PolarPanel(_title(k, st), st.normals) for k, st in enumerate(_distinct([states["initial"], states["peak"]]))]
    polar_forces = [
        PolarPanel(_title(k, st), st.forces) for k, st in enumerate(_distinct([states["initial"], states["peak"]]))
    ]
    drawn: dict[str, Figure | None] = {
        "fig06_contact_normals": polar_figure(polar, forces=False),
        "fig07_normal_forces": polar_figure(polar_forces, forces=True),
        "fig09_anisotropy": _series(analysis, "anisotropy"),
        "fig11_displacement": _displacements(analysis),
        "fig12_stability_index": _maps(
            analysis,
            lambda st: st.stability.stability_index,
            label=r"geometrical stability index $\lambda$",
            suptitle=r"Geometrical stability index $\lambda$ of the grains",
            vmin=0.0,
            vmax=1.0,
        ),
        "fig13_contact_count": _maps(
            analysis,
            _contact_counts,
            label="number of contacts",
            discrete=True,
            suptitle="Number of contacts per grain (boundary contacts included)",
            vmin=0.0,
        ),
        "fig14_mean_stability_index": _series(analysis, "lambda"),
    }
    files: dict[str, list[Path]] = {}
    for name, fig in drawn.items():
        if fig is not None:
            files[name] = plot.save_figure(fig, out / name)
    return FabricFigures(files, analysis.numbers)
