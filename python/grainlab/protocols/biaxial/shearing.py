"""The shearing of the biaxial and cyclic tests as a loading
(:mod:`grainlab.protocols.operations`): the platens driven as planned
(:func:`~grainlab.protocols.biaxial.phases.start_platens`) while the records,
the snapshots, the lateral boundary's upkeep, the platens' turns, the progress
and the checkpoints act on their triggers; rigid side walls are controlled
every :data:`WALL_CONTROL_STEPS` steps."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

from grainlab._progress import progress_bar
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO
from grainlab.protocols.biaxial.config import BiaxialConfig
from grainlab.protocols.biaxial.phases import drive_platens
from grainlab.protocols.biaxial.records import take_snapshot, wall_geometry
from grainlab.protocols.biaxial.state import BiaxialError, BiaxialRun, ShearPlan
from grainlab.protocols.boundary import GrainBoundary, Membrane, WallBoundary, membrane_breach
from grainlab.protocols.cracks import crack_records
from grainlab.protocols.operations import (
    Checkpoint,
    Loading,
    Operation,
    Progress,
    Records,
    Snapshots,
    Stop,
    run_loading,
)
from grainlab.protocols.runner import StageContext
from grainlab.protocols.triggers import And, EveryStop, OnSteps, Trigger, WallClock
from grainlab.simulation import Simulation

__all__ = ["WALL_CONTROL_STEPS", "BoundaryUpkeep", "NextTurn", "PlatenTurns", "ShearContext", "SideWalls",
           "reverse_platens", "shear", "shear_records", "shear_snapshots"]

BC = TypeVar("BC", bound=BiaxialConfig)

#: Steps between two settings of rigid side walls' motion while shearing (variant C).
WALL_CONTROL_STEPS = 100

#: A shearing stage's context: the biaxial or the cyclic test's.
ShearContext = StageContext[BC, BiaxialRun]


def reverse_platens(sim: Simulation, run: BiaxialRun) -> None:
    """The platens reversed at the plan's next turn: compression after an even number of
    turns, extension after an odd one."""
    plan = run.shear_plan()
    plan.next_turn += 1
    drive_platens(sim, run.lateral_boundary(), plan.platen_speed_m_per_s * (-1.0) ** plan.next_turn)


class NextTurn(Trigger):
    """Fires at the plan's next turning point (``turn_steps`` from ``next_turn`` on)."""

    def __init__(self, plan: ShearPlan) -> None:
        self.plan = plan

    def _ahead(self) -> list[int]:
        return [self.plan.start_step + s for s in self.plan.turn_steps[self.plan.next_turn:]]

    def __call__(self, step: int) -> bool:
        return self._ahead()[:1] == [step]

    def next_step(self, step: int) -> int | None:
        return next((s for s in self._ahead() if s > step), None)


class PlatenTurns(Operation):
    """Controller: the platens reversed at each planned turning point (a cyclic test's)."""

    def __init__(self, run: BiaxialRun) -> None:
        super().__init__(NextTurn(run.shear_plan()))
        self.run = run

    def act(self, loading: Loading) -> None:
        reverse_platens(loading.sim, self.run)


class SideWalls(Operation):
    """Controller: rigid side walls' motion set for the steps ahead (:meth:`WallBoundary.control`:
    the sample's area held at constant volume, sigma_0 drained)."""

    acts_before_run = True

    def __init__(self, walls: WallBoundary, area0: float, max_speed_m_per_s: float) -> None:
        super().__init__(EveryStop(WALL_CONTROL_STEPS))
        self.walls, self.area0, self.max_speed = walls, area0, max_speed_m_per_s

    def act(self, loading: Loading) -> None:
        self.walls.control(loading.sim, loading.next_stop - loading.sim.step_count, self.area0, self.max_speed)


class BoundaryUpkeep(Operation):
    """The lateral boundary kept: variant B's outer grains identified again; the membrane
    checked whole (a breach stops the run with a :class:`BiaxialError`)."""

    def __init__(self, trigger: Trigger, run: BiaxialRun, records: Records) -> None:
        super().__init__(trigger)
        self.run, self.records = run, records

    def act(self, loading: Loading) -> None:
        boundary = self.run.lateral_boundary()
        if isinstance(boundary, GrainBoundary):
            self.run.boundary = boundary.identify(loading.sim)
        elif isinstance(boundary, Membrane):
            breach = membrane_breach(loading.sim, boundary)
            if breach is not None:
                raise BiaxialError(
                    f"shearing stopped at {100 * self.records.values[AXIAL_STRAIN]:.2f} % axial strain: {breach}"
                )


def shear_records(context: ShearContext[BC], measure: Callable[[], dict[str, float]],
                  units: dict[str, str]) -> Records:
    """The shearing's records: ``measure()`` on each planned record step."""
    plan = context.state.shear_plan()
    return Records(OnSteps(plan.record_steps, plan.start_step), context.writer, measure, units, count=plan)


def shear_snapshots(context: ShearContext[BC], records: Records, name_of: Callable[[float], str]) -> Snapshots:
    """The shearing's snapshots: on each planned snapshot step, named ``name_of(path strain)``."""
    sim, run = context.sim, context.state
    plan = run.shear_plan()
    strains = {plan.start_step + int(step): strain for step, strain in plan.snapshot_steps.items()}
    return Snapshots(OnSteps(strains), context.writer, lambda step: name_of(strains[step]),
                     lambda: take_snapshot(sim, run, records.values[AXIAL_STRAIN]), lambda: wall_geometry(sim, run))


def shear(context: ShearContext[BC], records: Records, snapshots: Snapshots, *, final: float,
          first: Sequence[Operation] = ()) -> None:
    """Runs the planned shearing to its end, ``final`` of path strain (the progress
    counts to it): the operations ``first`` (a stress-controlled test's cycles), then on
    each record step the record, the snapshot, the boundary's upkeep, the platens' turn,
    the progress and a checkpoint once ``run.checkpoint_interval`` has passed; the loading
    ends at the last record. A new shearing first records its start and stores it."""
    sim, run = context.sim, context.state
    plan = run.shear_plan()
    steps = plan.record_steps
    if plan.next_record == 0 and "0" in plan.snapshot_steps and context.writer.n_rows == 0:
        records.write(sim.step_count)
        snapshots.store(snapshots.name_of(sim.step_count), sim.step_count)
    scheduled = OnSteps(steps, plan.start_step)
    done = 100 * final * steps[plan.next_record - 1] / steps[-1] if plan.next_record and steps[-1] else 0.0
    bar = progress_bar(round(100 * final, 3), "shearing", enabled=context.progress, unit="% strain", initial=done,
                       bar_format="{l_bar}{bar}| {n:.2f}/{total:.1f} % [{elapsed}<{remaining}{postfix}]")
    checkpoint = Checkpoint(And(scheduled, WallClock(context.config.run.checkpoint_interval)), context.save,
                            run.wall_time, "shear")
    # a cemented sample's breaks, stored after the record of their step
    cracks = crack_records(scheduled, context.writer, context.config)
    operations = [
        *first, records, *cracks, snapshots, BoundaryUpkeep(scheduled, run, records), PlatenTurns(run),
        Progress(scheduled, bar, lambda step: 100 * final * (step - plan.start_step) / steps[-1],
                 lambda: f"ratio {records.values[STRESS_RATIO]:.2f}", done),
        checkpoint, Stop(OnSteps(steps[-1:], plan.start_step)),
    ]
    boundary = run.lateral_boundary()
    if isinstance(boundary, WallBoundary):
        speed = 0.05 * float(sim.radii[: run.n_grains].min()) / (50 * sim.time_step)
        operations.append(SideWalls(boundary, plan.area0, speed))
    run_loading(sim, operations, checkpoint, bar)
