"""The unconfined compression test (UCS) of a cemented sample as a protocol of the
runner: the sample made and consolidated as every test's and cemented at the end of
the consolidation (:mod:`grainlab.protocols.specimen`), released (the side walls
removed, the platens held still, Table 1 friction on) and settled, seated (the top
platen servo-controlled to ``ucs.seating_stress``), then compressed
by the top platen at a constant strain rate, the bottom one fixed, until
``ucs.final_strain`` or until the axial stress falls below ``ucs.residual_fraction``
of its peak; :func:`run_ucs` runs it into a folder (docs/cemented.md, "The
unconfined compression test")."""

from __future__ import annotations

import os
import time
from typing import Any, ClassVar

import numpy as np

from grainlab.columns import AXIAL_STRESS_PA, LATERAL_STRAIN, UCS
from grainlab.protocols.consolidate import long_platens
from grainlab.protocols.cracks import broken_since
from grainlab.protocols.platens import Press, platen_snapshot, press, release, settle
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.specimen import CONSOLIDATE, SpecimenProtocol, engine_columns
from grainlab.protocols.ucs.config import UcsConfig
from grainlab.protocols.ucs.outputs import UcsResult, summarise, write_outputs
from grainlab.protocols.ucs.state import UcsRun
from grainlab.simulation import Simulation

__all__ = ["UcsProtocol", "UcsRun", "measure", "run_ucs", "sample_width"]

Context = StageContext[UcsConfig, UcsRun]


def sample_width(sim: Simulation, run: UcsRun) -> float:
    """The grains' width over the middle half of the height between the platens:
    max(x + r) - min(x - r) of the grains whose centre lies there and that the sample
    holds (an intact cement bond or a contact with another grain: a grain the release
    or a break set free and that drifts away is not the sample's width), m."""
    n = run.n_grains
    bottom = float(sim.wall(run.walls["bottom"]).points[0, 1])
    top = float(sim.wall(run.walls["top"]).points[0, 1])
    quarter = 0.25 * (top - bottom)
    x, r = sim.positions[:n], sim.radii[:n]
    contacts, bonds = sim.contacts(), sim.cement_bonds()
    held = np.zeros(sim.n_particles, dtype=bool)
    for ends in (contacts.i, contacts.j, bonds.i, bonds.j):
        held[np.asarray(ends, dtype=np.int64)] = True
    middle = held[:n] & (x[:, 1] >= bottom + quarter) & (x[:, 1] <= top - quarter)
    return float(np.max(x[middle, 0] + r[middle]) - np.min(x[middle, 0] - r[middle]))


def _height(sim: Simulation, run: UcsRun) -> float:
    return float(sim.wall(run.walls["top"]).points[0, 1] - sim.wall(run.walls["bottom"]).points[0, 1])


def measure(sim: Simulation, run: UcsRun) -> dict[str, float]:
    """One record of the compression, in :data:`grainlab.columns.UCS`'s order."""
    width, height = sample_width(sim, run), _height(sim, run)
    values = {
        "step": float(sim.step_count), "time_s": sim.time,
        "axial_strain": (run.height0 - height) / run.height0,
        "axial_stress_pa": sim.wall(run.walls["top"]).normal_stress(width),
        "lateral_strain": (width - run.width0) / run.width0, "width_m": width, "height_m": height,
        **engine_columns(sim),
        "cement_bonds_broken": broken_since(sim, run.consolidation),
    }
    return {name: values[name] for name in UCS}


def _release(context: Context) -> None:
    """Table 1 friction on; the box's walls replaced by platens three sample widths long
    (none at the sides), held still; the sample settled."""
    sim, run, config = context.sim, context.state, context.config
    start = time.perf_counter()
    long_platens(sim, run.walls)
    run.release_steps = release(sim, config, "release")
    run.consolidation["release_steps"] = run.release_steps
    run.wall_time["release"] = time.perf_counter() - start


def _seat(context: Context) -> None:
    """The top platen servo-controlled to ``ucs.seating_stress`` over the sample's width
    until it holds it within a tenth in equilibrium, then stopped; the sample's height
    and width there are the strains' references."""
    sim, run, config = context.sim, context.state, context.config
    start = time.perf_counter()
    target, top = config.ucs.seating_stress, sim.wall(run.walls["top"])
    speed = 0.05 * config.sample.d_min / (100 * sim.time_step)  # at most d_min/20 per 100 steps

    def servo() -> None:
        top.servo(target, sample_width(sim, run), relaxation=0.5, max_speed_m_per_s=speed)

    run.seating_steps = settle(sim, config, "seating",
                               lambda: abs(top.normal_stress(sample_width(sim, run)) - target) <= 0.1 * target, servo)
    top.velocity = (0.0, 0.0)
    run.height0, run.width0 = _height(sim, run), sample_width(sim, run)
    run.consolidation["seating_steps"] = run.seating_steps
    run.wall_time["seat"] = time.perf_counter() - start


def _compress(context: Context) -> None:
    """The top platen down at ``ucs.strain_rate`` x H0 (:func:`~grainlab.protocols.platens.press`)."""
    sim, run, config = context.sim, context.state, context.config
    press(context, config.ucs, config.ucs.strain_rate * run.height0, Press(
        lambda: measure(sim, run), UCS, AXIAL_STRESS_PA,
        lambda: platen_snapshot(sim, measure(sim, run), (AXIAL_STRESS_PA, LATERAL_STRAIN)), "compressing",
        lambda values: f"sigma_1 {values[AXIAL_STRESS_PA] / 1e3:.0f} kPa"))


class UcsProtocol(SpecimenProtocol[UcsConfig, UcsRun, UcsResult]):
    """Unconfined compression of a cemented sample: no side walls, the top platen at a constant strain rate."""

    name = "ucs"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        CONSOLIDATE,
        Stage("release", _release, "Table 1 friction on; the side walls removed, the platens held still; settled "
                                   "until the unbalanced force ratio is below consolidation.unbalanced_force_ratio"),
        Stage("seat", _seat, "the top platen servo-controlled to ucs.seating_stress until it holds it within a tenth "
                             "in equilibrium; the strains count from there"),
        Stage("compress", _compress, "the top platen down at ucs.strain_rate, the bottom one fixed; a record every "
                                     "ucs.final_strain / ucs.records of strain, to ucs.final_strain or the residual "
                                     "drop; a checkpoint on a record step once run.checkpoint_interval has passed"),
    )
    state_type = UcsRun
    summarise = summarise
    outputs = write_outputs
    result_type = UcsResult


def run_ucs(config: UcsConfig, out_dir: str | os.PathLike[str], *, resume: bool = False,
            progress: bool = False) -> UcsResult:
    """Runs (or, with ``resume``, continues) the unconfined compression test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`)."""
    return run_protocol(UcsProtocol(config), out_dir, resume=resume, progress=progress)
