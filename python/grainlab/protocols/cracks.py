"""The crack records of a cemented sample (docs/cemented.md, "Crack records"): each
cement bond that broke, taken from the engine's log on a record step and appended to
``run.h5``'s ``/cracks`` table (docs/file-formats.md), the test's strain (axial, or
simple shear's shear strain) read off the time series at the break's time; the
bonds-broken column a cemented sample adds to its test's records."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from grainlab.cement import BondBreaks
from grainlab.columns import AXIAL_STRAIN, CEMENT_BONDS_BROKEN, CEMENTED, TIME_S, Columns
from grainlab.io.hdf5 import Results, ResultsWriter
from grainlab.protocols.config import Config
from grainlab.protocols.operations import Loading, Operation
from grainlab.protocols.triggers import Trigger
from grainlab.simulation import Simulation

if TYPE_CHECKING:
    from grainlab.plot.workers import FigureTask

__all__ = ["CrackRecords", "bonds_broken", "broken_since", "crack_columns", "crack_records", "crack_task", "crack_units",
           "record_units"]


def crack_units(strain: str = AXIAL_STRAIN) -> dict[str, str]:
    """The ``/cracks`` table's columns and units, in order, ``strain`` the test's strain column."""
    return {
        "step": "1", "time_s": "s", strain: "1", "i": "1", "j": "1", "x_m": "m", "y_m": "m",
        "normal_x": "1", "normal_y": "1", "tension": "1", "energy_j": "J", "normal_force_n": "N",
        "shear_force_n": "N", "moment_n_m": "N m",
    }


def record_units(columns: Columns, config: Config) -> dict[str, str]:
    """The units of a record of ``columns``, a cemented sample's column after them."""
    return {**columns.units(), **(CEMENTED.units() if config.cement.bonds != "none" else {})}


def broken_since(sim: Simulation, consolidation: dict[str, Any]) -> float:
    """The cement bonds broken since the end of the consolidation (its ``consolidation["cement_bonds"]``)."""
    return float(consolidation["cement_bonds"] - sim.n_cement_bonds)


def bonds_broken(sim: Simulation, consolidation: dict[str, Any], config: Config) -> dict[str, float]:
    """A cemented sample's record column (:func:`broken_since`); nothing for an uncemented one."""
    return {} if config.cement.bonds == "none" else {CEMENT_BONDS_BROKEN: broken_since(sim, consolidation)}


def crack_columns(breaks: BondBreaks, strain: NDArray[np.float64],
                  strain_column: str = AXIAL_STRAIN) -> dict[str, NDArray[np.generic]]:
    """The ``/cracks`` rows of ``breaks`` at ``strain`` (one per break): the step and
    time, the strain (as ``strain_column``), the particles (user indices), the bond's
    centre and normal, ``tension`` 1 for a break in tension and 0 in shear, the energy
    released and the forces at the break."""
    return {
        "step": breaks.step.astype(np.int64), "time_s": breaks.time, strain_column: strain,
        "i": breaks.i.astype(np.int64), "j": breaks.j.astype(np.int64),
        "x_m": breaks.position[:, 0], "y_m": breaks.position[:, 1],
        "normal_x": breaks.normal[:, 0], "normal_y": breaks.normal[:, 1],
        "tension": (breaks.mode == "tension").astype(np.int8), "energy_j": breaks.energy,
        "normal_force_n": breaks.normal_force, "shear_force_n": breaks.shear_force, "moment_n_m": breaks.moment,
    }


def crack_task(results: Results, strain: str = "axial strain") -> FigureTask | None:
    """The crack map and rose (``fig20_cracks``) of a run with crack records, on its last
    snapshot's grains, titled with the run's last ``axial_strain`` (what it is: ``strain``);
    None without cracks."""
    if not results.cracks:
        return None
    from grainlab.plot.cracks import crack_figure
    from grainlab.plot.workers import FigureTask

    last = results.snapshot(-1)
    grains = np.asarray(last.is_sample)
    column = AXIAL_STRAIN if AXIAL_STRAIN in results.cracks else next(iter(set(results.cracks) - set(crack_units())))
    label = strain if column == AXIAL_STRAIN else column.replace("_", " ")
    title = f"Broken cement bonds to {100 * results.timeseries[column][-1]:.2f} % {label}"
    return FigureTask("fig20_cracks", crack_figure, (last.positions[grains], last.radii[grains], results.cracks, title))


class CrackRecords(Operation):
    """Writer: the bonds broken since its last act, appended to ``/cracks`` (after the
    step's record, so that each break's strain is the time series' ``strain`` column
    interpolated at its time: exact at a constant strain rate, the first record's for a
    break before the loading). ``strain_of(times)`` gives the strain at the breaks' times
    instead, and ``labels`` columns of one value each after the table's own."""

    def __init__(self, trigger: Trigger, writer: ResultsWriter, strain: str = AXIAL_STRAIN,
                 strain_of: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
                 labels: Mapping[str, int] | None = None) -> None:
        super().__init__(trigger)
        self.writer, self.strain, self.strain_of, self.labels = writer, strain, strain_of, dict(labels or {})

    def act(self, loading: Loading) -> None:
        breaks = loading.sim.take_bond_breaks()
        if len(breaks) == 0:
            return
        if self.strain_of is None:
            series = self.writer.read_timeseries((TIME_S, self.strain))
            strain = np.interp(breaks.time, series[TIME_S], series[self.strain])
        else:
            strain = self.strain_of(breaks.time)
        columns = {**crack_columns(breaks, strain, self.strain),
                   **{k: np.full(len(breaks), v) for k, v in self.labels.items()}}
        self.writer.append_cracks(columns, {**crack_units(self.strain), **dict.fromkeys(self.labels, "1")})


def crack_records(trigger: Trigger, writer: ResultsWriter, config: Config, strain: str = AXIAL_STRAIN) -> list[Operation]:
    """A cemented sample's :class:`CrackRecords` on ``trigger`` (put it after the
    records on the same trigger); none for an uncemented one."""
    return [CrackRecords(trigger, writer, strain)] if config.cement.bonds != "none" else []
