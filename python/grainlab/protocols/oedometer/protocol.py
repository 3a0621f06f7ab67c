"""The oedometer (K0) test as a protocol of the runner: the sample made and
consolidated as every test's (:mod:`grainlab.protocols.specimen`), then loaded
vertically between fixed side walls to each stress of a list, a record and a
snapshot at each equilibrium; :func:`run_oedometer` runs it into a folder."""

from __future__ import annotations

import dataclasses
import os
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from grainlab._progress import progress_bar
from grainlab.analysis.fragments import fragment_grading, fragment_labels
from grainlab.columns import OEDOMETER
from grainlab.io.walls import WallGeometry
from grainlab.protocols import operations
from grainlab.protocols.agglomerates import agglomerate_labels, agglomerate_sample
from grainlab.protocols.consolidate import BOX_WALLS, box_state
from grainlab.protocols.cracks import bonds_broken, crack_records, record_units
from grainlab.protocols.grains import grain_porosity
from grainlab.protocols.oedometer.config import OedometerConfig
from grainlab.protocols.oedometer.outputs import (
    FRAGMENTS_CSV,
    OedometerResult,
    fragment_sieves,
    summarise,
    write_outputs,
)
from grainlab.protocols.oedometer.state import OedometerRun
from grainlab.protocols.operations import Loading, Operation
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.specimen import (
    CHUNK_STEPS,
    CONSOLIDATE,
    OUTPUT_FILES,
    SpecimenError,
    SpecimenProtocol,
    grain_columns,
    grain_model,
    platen_model,
)
from grainlab.protocols.triggers import And, EveryStop, Flag, WallClock
from grainlab.simulation import Simulation, Wall
from grainlab.snapshot import ParticleKind

__all__ = ["FragmentGrading", "LoadSteps", "OedometerProtocol", "OedometerRun", "PlatenServo", "load_path",
           "run_oedometer"]

Context = StageContext[OedometerConfig, OedometerRun]


def load_path(config: OedometerConfig) -> list[float]:
    """The vertical stresses of the load steps: sigma_0 first (the state with
    friction on, from which strains count), then the configured ones."""
    return [config.consolidation.pressure, *config.oedometer.vertical_stresses]



def _confine(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    sim.set_contact_model(0, 0, grain_model(config))  # Table 1 friction from here on
    sim.set_contact_model(0, 1, platen_model(config))
    for name in BOX_WALLS:
        sim.wall(run.walls[name]).velocity = (0.0, 0.0)  # rigid and fixed; the top is servo-loaded
    run.max_vertical_stress_pa = config.consolidation.pressure
    run.load_start_step = sim.step_count


class PlatenServo(Operation):
    """Controller: the top platen servo-controlled to the load step's stress
    (``load_path(config)[run.next_load]``) over each chunk, at most ``max_speed_m_per_s``."""

    acts_before_run = True

    def __init__(self, walls: dict[str, Wall], stresses: list[float], run: OedometerRun, max_speed_m_per_s: float):
        super().__init__(EveryStop(CHUNK_STEPS))
        self.walls, self.stresses, self.run, self.max_speed = walls, stresses, run, max_speed_m_per_s

    def act(self, loading: Loading) -> None:
        box = box_state(self.walls)
        self.walls["top"].servo(self.stresses[self.run.next_load], box.width_m, relaxation=0.5,
                                max_speed_m_per_s=self.max_speed)


class LoadSteps(Operation):
    """After each chunk, whether the load step's stress is held within
    ``oedometer.tolerance`` in equilibrium: then the platen stops, the step's target is
    :attr:`target`, the run moves to the next step and :attr:`reached` fires (and
    :attr:`finished` after the last step); a step that takes ``oedometer.max_steps``
    stops the run with a :class:`SpecimenError`."""

    def __init__(self, walls: dict[str, Wall], stresses: list[float], run: OedometerRun, config: OedometerConfig,
                 step: int) -> None:
        super().__init__(EveryStop(CHUNK_STEPS))
        self.walls, self.stresses, self.run, self.config = walls, stresses, run, config
        self.started, self.target = step, stresses[run.next_load]
        self.reached, self.finished = Flag(), Flag()
        self.box = box_state(walls)

    def act(self, loading: Loading) -> None:
        sim, run, config = loading.sim, self.run, self.config
        target, limit = self.stresses[run.next_load], config.consolidation.unbalanced_force_ratio
        box = self.box = box_state(self.walls)
        if abs(box.stress_yy_pa / target - 1.0) < config.oedometer.tolerance and sim.unbalanced_force_ratio < limit:
            self.walls["top"].velocity = (0.0, 0.0)
            if run.next_load == 0:  # sigma_0 with friction on: strains count from here
                run.height0, run.area0 = box.height_m, box.width_m * box.height_m
            run.max_vertical_stress_pa = max(run.max_vertical_stress_pa, box.stress_yy_pa)
            self.target, self.started = target, sim.step_count
            run.next_load += 1
            self.reached.raise_at(sim.step_count)
            if run.next_load == len(self.stresses):
                self.finished.raise_at(sim.step_count)
        elif sim.step_count - self.started >= config.oedometer.max_steps:
            raise SpecimenError(
                f"load step {run.next_load} ({target / 1e3:.1f} kPa) did not reach equilibrium in "
                f"{sim.step_count - self.started} steps: sigma_v {box.stress_yy_pa / 1e3:.1f} kPa, unbalanced force "
                f"ratio {sim.unbalanced_force_ratio:.2e} (limit {limit:.0e}); raise oedometer.max_steps"
            )


def _load(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    walls = {name: sim.wall(run.walls[name]) for name in BOX_WALLS}
    stresses = load_path(config)
    if run.next_load == len(stresses):  # stopped after the last step's checkpoint
        return
    bar = progress_bar(len(stresses), "loading", enabled=context.progress, unit="step", initial=run.next_load)
    speed = 0.05 * config.sample.d_min / (100 * sim.time_step)  # at most d_min/20 per 100 steps
    steps = LoadSteps(walls, stresses, run, config, sim.step_count)
    geometry = {i: n for n, i in run.walls.items()}
    # a checkpoint at an equilibrium once run.checkpoint_interval has passed
    checkpoint = operations.Checkpoint(And(steps.reached, WallClock(config.run.checkpoint_interval)), context.save,
                            run.wall_time, "load")
    grading = [FragmentGrading(steps.reached, run, np.asarray(fragment_sieves(config)), steps)] if "agglomerates" in run.sample else []
    operations.run_loading(sim, [
        steps,
        operations.Records(steps.reached, context.writer, lambda: _record(sim, run, config, steps.target),
                           record_units(OEDOMETER, config)),
        *crack_records(steps.reached, context.writer, config),  # the breaks, after the record of their step
        *grading,
        operations.Snapshots(steps.reached, context.writer, lambda step: f"load_{run.next_load - 1:02d}", lambda: _snapshot(sim, run),
                  lambda: WallGeometry.from_simulation(sim, names=geometry)),
        operations.Progress(steps.reached, bar, lambda step: run.next_load, lambda: f"sigma_v {steps.box.stress_yy_pa / 1e3:.0f} "
                 f"kPa, K {steps.box.stress_xx_pa / steps.box.stress_yy_pa:.3f}", run.next_load),
        checkpoint,
        operations.Stop(steps.finished),
        PlatenServo(walls, stresses, run, speed),
    ], checkpoint, bar)


def _snapshot(sim: Simulation, run: OedometerRun) -> Any:
    kind = np.full(sim.n_particles, int(ParticleKind.SOIL), dtype=np.int8)
    box = box_state({name: sim.wall(run.walls[name]) for name in BOX_WALLS})
    scalars = {"axial_strain": (run.height0 - box.height_m) / run.height0, "vertical_stress_pa": box.stress_yy_pa,
               "horizontal_stress_pa": box.stress_xx_pa}
    snapshot = sim.snapshot(kind=kind, scalars=scalars, step=sim.step_count)
    if "agglomerates" not in run.sample:
        return snapshot
    fields = {"agglomerate": agglomerate_labels(run), "fragment": _fragments(sim)}  # each disk's
    return dataclasses.replace(snapshot, particle_fields={**snapshot.particle_fields, **fields})


def _fragments(sim: Simulation) -> NDArray[np.int64]:
    bonds = sim.cement_bonds()
    return fragment_labels(sim.n_particles, bonds.i, bonds.j)


class FragmentGrading(Operation):
    """Writer: at each load step's equilibrium, the fragments of a sample of agglomerates
    (the connected components of the intact bonds) and their grading, appended to the
    run's ``fragment_grading``."""

    def __init__(self, trigger: Flag, run: OedometerRun, sieves: NDArray[np.float64], steps: LoadSteps) -> None:
        super().__init__(trigger)
        self.run, self.sieves, self.steps = run, sieves, steps

    def act(self, loading: Loading) -> None:
        sim = loading.sim
        grading = fragment_grading(sim.radii, _fragments(sim), self.sieves)
        self.run.fragment_grading.append({"load_step": self.run.next_load - 1,
                                          "vertical_stress_pa": self.steps.box.stress_yy_pa, **grading})


def _record(sim: Simulation, run: OedometerRun, config: OedometerConfig, target: float) -> dict[str, float]:
    """One record at a load step's equilibrium, in :data:`grainlab.columns.OEDOMETER`'s order
    (a cemented sample's bonds broken after them)."""
    box = box_state({name: sim.wall(run.walls[name]) for name in BOX_WALLS})
    area = box.width_m * box.height_m
    n = run.n_grains
    porosity = grain_porosity(sim, n, area)
    values = {
        "step": float(sim.step_count), "time_s": sim.time, "target_vertical_stress_pa": target,
        "vertical_stress_pa": box.stress_yy_pa, "horizontal_stress_pa": box.stress_xx_pa,
        "lateral_stress_ratio": box.stress_xx_pa / box.stress_yy_pa,
        "max_vertical_stress_pa": run.max_vertical_stress_pa,
        "overconsolidation_ratio": run.max_vertical_stress_pa / box.stress_yy_pa,
        "axial_strain": (run.height0 - box.height_m) / run.height0,
        "volumetric_strain": (run.area0 - area) / run.area0,
        "porosity": porosity, "void_ratio": porosity / (1.0 - porosity), "height_m": box.height_m, "area_m2": area,
        **grain_columns(sim, n, area, sim.contacts(), _snapshot(sim, run)),
    }
    return {**{name: values[name] for name in OEDOMETER}, **bonds_broken(sim, run.consolidation, config)}


class OedometerProtocol(SpecimenProtocol[OedometerConfig, OedometerRun, OedometerResult]):
    """Confined (K0) compression: side walls fixed, the top platen servo-loaded to each vertical stress."""

    name = "oedometer"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        CONSOLIDATE,
        Stage("confine", _confine, "Table 1 friction on; the four walls fixed"),
        Stage("load", _load, "the top platen servo-controlled to sigma_0 (strains count from there), then to "
                             "each vertical stress in turn; a record and a snapshot at each equilibrium, a checkpoint there "
                             "once run.checkpoint_interval has passed"),
    )
    state_type = OedometerRun
    summarise = summarise
    outputs = write_outputs
    result_type = OedometerResult
    output_files = (*OUTPUT_FILES, FRAGMENTS_CSV)

    def start(self, threads: int, progress: bool) -> tuple[Simulation, OedometerRun]:
        """The sample generated; with ``sample.grains = agglomerate`` each grain then
        replaced by an agglomerate (:func:`grainlab.protocols.agglomerates.agglomerate_sample`)."""
        sim, run = super().start(threads, progress)
        if self.config.grain_kind.grains == "agglomerate":
            sim = agglomerate_sample(sim, run, self.config)
        return sim, run


def run_oedometer(config: OedometerConfig, out_dir: str | os.PathLike[str], *, resume: bool = False,
                  progress: bool = False) -> OedometerResult:
    """Runs (or, with ``resume``, continues) the oedometer test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`)."""
    return run_protocol(OedometerProtocol(config), out_dir, resume=resume, progress=progress)
