"""The crack records of a cemented sample (docs/cemented.md, "Crack records"): each
cement bond that broke, taken from the engine's log on a record step and appended to
``run.h5``'s ``/cracks`` table (docs/file-formats.md), its axial strain read off the
time series at the break's time."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from grainlab.cement import BondBreaks
from grainlab.columns import AXIAL_STRAIN, TIME_S
from grainlab.io.hdf5 import Results, ResultsWriter
from grainlab.protocols.operations import Loading, Operation
from grainlab.protocols.triggers import Trigger

if TYPE_CHECKING:
    from grainlab.plot.workers import FigureTask

__all__ = ["CRACK_UNITS", "CrackRecords", "crack_columns", "crack_task"]

#: The ``/cracks`` table's columns and units, in order.
CRACK_UNITS: dict[str, str] = {
    "step": "1", "time_s": "s", "axial_strain": "1", "i": "1", "j": "1", "x_m": "m", "y_m": "m",
    "normal_x": "1", "normal_y": "1", "tension": "1", "energy_j": "J", "normal_force_n": "N",
    "shear_force_n": "N", "moment_n_m": "N m",
}


def crack_columns(breaks: BondBreaks, axial_strain: NDArray[np.float64]) -> dict[str, NDArray[np.generic]]:
    """The ``/cracks`` rows of ``breaks`` at ``axial_strain`` (one per break): the step
    and time, the particles (user indices), the bond's centre and normal, ``tension`` 1
    for a break in tension and 0 in shear, the energy released and the forces at the break."""
    return {
        "step": breaks.step.astype(np.int64), "time_s": breaks.time, "axial_strain": axial_strain,
        "i": breaks.i.astype(np.int64), "j": breaks.j.astype(np.int64),
        "x_m": breaks.position[:, 0], "y_m": breaks.position[:, 1],
        "normal_x": breaks.normal[:, 0], "normal_y": breaks.normal[:, 1],
        "tension": (breaks.mode == "tension").astype(np.int8), "energy_j": breaks.energy,
        "normal_force_n": breaks.normal_force, "shear_force_n": breaks.shear_force, "moment_n_m": breaks.moment,
    }


def crack_task(results: Results) -> FigureTask | None:
    """The crack map and rose (``fig20_cracks``) of a run with crack records, on its last
    snapshot's grains; None without cracks."""
    if not results.cracks:
        return None
    from grainlab.plot.cracks import crack_figure
    from grainlab.plot.workers import FigureTask

    last = results.snapshot(-1)
    grains = np.asarray(last.is_sample)
    title = f"Broken cement bonds to {100 * results.timeseries[AXIAL_STRAIN][-1]:.2f} % axial strain"
    return FigureTask("fig20_cracks", crack_figure, (last.positions[grains], last.radii[grains], results.cracks, title))


class CrackRecords(Operation):
    """Writer: the bonds broken since its last act, appended to ``/cracks`` (after the
    step's record, so that each break's axial strain is the time series' at its time:
    exact at a constant strain rate, the first record's for a break before shearing).
    ``strain(times)`` gives the axial strain at the breaks' times instead, and ``labels``
    columns of one value each (with their units) after the table's own."""

    def __init__(self, trigger: Trigger, writer: ResultsWriter,
                 strain: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
                 labels: Mapping[str, int] | None = None) -> None:
        super().__init__(trigger)
        self.writer, self.strain, self.labels = writer, strain, dict(labels or {})

    def act(self, loading: Loading) -> None:
        breaks = loading.sim.take_bond_breaks()
        if len(breaks) == 0:
            return
        if self.strain is None:
            series = self.writer.read_timeseries()
            strain = np.interp(breaks.time, series[TIME_S], series[AXIAL_STRAIN])
        else:
            strain = self.strain(breaks.time)
        columns = {**crack_columns(breaks, strain), **{k: np.full(len(breaks), v) for k, v in self.labels.items()}}
        self.writer.append_cracks(columns, {**CRACK_UNITS, **dict.fromkeys(self.labels, "1")})
