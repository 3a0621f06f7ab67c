"""Periodic simple shear as a protocol of the runner: the sample made as every
test's, consolidated in a periodic cell of its box and sheared at a constant
rate to large strain (docs/protocols.md, "Periodic simple shear");
:func:`run_simple_shear` runs it into a folder."""

from __future__ import annotations

import math
import os
import time
from typing import Any, ClassVar

import numpy as np

from grainlab._progress import progress_bar
from grainlab.analysis import StressForceFabric, fabric_summary
from grainlab.columns import SHEAR_STRAIN, SIMPLE_SHEAR
from grainlab.io.hdf5.snapshot import snapshot_name
from grainlab.io.results import SHEAR_START_FILE
from grainlab.protocols import operations
from grainlab.protocols.cracks import bonds_broken, crack_records, record_units
from grainlab.protocols.grains import grain_coordination, grain_porosity
from grainlab.protocols.operations import Loading, Operation
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.simple_shear.cell import (
    CONTROL_STEPS,
    cell_stress,
    servo_rate,
    side_stresses,
)
from grainlab.protocols.simple_shear.config import SimpleShearConfig
from grainlab.protocols.simple_shear.outputs import SimpleShearResult, summarise, write_outputs
from grainlab.protocols.simple_shear.state import SimpleShearRun
from grainlab.protocols.specimen import (
    CHUNK_STEPS,
    OUTPUT_FILES,
    SpecimenError,
    SpecimenProtocol,
    cement_sample,
    contact_law,
    damped_time_step_factor,
    engine_columns,
    grain_model,
)
from grainlab.protocols.triggers import (
    And,
    EveryStop,
    OnSteps,
    Periodic,
    WallClock,
    schedule_steps,
)
from grainlab.simulation import Simulation
from grainlab.snapshot import ParticleKind

__all__ = ["CellControl", "SimpleShearProtocol", "SimpleShearRun", "record_steps", "run_simple_shear", "set_cell_rates",
           "snapshot_name_of"]

Context = StageContext[SimpleShearConfig, SimpleShearRun]


def snapshot_name_of(shear_strain: float) -> str:
    """The snapshot's name in run.h5 at ``shear_strain``: ``gamma_0.2500``."""
    return snapshot_name(shear_strain, prefix="gamma")


def record_steps(config: SimpleShearConfig, steps_per_unit: float) -> tuple[list[int], dict[int, float]]:
    """The steps after the start of shearing that carry a record, and those that
    also carry a snapshot (step -> its shear strain)."""
    final = config.simple_shear.final_strain
    strains = [s for s in config.simple_shear.snapshot_strains if 0 < s <= final]
    steps = schedule_steps(config.simple_shear.record_interval, strains, final=final,
                           steps_per_unit=steps_per_unit)
    snaps = {round(s * steps_per_unit): s for s in strains}
    return steps, snaps


def _max_rate(sim: Simulation, config: SimpleShearConfig, shear_rate: float) -> float:
    """The cap on the cell's rate: a twentieth of the smallest diameter per 100 steps over the
    cell's height, plus the shear rate."""
    cell = sim.cell
    assert cell is not None
    return float(0.05 * config.sample.d_min / (100 * sim.time_step * cell.b[1]) + abs(shear_rate))


def set_cell_rates(sim: Simulation, run: SimpleShearRun, config: SimpleShearConfig, targets: tuple[float | None, float | None],
                   shear_rate: float) -> None:
    """The cell's velocity gradient ``[[L_xx, shear_rate], [0, L_yy]]`` for the next
    CONTROL_STEPS steps, each side's rate servo-controlled to hold its target of
    ``targets`` (sigma_xx, sigma_yy; None: that side's rate 0)."""
    rates = [0.0, 0.0]
    interval = CONTROL_STEPS * sim.time_step
    cap = _max_rate(sim, config, shear_rate)
    held = [(k, target) for k, target in enumerate(targets) if target is not None]
    measured = side_stresses(sim, [k for k, _ in held])
    for (k, target), (stress, stiffness) in zip(held, measured, strict=True):
        rates[k], run.cell_rate_integral[k] = servo_rate(
            stress, target, stiffness, interval, cap, run.cell_rate_integral[k])
    sim.set_velocity_gradient([[rates[0], shear_rate], [0.0, rates[1]]])


class CellControl(Operation):
    """Controller: the cell sheared at ``shear_rate``; a side with a target stress
    servo-controlled to it every CONTROL_STEPS steps from ``run.start_step``
    (:func:`set_cell_rates`), or, with no target, the gradient set at every stop."""

    acts_before_run = True

    def __init__(self, run: SimpleShearRun, config: SimpleShearConfig, targets: tuple[float | None, float | None],
                 shear_rate: float) -> None:
        held = targets != (None, None)
        super().__init__(Periodic(CONTROL_STEPS, run.start_step) if held else EveryStop())
        self.run, self.config, self.targets, self.shear_rate = run, config, targets, shear_rate

    def act(self, loading: Loading) -> None:
        sim = loading.sim
        if self.targets != (None, None):
            set_cell_rates(sim, self.run, self.config, self.targets, self.shear_rate)
            return
        wanted = ((0.0, self.shear_rate), (0.0, 0.0))
        cell = sim.cell
        if cell is None or cell.velocity_gradient != wanted:
            sim.set_velocity_gradient(wanted)


def _to_periodic(context: Context) -> None:
    """The walls give way to a periodic cell of their box; the gradient is set to 0."""
    sim, run = context.sim, context.state
    left = float(sim.wall(run.walls["left"]).points[0, 0])
    right = float(sim.wall(run.walls["right"]).points[0, 0])
    bottom = float(sim.wall(run.walls["bottom"]).points[0, 1])
    top = float(sim.wall(run.walls["top"]).points[0, 1])
    for wall_id in run.walls.values():
        sim.wall(wall_id).active = False
    sim.set_periodic_cell((left, bottom), (right, top))
    sim.set_velocity_gradient(np.zeros((2, 2)))


class CellSettled(Operation):
    """Stop rule: every CHUNK_STEPS steps from ``run.start_step``, the loading ends once both
    sides hold sigma_0 within ``consolidation.tolerance`` in equilibrium; a loading that
    takes ``consolidation.max_steps`` stops the run with a :class:`SpecimenError`."""

    def __init__(self, run: SimpleShearRun, config: SimpleShearConfig, bar: operations.Bar, label: str) -> None:
        super().__init__(Periodic(CHUNK_STEPS, run.start_step))
        self.run, self.config, self.bar, self.label = run, config, bar, label

    def act(self, loading: Loading) -> None:
        sim, c = loading.sim, self.config.consolidation
        steps, target, limit = sim.step_count - self.run.start_step, c.pressure, c.unbalanced_force_ratio
        stress = cell_stress(sim).total
        self.bar.update(CHUNK_STEPS)
        self.bar.set_postfix_str(f"sxx {stress[0, 0] / 1e3:.1f} kPa, syy {stress[1, 1] / 1e3:.1f} kPa, "
                                 f"unbalanced {sim.unbalanced_force_ratio:.1e}")
        if max(abs(stress[0, 0] / target - 1.0), abs(stress[1, 1] / target - 1.0)) < c.tolerance and \
                sim.unbalanced_force_ratio < limit:
            loading.stop()
        elif steps >= c.max_steps:
            raise SpecimenError(
                f"{self.label} in the periodic cell did not converge in {steps} steps: sigma_xx "
                f"{stress[0, 0] / 1e3:.1f}, sigma_yy {stress[1, 1] / 1e3:.1f} kPa (target {target / 1e3:.1f} kPa "
                f"+- {c.tolerance:.0%}), unbalanced force ratio {sim.unbalanced_force_ratio:.2e} (limit "
                f"{limit:.0e}); raise consolidation.max_steps"
            )


def _equilibrate(sim: Simulation, run: SimpleShearRun, config: SimpleShearConfig, progress: bool, label: str) -> int:
    """Servo-controls both sides of the cell to sigma_0 until equilibrium; returns the steps taken."""
    target = config.consolidation.pressure
    bar = progress_bar(config.consolidation.max_steps, label, enabled=progress, unit="step")
    run.start_step = sim.step_count  # the control's step count starts here
    run.cell_rate_integral = [0.0, 0.0]
    try:
        Loading(sim, [CellSettled(run, config, bar, label), CellControl(run, config, (target, target), 0.0)]).run()
    finally:
        bar.close()
    sim.set_velocity_gradient(np.zeros((2, 2)))
    return sim.step_count - run.start_step


def _consolidate(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    start = time.perf_counter()
    _to_periodic(context)
    sim.set_contact_model(0, 0, contact_law(config, config.consolidation.friction))
    sim.local_damping = config.material.local_damping
    sim.time_step = config.run.time_step_safety * sim.critical_time_step(1.0) * damped_time_step_factor(config)
    steps = _equilibrate(sim, run, config, context.progress, "consolidating")
    cell = sim.cell
    assert cell is not None
    stress = cell_stress(sim).total
    run.consolidation = {
        "steps": steps, "stress_xx_pa": float(stress[0, 0]), "stress_yy_pa": float(stress[1, 1]),
        "width_m": float(cell.a[0]), "height_m": float(cell.b[1]),
        "porosity": grain_porosity(sim, run.n_grains, cell.area),
        "coordination_number": grain_coordination(sim), "unbalanced_force_ratio": sim.unbalanced_force_ratio,
        "time_step_s": sim.time_step,
    }
    cement_sample(sim, run, config, period=(float(cell.a[0]), float(cell.b[1])))
    run.wall_time["consolidate"] = time.perf_counter() - start


def _settle(context: Context) -> None:
    """Table 1 friction on, the cell held at sigma_0 until equilibrium again; the shearing's plan."""
    sim, run, config = context.sim, context.state, context.config
    start = time.perf_counter()
    sim.set_contact_model(0, 0, grain_model(config))
    _equilibrate(sim, run, config, context.progress, "settling with friction")
    cell = sim.cell
    assert cell is not None
    stress = cell_stress(sim).total
    held = config.simple_shear.normal_stress
    run.normal_stress_pa = float(stress[1, 1]) if config.simple_shear.volume == "constant" or held == "auto" \
        else float(held)
    if config.simple_shear.volume == "free" and held == "auto":
        run.normal_stress_pa = float(config.consolidation.pressure)
    run.mean_diameter_m = float(2.0 * np.mean(sim.radii[: run.n_grains]))
    density = config.material.density
    run.shear_rate_per_s = config.simple_shear.inertial_number * math.sqrt(run.normal_stress_pa / density) \
        / run.mean_diameter_m
    damping = config.simple_shear.local_damping
    sim.local_damping = config.material.local_damping if damping == "auto" else float(damping)
    run.start_step = sim.step_count
    run.cell_rate_integral = [0.0, 0.0]
    run.area0 = float(cell.area)
    sim.save(context.writer.path.parent / SHEAR_START_FILE)  # for grainlab export DIR --lammps
    run.wall_time["settle"] = time.perf_counter() - start


def _shear(context: Context) -> None:
    sim, run, config, writer = context.sim, context.state, context.config, context.writer
    rate = run.shear_rate_per_s
    steps_per_unit = 1.0 / (rate * sim.time_step)
    steps, snaps = record_steps(config, steps_per_unit)
    records = operations.Records(OnSteps(steps, run.start_step), writer, lambda: _record(sim, run, config),
                                 record_units(SIMPLE_SHEAR, config),
                      count=run)
    strains = {run.start_step + step: strain for step, strain in snaps.items()}
    snapshots = operations.Snapshots(OnSteps(strains), writer, lambda step: snapshot_name_of(strains[step]),
                          lambda: _snapshot(sim, run, records.values))
    if run.next_record == 0 and writer.n_rows == 0:
        sim.set_velocity_gradient([[0.0, rate], [0.0, 0.0]])
        records.write(sim.step_count)
        if 0.0 in config.simple_shear.snapshot_strains:
            snapshots.store(snapshot_name_of(0.0), sim.step_count)
    if run.next_record == len(steps):  # stopped after the last record's checkpoint
        return
    final = config.simple_shear.final_strain
    done = 100 * steps[run.next_record - 1] / steps_per_unit if run.next_record else 0.0
    bar = progress_bar(round(100 * final, 3), "shearing", enabled=context.progress, unit="% strain", initial=done,
                       bar_format="{l_bar}{bar}| {n:.1f}/{total:.0f} % [{elapsed}<{remaining}{postfix}]")
    scheduled = records.trigger
    checkpoint = operations.Checkpoint(And(scheduled, WallClock(config.run.checkpoint_interval)), context.save,
                            run.wall_time, "shear")
    targets = (None, run.normal_stress_pa) if config.simple_shear.volume == "free" else (None, None)
    operations.run_loading(sim, [
        records, *crack_records(scheduled, writer, config, SHEAR_STRAIN), snapshots,
        operations.Progress(scheduled, bar, lambda step: 100 * (step - run.start_step) / steps_per_unit,
                 lambda: f"mu {records.values['friction_coefficient']:.3f}, Z {records.values['coordination_number']:.2f}",
                 done),
        checkpoint, operations.Stop(OnSteps(steps[-1:], run.start_step)), CellControl(run, config, targets, rate),
    ], checkpoint, bar)


def _snapshot(sim: Simulation, run: SimpleShearRun, values: dict[str, float]) -> Any:
    kind = np.full(sim.n_particles, int(ParticleKind.SOIL), dtype=np.int8)
    scalars = {name: values[name] for name in ("shear_strain", "shear_stress_pa", "normal_stress_pa",
                                                "friction_coefficient", "volumetric_strain", "cell_tilt")}
    return sim.snapshot(kind=kind, scalars=scalars, step=sim.step_count)  # with the cell's box and tilt


def _record(sim: Simulation, run: SimpleShearRun, config: SimpleShearConfig) -> dict[str, float]:
    """One record, in :data:`grainlab.columns.SIMPLE_SHEAR`'s order (a cemented sample's bonds broken after them)."""
    cell = sim.cell
    assert cell is not None
    stress = cell_stress(sim)
    total = stress.total
    n = run.n_grains
    area = float(cell.area)
    porosity = grain_porosity(sim, n, area)
    normal = float(total[1, 1])
    tau = -float(total[0, 1])
    snap = sim.snapshot(kind=np.full(sim.n_particles, int(ParticleKind.SOIL), dtype=np.int8))
    fabric = fabric_summary(snap)
    z = fabric.pop("coordination_number")
    rb = StressForceFabric().compute(snap)
    strain = (sim.step_count - run.start_step) * sim.time_step * run.shear_rate_per_s
    values = {
        "step": float(sim.step_count), "time_s": sim.time, "shear_strain": strain,
        "shear_stress_pa": tau, "normal_stress_pa": normal, "lateral_stress_pa": float(total[0, 0]),
        "friction_coefficient": tau / normal if normal > 0 else math.nan,
        "inertial_number": run.shear_rate_per_s * run.mean_diameter_m / math.sqrt(normal / config.material.density)
        if normal > 0 else math.nan,
        "volumetric_strain": (run.area0 - area) / run.area0 if run.area0 else 0.0,
        "porosity": porosity, "void_ratio": porosity / (1.0 - porosity), "area_m2": area,
        "height_m": float(cell.b[1]), "cell_tilt": float(cell.b[0] / cell.a[0]),
        "kinetic_stress_share": float(stress.kinetic[1, 1]) / normal if normal > 0 else math.nan,
        "love_weber_xx_pa": float(stress.contact[0, 0]), "love_weber_yy_pa": float(stress.contact[1, 1]),
        "love_weber_xy_pa": float(stress.contact[0, 1]),
        "coordination_number": z,
        **engine_columns(sim),
        **fabric,
        "rb_stress_ratio": rb.stress_ratio, "rb_predicted_stress_ratio": rb.predicted_stress_ratio,
        "rb_residual": rb.residual,
    }
    return {**{name: values[name] for name in SIMPLE_SHEAR}, **bonds_broken(sim, run.consolidation, config)}


class SimpleShearProtocol(SpecimenProtocol[SimpleShearConfig, SimpleShearRun, SimpleShearResult]):
    """Periodic simple shear at constant normal stress or constant volume, to large strain."""

    name = "simple_shear"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        Stage("consolidate", _consolidate, "the walls replaced by a periodic cell of their box, the cell "
                                           "servo-controlled to sigma_0 (consolidation friction) until equilibrium"),
        Stage("settle", _settle, "Table 1 friction on, the cell held at sigma_0 until equilibrium; the shear rate "
                                 "from the inertial number, the shearing's local damping; the state saved as "
                                 "shear_start.state (grainlab export --lammps)"),
        Stage("shear", _shear, "simple shear L = [[0, gamma_dot], [0, L_yy]] to the final strain (L_yy holds "
                               "sigma_n, or 0 at constant volume); a record on each interval, snapshots, "
                               "checkpoints on the wall clock"),
    )
    state_type = SimpleShearRun
    summarise = summarise
    outputs = write_outputs
    result_type = SimpleShearResult
    output_files = (*OUTPUT_FILES, SHEAR_START_FILE)


def run_simple_shear(config: SimpleShearConfig, out_dir: str | os.PathLike[str], *, resume: bool = False,
                     progress: bool = False) -> SimpleShearResult:
    """Runs (or, with ``resume``, continues) the periodic simple-shear test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`)."""
    return run_protocol(SimpleShearProtocol(config), out_dir, resume=resume, progress=progress)
