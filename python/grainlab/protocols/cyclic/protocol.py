"""The cyclic biaxial test as a protocol of the runner: the biaxial test's sample,
consolidation and flexible boundary, then the platens driven between +/- A in
strain or, with ``cyclic.control = "stress"``, in the deviator q, for
``cyclic.cycles`` cycles (docs/protocols.md, "The cyclic biaxial test");
:func:`run_cyclic` runs it into a folder."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any, ClassVar

from grainlab.columns import CYCLE, CYCLIC, STRAIN_PATH
from grainlab.protocols.biaxial import records as biaxial_records
from grainlab.protocols.biaxial.phases import check_shear_plan, install_boundary, start_platens
from grainlab.protocols.biaxial.rates import check_density_scaling, check_strain_rate
from grainlab.protocols.biaxial.shearing import (
    WALL_CONTROL_STEPS,
    reverse_platens,
    shear,
    shear_records,
    shear_snapshots,
)
from grainlab.protocols.biaxial.state import BiaxialRun
from grainlab.protocols.cracks import record_units
from grainlab.protocols.cyclic.config import CyclicConfig
from grainlab.protocols.cyclic.outputs import CyclicResult, summarise, write_outputs
from grainlab.protocols.operations import Loading, Operation, Records, Snapshots
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.specimen import CONSOLIDATE, SpecimenProtocol
from grainlab.protocols.triggers import EveryStop
from grainlab.simulation import Simulation

__all__ = ["STRESS_EVENTS", "CyclicProtocol", "StressCycles", "cycle_plan", "event_snapshot_name", "run_cyclic",
           "snapshot_name_of", "stress_path_length"]

Context = StageContext[CyclicConfig, BiaxialRun]


def cycle_plan(amplitude: float, cycles: int) -> tuple[float, list[float], list[float]]:
    """The loading in strain path (axial strain travelled): its length ``4 A N``, the
    turning points ``A, 3A, 5A, ..., (4N - 1) A`` and the snapshots (the start, the
    first and last cycles' turning points, every cycle's end).

    >>> cycle_plan(0.01, 2)
    (0.08, [0.01, 0.03, 0.05, 0.07], [0.0, 0.01, 0.03, 0.04, 0.05, 0.07, 0.08])
    """
    a = amplitude
    turns = [round((2 * k + 1) * a, 12) for k in range(2 * cycles)]
    ends = [round(4 * a * k, 12) for k in range(1, cycles + 1)]
    peaks = turns[:2] + turns[-2:]
    return round(4 * a * cycles, 12), turns, sorted({0.0, *peaks, *ends})


def snapshot_name_of(amplitude: float) -> Callable[[float], str]:
    """The snapshot name of a path strain: ``start``, ``cycle_003_compression`` (its
    compression turning point), ``cycle_003_extension``, ``cycle_003_end``."""

    def name(path: float) -> str:
        quarter = round(path / amplitude)
        if quarter == 0:
            return "start"
        cycle, where = divmod(quarter, 4)
        if where == 0:
            return f"cycle_{cycle:03d}_end"
        return f"cycle_{cycle + 1:03d}_{'compression' if where == 1 else 'extension'}"

    return name



#: What each event of a stress-controlled cycle is, in order.
STRESS_EVENTS = ("compression", "unloaded", "extension", "end")


def stress_path_length(config: CyclicConfig) -> float:
    """The strain path a stress-controlled test may travel at most: every cycle's
    quarters at the strain limit."""
    return float(4 * config.cyclic.cycles * config.cyclic.strain_limit)


def event_snapshot_name(event: int, cycles: int) -> str | None:
    """The snapshot of a stress-controlled test's event ``event`` (1, 2, ...): the first and
    last cycles' turning points and every cycle's end, named as the strain-controlled test's."""
    cycle, what = (event - 1) // 4 + 1, STRESS_EVENTS[(event - 1) % 4]
    if what == "end" or (what != "unloaded" and cycle in (1, cycles)):
        return f"cycle_{cycle:03d}_{what}"
    return None


class StressCycles(Operation):
    """A stress-controlled test's cycles, every WALL_CONTROL_STEPS steps: the platens load
    until q reaches +A_q (a turn), unload through q = 0 (an event) to -A_q (a turn) and
    load back to q = 0 (an event, or the end after the last cycle); the loading also
    ends where the axial strain reaches +/- ``cyclic.strain_limit``. Each event is
    counted in the plan (``events``), recorded and stored as a snapshot when
    :func:`event_snapshot_name` names one; the platens reverse at a turn."""

    def __init__(self, config: CyclicConfig, run: BiaxialRun, records: Records, snapshots: Snapshots) -> None:
        super().__init__(EveryStop(WALL_CONTROL_STEPS))
        self.config, self.run, self.records, self.snapshots = config, run, records, snapshots

    def _event(self, sim: Simulation) -> tuple[bool, bool] | None:
        """(whether the platens turn, whether the loading ends) at an event; None between events."""
        plan, config = self.run.shear_plan(), self.config
        boundary = self.run.lateral_boundary()
        height = float(sim.wall(boundary.top_wall).points[0, 1] - sim.wall(boundary.bottom_wall).points[0, 1])
        if abs((plan.height0 - height) / plan.height0) >= config.cyclic.strain_limit:
            return False, True
        q, amplitude = biaxial_records.deviator_stress(sim, self.run, config), float(config.cyclic.stress_amplitude)
        quarter = plan.events % 4
        if quarter == 0 and q >= amplitude or quarter == 2 and q <= -amplitude:
            return True, False
        if quarter == 1 and q <= 0.0:
            return False, False
        if quarter == 3 and q >= 0.0:
            return False, plan.events + 1 == 4 * config.cyclic.cycles
        return None

    def act(self, loading: Loading) -> None:
        sim, plan = loading.sim, self.run.shear_plan()
        event = self._event(sim)
        if event is None:
            return
        turn, end = event
        plan.events += 1
        if turn:
            plan.turn_steps.append(sim.step_count - plan.start_step)
            reverse_platens(sim, self.run)
        self.records.write(sim.step_count)
        name = event_snapshot_name(plan.events, self.config.cyclic.cycles)
        if name is not None:
            self.snapshots.store(name, sim.step_count)
        if end:
            plan.next_record = len(plan.record_steps)
            loading.stop()


def _boundary(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    install_boundary(sim, run, config, context.progress)
    if config.cyclic.control == "stress":
        start_platens(sim, run, config, final=stress_path_length(config), snapshots=[0.0])
        check_shear_plan(sim, run, config, [0.0], key="cyclic.stress_amplitude")
        return
    final, turns, snapshots = cycle_plan(config.cyclic.strain_amplitude, config.cyclic.cycles)
    start_platens(sim, run, config, final=final, snapshots=snapshots, turns=turns)
    check_shear_plan(sim, run, config, snapshots, key="cyclic.strain_amplitude")


def _cycle(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    amplitude = config.cyclic.strain_amplitude
    plan = run.shear_plan()
    strain_per_step = plan.strain_rate * sim.time_step
    stress = config.cyclic.control == "stress"

    def measure() -> dict[str, float]:
        travelled = (sim.step_count - plan.start_step) * strain_per_step
        cycle = plan.events / 4.0 if stress else travelled / (4.0 * amplitude)
        return {**biaxial_records.measure(sim, run, config), STRAIN_PATH: travelled, CYCLE: cycle}

    records = shear_records(context, measure, record_units(CYCLIC, config))
    if stress:
        snapshots = shear_snapshots(context, records, lambda path: "start")
        shear(context, records, snapshots, final=stress_path_length(config),
              first=[StressCycles(config, run, records, snapshots)])
        return
    final, _, _ = cycle_plan(amplitude, config.cyclic.cycles)
    shear(context, records, shear_snapshots(context, records, snapshot_name_of(amplitude)), final=final)


class CyclicProtocol(SpecimenProtocol[CyclicConfig, BiaxialRun, CyclicResult]):
    """The cyclic biaxial test (strain amplitude, N cycles, constant confining pressure)."""

    name = "cyclic"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        CONSOLIDATE,
        Stage("boundary", _boundary, "the side walls replaced by the membrane (or the outer grains) under "
                                     "sigma_0, the sample re-equilibrated, the cycles planned"),
        Stage("shear", _cycle, "the platens between +/- the amplitude, N cycles; records and snapshots on "
                               "their triggers, checkpoints on the wall clock"),
    )
    state_type = BiaxialRun
    summarise = summarise
    outputs = write_outputs
    result_type = CyclicResult

    def check(self) -> None:
        check_strain_rate(self.config)
        check_density_scaling(self.config)


def run_cyclic(config: CyclicConfig, out_dir: str | os.PathLike[str], *, resume: bool = False,
               progress: bool = False) -> CyclicResult:
    """Runs (or, with ``resume``, continues) the cyclic biaxial test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`)."""
    return run_protocol(CyclicProtocol(config), out_dir, resume=resume, progress=progress)
