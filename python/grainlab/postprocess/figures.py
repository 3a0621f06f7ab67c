"""The paper's Figs. 6, 7, 9, 11, 12, 13 and 14 of a biaxial run, as PNG + SVG files
(docs/analysis.md, "Figures of a biaxial run").
"""

from __future__ import annotations

import math
import string
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.columns import AXIAL_STRAIN
from grainlab.plot.biaxial import (
    COUNT_CAP,
    BandOutline,
    MapPanel,
    PolarPanel,
    anisotropy_figure,
    displacement_figure,
    mean_lambda_figure,
    polar_figure,
    shared_map_figure,
)
from grainlab.plot.workers import FigureTask, figure_pool
from grainlab.postprocess.band import BandSearch
from grainlab.postprocess.biaxial import FabricNumbers, RunAnalysis, RunState, analyse_run

__all__ = ["FIGURES", "FabricFigures", "fabric_figures", "figure_tasks"]

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
    """A map of ``values`` (one per grain of ``st.snap``); a run of clumps drawn as its
    pebbles, each in its body's colour."""
    note, outlines = _band_note(analysis.band_of(st))
    if st.view is not None:
        pebbles = st.view.pebbles
        return MapPanel(pebbles.positions, pebbles.radii, values[st.view.body], _title(k, st), note, outlines)
    return MapPanel(st.snap.positions, st.snap.radii, values, _title(k, st), note, outlines)


def _displacements(analysis: RunAnalysis) -> FigureTask | None:
    states = _distinct([analysis.states["peak"], analysis.states["final"]])
    searched = [(st, b) for st in states if (b := analysis.band_of(st)) is not None]
    if not searched:
        return None
    panels = [_panel(analysis, k, st, b.displacement) for k, (st, b) in enumerate(searched)]
    return FigureTask("fig11_displacement", displacement_figure, (panels, analysis.states["initial"].name), cost=3.0)


def _maps(name: str, analysis: RunAnalysis, values: Any, **style: Any) -> FigureTask:
    states = _distinct([analysis.states[r] for r in ("initial", "peak", "final")])
    panels = [
        _panel(analysis, k, st, np.asarray(values(st), dtype=np.float64)) for k, st in enumerate(states)
    ]
    return FigureTask(name, shared_map_figure, (panels,), style, cost=4.0)


def _contact_counts(st: RunState) -> NDArray[np.float64]:
    counts = np.minimum(st.stability.n_contacts, COUNT_CAP).astype(np.float64)
    return np.where(st.snap.is_sample, counts, np.nan)


def _series(analysis: RunAnalysis, which: str) -> FigureTask:
    ts = analysis.results.timeseries
    eps, peak = ts[AXIAL_STRAIN], analysis.numbers.peak_axial_strain
    if which == "anisotropy":
        return FigureTask("fig09_anisotropy", anisotropy_figure, (eps, ts["anisotropy"], ts["force_anisotropy"], peak))
    return FigureTask(
        "fig14_mean_stability_index",
        mean_lambda_figure,
        (eps, ts["mean_stability_index"], ts.get("mean_stability_index_all"), peak),
    )


def figure_tasks(analysis: RunAnalysis) -> list[FigureTask]:
    """The figures of :func:`fabric_figures` for the measured run, in the paper's order
    (``fig11_displacement`` only with a band searched), each with its drawing cost."""
    states = analysis.states
    polar_states = _distinct([states["initial"], states["peak"]])
    polar = [PolarPanel(_title(k, st), st.normals) for k, st in enumerate(polar_states)]
    polar_forces = [PolarPanel(_title(k, st), st.forces) for k, st in enumerate(polar_states)]
    tasks = [
        FigureTask("fig06_contact_normals", polar_figure, (polar, False), cost=2.0),
        FigureTask("fig07_normal_forces", polar_figure, (polar_forces, True), cost=2.5),
        _series(analysis, "anisotropy"),
        _displacements(analysis),
        _maps(
            "fig12_stability_index",
            analysis,
            lambda st: st.stability.stability_index,
            label=r"geometrical stability index $\lambda$",
            suptitle=r"Geometrical stability index $\lambda$ of the grains",
            vmin=0.0,
            vmax=1.0,
        ),
        _maps(
            "fig13_contact_count",
            analysis,
            _contact_counts,
            label="number of contacts",
            discrete=True,
            suptitle="Number of contacts per grain (boundary contacts included)",
            vmin=0.0,
        ),
        _series(analysis, "lambda"),
    ]
    return [task for task in tasks if task is not None]


def fabric_figures(
    run_dir: str | Path,
    out_dir: str | Path | None = None,
    *,
    peak_snapshot: str | int | None = None,
    workers: int | None = None,
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
    workers
        The most worker processes drawing the figures side by side (0: all
        in this process); inside a ``with FigurePool()`` block they are drawn
        in that pool instead (:mod:`grainlab.plot.workers`).

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
    with figure_pool(workers, tasks=len(FIGURES)) as pool:
        # measured in a worker too: its numerical libraries run on one thread (twice as fast here)
        numbers, tasks = pool.submit(_planned, Path(run_dir), peak_snapshot).result()
        out = Path(out_dir) if out_dir is not None else numbers.results_path.parent
        drawn = pool.draw(tasks, out).result()
    return FabricFigures(drawn, numbers)


def _planned(run_dir: Path, peak_snapshot: str | int | None) -> tuple[FabricNumbers, list[FigureTask]]:
    """The run measured and its figures planned (where the pool runs it)."""
    analysis = analyse_run(run_dir, peak_snapshot)
    return analysis.numbers, figure_tasks(analysis)
