"""What the tests that press a cemented sample between two platens share (the
unconfined compression test and the Brazilian test, docs/cemented.md): the run
state's part of the loading (:class:`PlatenRun`), the sample settled on the platens
held still (:func:`release`), and the loading itself (:func:`press`): the top platen
down at a constant speed, the bottom one fixed, a record every ``final_strain /
records`` of strain with the crack records, the peak kept in the run state and the
end at the last record or at the first record after the peak whose stress is below
``residual_fraction`` of it."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from grainlab._progress import progress_bar
from grainlab.columns import AXIAL_STRAIN, Columns
from grainlab.io.walls import WallGeometry
from grainlab.protocols import operations
from grainlab.protocols.config import Config, PlatenSection
from grainlab.protocols.cracks import CrackRecords
from grainlab.protocols.operations import Loading, Operation, Records
from grainlab.protocols.runner import StageContext
from grainlab.protocols.specimen import CHUNK_STEPS, SpecimenRun, grain_model, platen_model
from grainlab.protocols.triggers import And, EveryStop, Flag, OnSteps, WallClock, schedule_steps
from grainlab.simulation import Simulation
from grainlab.snapshot import ParticleKind, Snapshot

__all__ = ["PeakWatch", "PlatenRun", "Press", "TopPlaten", "platen_snapshot", "platen_walls", "press",
           "record_steps", "release", "settle", "watch"]


@dataclass
class PlatenRun(SpecimenRun):
    """A platen test's run state (saved in every checkpoint): :class:`SpecimenRun`'s
    fields, the steps of the settling on the still platens, the step the loading started
    at (-1 before), the records taken, the peak so far (its stress, strain and record) and
    how the loading ended ("" while it runs, "final_strain" or "residual")."""

    release_steps: int = 0
    start_step: int = -1
    peak_stress_pa: float = 0.0
    peak_strain: float = 0.0
    peak_record: int = -1
    next_record: int = 0
    ended: str = ""


def release(sim: Simulation, config: Config, stage: str, platen_friction: float | None = None) -> int:
    """Table 1 friction on (between the grains, and at the platens unless
    ``platen_friction`` is given) and the sample settled, the platens held still, until
    the unbalanced force ratio is below ``consolidation.unbalanced_force_ratio`` (a
    warning after ``consolidation.max_steps``); returns the steps run."""
    platen = platen_model(config)
    sim.set_contact_model(0, 0, grain_model(config))  # Table 1 friction from here on
    sim.set_contact_model(0, 1, platen if platen_friction is None else replace(platen, friction=platen_friction))
    return settle(sim, config, stage)


def settle(sim: Simulation, config: Config, stage: str, settled: Callable[[], bool] = lambda: True,
           each_chunk: Callable[[], None] = lambda: None) -> int:
    """Chunks of steps (``each_chunk()`` before each) until ``settled()`` and the
    unbalanced force ratio is below ``consolidation.unbalanced_force_ratio``, or until
    ``consolidation.max_steps`` (a warning: the test goes on from there); the steps run."""
    limit, steps = config.consolidation.unbalanced_force_ratio, 0
    while True:
        each_chunk()
        sim.run(CHUNK_STEPS)
        steps += CHUNK_STEPS
        if sim.unbalanced_force_ratio < limit and settled():
            return steps
        if steps >= config.consolidation.max_steps:
            warnings.warn(f"{stage}: consolidation.max_steps reached with an unbalanced force ratio of "
                          f"{sim.unbalanced_force_ratio:.2e} (limit {limit:.0e}): the loading starts from there",
                          RuntimeWarning, stacklevel=3)
            return steps


def record_steps(loading: PlatenSection, time_step: float) -> list[int]:
    """The loading's record steps from its start: one every ``final_strain / records`` of
    strain (``strain_rate`` x the time step a step)."""
    return schedule_steps(loading.final_strain / loading.records, final=loading.final_strain,
                          steps_per_unit=1.0 / (loading.strain_rate * time_step))


def platen_walls(sim: Simulation, run: SpecimenRun) -> WallGeometry:
    """The run's walls by name, as a snapshot stores them."""
    return WallGeometry.from_simulation(sim, names={wall_id: name for name, wall_id in run.walls.items()})


def platen_snapshot(sim: Simulation, values: Mapping[str, float], scalars: Sequence[str]) -> Snapshot:
    """The state now, every particle a grain, with the record ``values``' strain and ``scalars``."""
    kind = np.full(sim.n_particles, int(ParticleKind.SOIL), dtype=np.int8)
    return sim.snapshot(kind=kind, axial_strain=values.get(AXIAL_STRAIN, 0.0),
                        scalars={k: values[k] for k in scalars if k in values}, step=sim.step_count)


class TopPlaten(Operation):
    """Controller: the top platen down at ``speed_m_per_s``, the bottom one fixed, over
    the steps ahead."""

    acts_before_run = True

    def __init__(self, run: SpecimenRun, speed_m_per_s: float) -> None:
        super().__init__(EveryStop())
        self.run, self.speed = run, speed_m_per_s

    def act(self, loading: Loading) -> None:
        loading.sim.wall(self.run.walls["top"]).velocity = (0.0, -self.speed)
        loading.sim.wall(self.run.walls["bottom"]).velocity = (0.0, 0.0)


class PeakWatch(Operation):
    """After each record: the peak of the record's ``stress`` so far kept in the run's
    state, and :attr:`ended` raised at the last record step or at the first record after
    the peak whose stress is below ``residual_fraction`` of the peak."""

    def __init__(self, trigger: OnSteps, run: PlatenRun, records: Records, stress: str, residual_fraction: float,
                 last_step: int) -> None:
        super().__init__(trigger)
        self.run, self.records, self.stress = run, records, stress
        self.fraction, self.last_step = residual_fraction, last_step
        self.ended = Flag()

    def act(self, loading: Loading) -> None:
        run, values, step = self.run, self.records.values, loading.sim.step_count
        watch(run, values[self.stress], values[AXIAL_STRAIN])
        residual = run.peak_record > 0 and values[self.stress] < self.fraction * run.peak_stress_pa
        if residual or step >= self.last_step:
            run.ended = "residual" if residual else "final_strain"
            self.ended.raise_at(step)


def watch(run: PlatenRun, stress: float, strain: float) -> None:
    """The record just taken (the run's ``next_record - 1``) becomes the peak if its stress is the highest."""
    if run.peak_record < 0 or stress > run.peak_stress_pa:
        run.peak_stress_pa, run.peak_strain, run.peak_record = stress, strain, run.next_record - 1


@dataclass(frozen=True)
class Press:
    """What a platen test's loading records: ``measure()`` in ``columns``, whose ``stress``
    column the peak and the residual drop watch, ``snapshot()`` at the start and the end,
    the progress bar's ``label`` and its text beside it from the last record (``postfix``)."""

    measure: Callable[[], dict[str, float]]
    columns: Columns
    stress: str
    snapshot: Callable[[], Snapshot]
    label: str
    postfix: Callable[[Mapping[str, float]], str]


def press(context: StageContext[Any, Any], loading: PlatenSection, speed_m_per_s: float, what: Press) -> None:
    """The loading of the run in ``context`` (its state a :class:`PlatenRun`): the top
    platen down at ``speed_m_per_s`` from the step it starts at, records on
    :func:`record_steps` with the crack records, the ``start`` snapshot and record first
    and the ``end`` snapshot where the loading ends; a checkpoint on a record step once
    ``run.checkpoint_interval`` has passed (a resumed run goes on from there)."""
    sim, run = context.sim, context.state
    if run.ended:  # stopped after the last record's checkpoint
        return
    if run.start_step < 0:
        run.start_step = sim.step_count
    steps = record_steps(loading, sim.time_step)
    scheduled = OnSteps(steps, run.start_step)
    records = Records(scheduled, context.writer, what.measure, what.columns.units(), count=run)
    peak = PeakWatch(scheduled, run, records, what.stress, loading.residual_fraction, run.start_step + steps[-1])
    snapshots = operations.Snapshots(peak.ended, context.writer, lambda step: "end", what.snapshot,
                                     lambda: platen_walls(sim, run))
    if run.next_record == 0:  # the start: its record and snapshot
        records.write(sim.step_count)
        run.next_record = 1
        watch(run, records.values[what.stress], records.values[AXIAL_STRAIN])
        snapshots.store("start", sim.step_count)
    final = loading.final_strain
    done = 100 * final * (sim.step_count - run.start_step) / steps[-1]
    bar = progress_bar(round(100 * final, 3), what.label, enabled=context.progress, unit="% strain",
                       initial=done, bar_format="{l_bar}{bar}| {n:.2f}/{total:.1f} % [{elapsed}<{remaining}{postfix}]")
    checkpoint = operations.Checkpoint(And(scheduled, WallClock(context.config.run.checkpoint_interval)),
                                       context.save, run.wall_time, run.phase)
    operations.run_loading(sim, [
        records,
        CrackRecords(scheduled, context.writer),  # the breaks, after the record of their step
        peak,
        snapshots,
        operations.Progress(scheduled, bar, lambda step: 100 * final * (step - run.start_step) / steps[-1],
                            lambda: what.postfix(records.values), done),
        checkpoint,
        operations.Stop(peak.ended),
        TopPlaten(run, speed_m_per_s),
    ], checkpoint, bar)

