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
import warnings
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from grainlab._progress import progress_bar
from grainlab.columns import AXIAL_STRAIN, AXIAL_STRESS_PA, UCS
from grainlab.io.walls import WallGeometry
from grainlab.protocols import operations
from grainlab.protocols.consolidate import long_platens
from grainlab.protocols.cracks import CrackRecords
from grainlab.protocols.operations import Loading, Operation, Records
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.specimen import (
    CHUNK_STEPS,
    CONSOLIDATE,
    SpecimenProtocol,
    engine_columns,
    grain_model,
    platen_model,
)
from grainlab.protocols.triggers import And, EveryStop, Flag, OnSteps, WallClock, schedule_steps
from grainlab.protocols.ucs.config import UcsConfig
from grainlab.protocols.ucs.outputs import UcsResult, summarise, write_outputs
from grainlab.protocols.ucs.state import UcsRun
from grainlab.simulation import Simulation
from grainlab.snapshot import ParticleKind, Snapshot

__all__ = ["PeakWatch", "TopPlaten", "UcsProtocol", "UcsRun", "measure", "record_steps", "run_ucs", "sample_width"]

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
        "cement_bonds_broken": float(run.consolidation["cement_bonds"] - sim.n_cement_bonds),
    }
    return {name: values[name] for name in UCS}


def _snapshot(sim: Simulation, run: UcsRun) -> Snapshot:
    kind = np.full(sim.n_particles, int(ParticleKind.SOIL), dtype=np.int8)
    values = measure(sim, run) if run.height0 > 0 else {}
    scalars = {k: values[k] for k in ("axial_stress_pa", "lateral_strain") if k in values}
    return sim.snapshot(kind=kind, axial_strain=values.get("axial_strain", 0.0), scalars=scalars,
                        step=sim.step_count)


def _walls(sim: Simulation, run: UcsRun) -> WallGeometry:
    return WallGeometry.from_simulation(sim, names={wall_id: name for name, wall_id in run.walls.items()})


def _settle(sim: Simulation, config: UcsConfig, what: str, settled: Callable[[], bool],
            each_chunk: Callable[[], None] = lambda: None) -> int:
    """Chunks of steps until ``settled()`` and the unbalanced force ratio is below
    ``consolidation.unbalanced_force_ratio``, or until ``consolidation.max_steps`` (a
    warning: the test goes on from there); the steps run."""
    limit, steps = config.consolidation.unbalanced_force_ratio, 0
    while True:
        each_chunk()
        sim.run(CHUNK_STEPS)
        steps += CHUNK_STEPS
        if sim.unbalanced_force_ratio < limit and settled():
            return steps
        if steps >= config.consolidation.max_steps:
            warnings.warn(f"{what}: consolidation.max_steps reached with an unbalanced force ratio of "
                          f"{sim.unbalanced_force_ratio:.2e} (limit {limit:.0e}): the compression starts from there",
                          RuntimeWarning, stacklevel=3)
            return steps


def _release(context: Context) -> None:
    """Table 1 friction on; the box's walls replaced by platens three sample widths long
    (none at the sides), held still; the sample settled."""
    sim, run, config = context.sim, context.state, context.config
    start = time.perf_counter()
    long_platens(sim, run.walls)
    sim.set_contact_model(0, 0, grain_model(config))  # Table 1 friction from here on
    sim.set_contact_model(0, 1, platen_model(config))
    run.release_steps = _settle(sim, config, "release", lambda: True)
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

    run.seating_steps = _settle(sim, config, "seating",
                                lambda: abs(top.normal_stress(sample_width(sim, run)) - target) <= 0.1 * target,
                                servo)
    top.velocity = (0.0, 0.0)
    run.height0, run.width0 = _height(sim, run), sample_width(sim, run)
    run.consolidation["seating_steps"] = run.seating_steps
    run.wall_time["seat"] = time.perf_counter() - start


def record_steps(config: UcsConfig, time_step: float) -> list[int]:
    """The compression's record steps from its start: one every ``ucs.final_strain /
    ucs.records`` of axial strain (``ucs.strain_rate`` x the time step a step)."""
    c = config.ucs
    return schedule_steps(c.final_strain / c.records, final=c.final_strain,
                          steps_per_unit=1.0 / (c.strain_rate * time_step))


class TopPlaten(Operation):
    """Controller: the top platen down at ``ucs.strain_rate`` x the height after the
    seating, the bottom one fixed, over the steps ahead."""

    acts_before_run = True

    def __init__(self, run: UcsRun, speed_m_per_s: float) -> None:
        super().__init__(EveryStop())
        self.run, self.speed = run, speed_m_per_s

    def act(self, loading: Loading) -> None:
        loading.sim.wall(self.run.walls["top"]).velocity = (0.0, -self.speed)
        loading.sim.wall(self.run.walls["bottom"]).velocity = (0.0, 0.0)


class PeakWatch(Operation):
    """After each record: the peak so far kept in the run's state, and :attr:`ended`
    raised at the last record step or at the first record after the peak whose axial
    stress is below ``residual_fraction`` of the peak."""

    def __init__(self, trigger: OnSteps, run: UcsRun, records: Records, residual_fraction: float,
                 last_step: int) -> None:
        super().__init__(trigger)
        self.run, self.records, self.fraction, self.last_step = run, records, residual_fraction, last_step
        self.ended = Flag()

    def act(self, loading: Loading) -> None:
        run, values, step = self.run, self.records.values, loading.sim.step_count
        watch(run, values[AXIAL_STRESS_PA], values[AXIAL_STRAIN])
        residual = run.peak_record > 0 and values[AXIAL_STRESS_PA] < self.fraction * run.peak_stress_pa
        if residual or step >= self.last_step:
            run.ended = "residual" if residual else "final_strain"
            self.ended.raise_at(step)


def watch(run: UcsRun, stress: float, strain: float) -> None:
    """The record just taken (the run's ``next_record - 1``) becomes the peak if its stress is the highest."""
    if run.peak_record < 0 or stress > run.peak_stress_pa:
        run.peak_stress_pa, run.peak_strain, run.peak_record = stress, strain, run.next_record - 1


def _compress(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    if run.ended:  # stopped after the last record's checkpoint
        return
    if run.start_step < 0:
        run.start_step = sim.step_count
    steps = record_steps(config, sim.time_step)
    speed = config.ucs.strain_rate * run.height0
    scheduled = OnSteps(steps, run.start_step)
    records = Records(scheduled, context.writer, lambda: measure(sim, run), UCS.units(), count=run)
    peak = PeakWatch(scheduled, run, records, config.ucs.residual_fraction, run.start_step + steps[-1])
    snapshots = operations.Snapshots(peak.ended, context.writer, lambda step: "end", lambda: _snapshot(sim, run),
                                     lambda: _walls(sim, run))
    if run.next_record == 0:  # the start: its record and snapshot
        records.write(sim.step_count)
        run.next_record = 1
        watch(run, records.values[AXIAL_STRESS_PA], records.values[AXIAL_STRAIN])
        snapshots.store("start", sim.step_count)
    final = config.ucs.final_strain
    done = 100 * final * (sim.step_count - run.start_step) / steps[-1]
    bar = progress_bar(round(100 * final, 3), "compressing", enabled=context.progress, unit="% strain",
                       initial=done, bar_format="{l_bar}{bar}| {n:.2f}/{total:.1f} % [{elapsed}<{remaining}{postfix}]")
    checkpoint = operations.Checkpoint(And(scheduled, WallClock(config.run.checkpoint_interval)), context.save,
                                       run.wall_time, "compress")
    operations.run_loading(sim, [
        records,
        CrackRecords(scheduled, context.writer),  # the breaks, after the record of their step
        peak,
        snapshots,
        operations.Progress(scheduled, bar, lambda step: 100 * final * (step - run.start_step) / steps[-1],
                            lambda: f"sigma_1 {records.values[AXIAL_STRESS_PA] / 1e3:.0f} kPa", done),
        checkpoint,
        operations.Stop(peak.ended),
        TopPlaten(run, speed),
    ], checkpoint, bar)


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
